//! `mcctrace info SCENE`: what a scene holds, for choosing cameras and checking a file.

use clap::Args;
use std::path::PathBuf;
use tracer::scene::{PunctualLight, Scene};

/// Arguments of `mcctrace info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    scene: PathBuf,
}

pub fn run(a: InfoArgs) -> anyhow::Result<()> {
    let scene = Scene::load(&a.scene)?;
    println!("scene      {}", a.scene.display());
    println!("triangles  {}", scene.mesh.triangle_count());
    println!("cameras    {}", scene.describe_cameras());
    let emissive = scene.materials.iter().filter(|m| m.is_emissive()).count();
    println!("materials  {} ({} emissive)", scene.materials.len(), emissive);
    for light in &scene.lights {
        match light {
            PunctualLight::Point { position, intensity } => {
                println!("light      point at {position}, {intensity} W/sr")
            }
        }
    }
    if let Some((lo, hi)) = scene.bounds() {
        println!("bounds     {lo} .. {hi}");
    }
    for w in &scene.warnings {
        println!("warning    {w}");
    }
    Ok(())
}
