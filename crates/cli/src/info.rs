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
    let (drawn, stored) = (scene.drawn_triangle_count(), scene.mesh.triangle_count());
    match drawn == stored {
        true => println!("triangles  {drawn}"),
        false => println!("triangles  {drawn} ({stored} stored: copies share their mesh)"),
    }
    println!("textures   {}", scene.textures.len());
    println!("cameras    {}", scene.describe_cameras());
    let emissive = scene.materials.iter().filter(|m| m.is_emissive()).count();
    println!("materials  {} ({} emissive)", scene.materials.len(), emissive);
    for light in &scene.lights {
        match light {
            PunctualLight::Point { position, intensity } => {
                println!("light      point at {position}, {intensity} W/sr")
            }
            PunctualLight::Spot { position, direction, intensity, inner_cone, outer_cone, .. } => println!(
                "light      spot at {position} towards {direction}, {intensity} W/sr, cone {:.1}°/{:.1}°",
                inner_cone.to_degrees(),
                outer_cone.to_degrees()
            ),
            PunctualLight::Directional { direction, irradiance } => {
                println!("light      directional towards {direction}, {irradiance} W/m²")
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
