//! The Cornell box generator: reads the Cornell box's OBJ parts in a directory (with their
//! `cornell.mtl`) and writes the same scene as glTF 2.0: `cornell.gltf` + `cornell.bin`, one mesh
//! and node per part, one material per MTL material, and the reference camera. The parsing here
//! is deliberately minimal (v, f, o, usemtl, mtllib; newmtl, Kd, Ke): it serves these simple
//! files, the tracer's real loaders are tobj and gltf.

use crate::gltf_writer::{GltfBuilder, write_atomic, write_json};
use anyhow::{Context, Result, bail};
use glam::Vec3;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The Cornell reference camera (the Mitsuba reference's, `tests/data/cornell/README.md`): the OBJ
/// carries none.
const CORNELL_FROM: [f64; 3] = [2.78, 2.73, -8.0];
const CORNELL_FOV_Y_DEG: f64 = 39.30764811610662;

/// One OBJ part: its triangles over its own vertices, and its material's name.
struct Part {
    name: String,
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    material: String,
}

/// The MTL parameters the generator understands.
#[derive(Default)]
struct MtlMaterial {
    kd: [f64; 3],
    ke: Option<[f64; 3]>,
}

pub fn cornell(dir: &Path) -> Result<()> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("reading {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "obj"))
        .collect();
    // Sorted like the tracer's directory loader, so both list the parts in the same order.
    files.sort_by(|a, b| a.file_name().cmp(&b.file_name()));
    if files.is_empty() {
        bail!("{}: no .obj files", dir.display());
    }
    let mut mtllib = None;
    let mut parts = Vec::new();
    for file in &files {
        let (part, lib) = parse_obj(file)?;
        mtllib = mtllib.or(lib);
        parts.push(part);
    }
    let mtllib = mtllib.context("no OBJ part names a material library (mtllib)")?;
    let materials = parse_mtl(&dir.join(&mtllib))?;
    let (gltf, bin) = build_gltf(&parts, &materials)?;
    write_atomic(&dir.join("cornell.bin"), &bin)?;
    write_json(&dir.join("cornell.gltf"), &gltf)?;
    println!(
        "wrote {} parts, {} materials to {}",
        parts.len(),
        materials.len(),
        dir.join("cornell.gltf").display()
    );
    Ok(())
}

fn parse_obj(path: &Path) -> Result<(Part, Option<String>)> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let stem = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default();
    let mut part = Part { name: stem, positions: Vec::new(), triangles: Vec::new(), material: String::new() };
    let mut mtllib = None;
    for (i, line) in text.lines().enumerate() {
        let at = || format!("{}:{}", path.display(), i + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let v: Vec<f32> = words.take(3).map(str::parse).collect::<Result<_, _>>().with_context(at)?;
                let [x, y, z] = v[..] else { bail!("{}: a vertex needs three coordinates", at()) };
                part.positions.push(Vec3::new(x, y, z));
            }
            Some("f") => {
                let n = part.positions.len() as i64;
                let corners: Vec<u32> = words
                    .map(|w| {
                        // "v", "v/vt" or "v/vt/vn": only the position index matters here.
                        let v: i64 = w.split('/').next().unwrap_or("").parse().with_context(at)?;
                        let idx = if v < 0 { n + v } else { v - 1 };
                        if !(0..n).contains(&idx) {
                            bail!("{}: vertex {v} out of range", at());
                        }
                        Ok(idx as u32)
                    })
                    .collect::<Result<_>>()?;
                if corners.len() < 3 {
                    bail!("{}: a face needs three corners", at());
                }
                // Fan triangulation keeps the polygon's winding.
                part.triangles.extend(corners.windows(2).skip(1).map(|w| [corners[0], w[0], w[1]]));
            }
            Some("o") => part.name = words.collect::<Vec<_>>().join(" "),
            Some("mtllib") => mtllib = Some(words.collect::<Vec<_>>().join(" ")),
            Some("usemtl") => {
                let name = words.collect::<Vec<_>>().join(" ");
                if !part.triangles.is_empty() && name != part.material {
                    bail!("{}: one material per part only (the generator's limit)", at());
                }
                part.material = name;
            }
            _ => {}
        }
    }
    if part.material.is_empty() {
        bail!("{}: no usemtl", path.display());
    }
    Ok((part, mtllib))
}

fn parse_mtl(path: &Path) -> Result<BTreeMap<String, MtlMaterial>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let mut materials: BTreeMap<String, MtlMaterial> = BTreeMap::new();
    let mut current: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        let at = || format!("{}:{}", path.display(), i + 1);
        let mut words = line.split_whitespace();
        let keyword = words.next();
        if keyword == Some("newmtl") {
            let name = words.collect::<Vec<_>>().join(" ");
            materials.insert(name.clone(), MtlMaterial::default());
            current = Some(name);
            continue;
        }
        let (Some(k @ ("Kd" | "Ke")), Some(name)) = (keyword, &current) else {
            match keyword {
                Some(k) if !k.starts_with('#') => {
                    bail!("{}: '{k}' is outside this generator's MTL subset", at())
                }
                _ => continue,
            }
        };
        let v: Vec<f64> = words.map(str::parse).collect::<Result<_, _>>().with_context(at)?;
        let rgb: [f64; 3] = v.try_into().map_err(|_| anyhow::anyhow!("{}: {k} needs three numbers", at()))?;
        let m = materials.entry(name.clone()).or_default();
        if k == "Kd" { m.kd = rgb } else { m.ke = Some(rgb) }
    }
    Ok(materials)
}

/// A glTF material for an MTL one, as Blender's exporter writes such surfaces (docs/design/tracer.md
/// §3.10): plain surfaces are two-sided with `KHR_materials_specular` 0 (pure Lambertian, like an
/// MTL without Ks); an emitter is emissiveFactor × emissiveStrength, one-sided like the MTL's
/// front-face `Ke`.
fn gltf_material(name: &str, m: &MtlMaterial) -> Value {
    let mut out = json!({
        "name": name,
        "pbrMetallicRoughness": {
            "baseColorFactor": [m.kd[0], m.kd[1], m.kd[2], 1.0],
            "metallicFactor": 0.0,
            "roughnessFactor": 1.0,
        },
        "doubleSided": true,
        "extensions": { "KHR_materials_specular": { "specularFactor": 0.0 } },
    });
    if let Some(ke) = m.ke.filter(|ke| ke.iter().any(|&c| c > 0.0)) {
        // glTF factors live in [0, 1]: the brightest channel becomes the strength.
        let strength = ke.iter().copied().fold(0.0, f64::max);
        out["emissiveFactor"] = json!(ke.map(|c| c / strength));
        out["extensions"]["KHR_materials_emissive_strength"] = json!({ "emissiveStrength": strength });
        out["doubleSided"] = json!(false);
    }
    out
}

/// The glTF JSON and its binary buffer for `parts`.
fn build_gltf(parts: &[Part], materials: &BTreeMap<String, MtlMaterial>) -> Result<(Value, Vec<u8>)> {
    let names: Vec<&String> = materials.keys().collect();
    let mut doc = GltfBuilder::new();
    for part in parts {
        let material = names
            .iter()
            .position(|n| **n == part.material)
            .with_context(|| format!("part '{}' uses undefined material '{}'", part.name, part.material))?;
        let indices: Vec<u32> = part.triangles.iter().flatten().copied().collect();
        let pos = doc.vec3_accessor(&part.positions, true);
        let idx = doc.index_accessor(&indices, part.positions.len());
        let mesh = doc.add_mesh(json!({
            "name": part.name,
            "primitives": [{ "attributes": { "POSITION": pos }, "indices": idx, "material": material, "mode": 4 }],
        }));
        doc.add_node(json!({ "name": part.name, "mesh": mesh }));
    }
    // A glTF camera looks down its local -Z: turned 180° about +Y it looks down world +Z, at the
    // box, with +X to image left, as the reference's look-at camera.
    doc.add_node(json!({ "name": "cornell", "camera": 0, "rotation": [0.0, 1.0, 0.0, 0.0], "translation": CORNELL_FROM }));
    doc.add_camera(json!({
        "name": "cornell",
        "type": "perspective",
        "perspective": { "yfov": CORNELL_FOV_Y_DEG.to_radians(), "aspectRatio": 1.0, "znear": 0.01 },
    }));
    doc.use_extension("KHR_materials_emissive_strength");
    doc.use_extension("KHR_materials_specular");
    for n in &names {
        doc.add_material(gltf_material(n, &materials[*n]));
    }
    Ok(doc.finish("cornell", None, "cornell.bin"))
}
