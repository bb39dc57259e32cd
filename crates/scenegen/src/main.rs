//! Generators for the bundled scenes in `scenes/` (a developer tool, not part of mcctrace).
//!
//! `mcctrace-scenegen cornell DIR` reads the Cornell box's OBJ parts in DIR (with their
//! `cornell.mtl`) and writes the same scene as glTF 2.0: `DIR/cornell.gltf` + `DIR/cornell.bin`,
//! one mesh and node per part, one material per MTL material, and the reference camera. The
//! parsing here is deliberately minimal (v, f, o, usemtl, mtllib; newmtl, Kd, Ke): it serves
//! these simple files, the tracer's real loaders are tobj and gltf.

use anyhow::{Context, Result, bail};
use glam::Vec3;
use serde_json::{Value, json};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The Cornell reference camera (shared/reference/cornell/scene.json): the OBJ carries none.
const CORNELL_FROM: [f64; 3] = [2.78, 2.73, -8.0];
const CORNELL_FOV_Y_DEG: f64 = 39.30764811610662;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [cmd, dir] if cmd == "cornell" => cornell(Path::new(dir)),
        _ => bail!("usage: mcctrace-scenegen cornell DIR"),
    }
}

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

fn cornell(dir: &Path) -> Result<()> {
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
    write_atomic(&dir.join("cornell.gltf"), (serde_json::to_string_pretty(&gltf)? + "\n").as_bytes())?;
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

/// A glTF material for an MTL one, as Blender's exporter writes such surfaces (NOTES.md): plain
/// surfaces are two-sided with `KHR_materials_specular` 0 (pure Lambertian, like an MTL without
/// Ks); an emitter is emissiveFactor × emissiveStrength, one-sided like the MTL's front-face `Ke`.
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
    let mut bin = Vec::new();
    let (mut views, mut accessors, mut meshes, mut nodes) = (vec![], vec![], vec![], vec![]);
    for part in parts {
        let material = names
            .iter()
            .position(|n| **n == part.material)
            .with_context(|| format!("part '{}' uses undefined material '{}'", part.name, part.material))?;
        let (lo, hi) = part
            .positions
            .iter()
            .fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let pos_bytes: Vec<u8> =
            part.positions.iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes).collect();
        let wide = part.positions.len() > usize::from(u16::MAX);
        let idx_bytes: Vec<u8> = part
            .triangles
            .iter()
            .flatten()
            .flat_map(|&i| if wide { i.to_le_bytes().to_vec() } else { (i as u16).to_le_bytes().to_vec() })
            .collect();
        let pos_view = push_view(&mut bin, &mut views, &pos_bytes, 34962);
        let idx_view = push_view(&mut bin, &mut views, &idx_bytes, 34963);
        accessors.push(json!({
            "bufferView": pos_view, "componentType": 5126, "count": part.positions.len(), "type": "VEC3",
            // f32 → f64 is exact, so the bounds equal the stored floats bit for bit.
            "min": lo.to_array().map(f64::from), "max": hi.to_array().map(f64::from),
        }));
        accessors.push(json!({
            "bufferView": idx_view, "componentType": if wide { 5125 } else { 5123 },
            "count": 3 * part.triangles.len(), "type": "SCALAR",
        }));
        let n = accessors.len();
        meshes.push(json!({
            "name": part.name,
            "primitives": [{ "attributes": { "POSITION": n - 2 }, "indices": n - 1, "material": material, "mode": 4 }],
        }));
        nodes.push(json!({ "name": part.name, "mesh": meshes.len() - 1 }));
    }
    // A glTF camera looks down its local -Z: turned 180° about +Y it looks down world +Z, at the
    // box, with +X to image left, as the reference's look-at camera.
    nodes.push(json!({ "name": "cornell", "camera": 0, "rotation": [0.0, 1.0, 0.0, 0.0], "translation": CORNELL_FROM }));
    let gltf = json!({
        "asset": { "version": "2.0", "generator": "mcctrace-scenegen (crates/scenegen)" },
        "extensionsUsed": ["KHR_materials_emissive_strength", "KHR_materials_specular"],
        "scene": 0,
        "scenes": [{ "name": "cornell", "nodes": (0..nodes.len()).collect::<Vec<_>>() }],
        "nodes": nodes,
        "cameras": [{
            "name": "cornell",
            "type": "perspective",
            "perspective": { "yfov": CORNELL_FOV_Y_DEG.to_radians(), "aspectRatio": 1.0, "znear": 0.01 },
        }],
        "meshes": meshes,
        "materials": names.iter().map(|n| gltf_material(n, &materials[*n])).collect::<Vec<_>>(),
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{ "uri": "cornell.bin", "byteLength": bin.len() }],
    });
    Ok((gltf, bin))
}

/// Appends `data` as a buffer view starting on a 4-byte boundary (glTF requires accessor
/// offsets to be multiples of their component size; 4 serves every type) and returns its index.
fn push_view(bin: &mut Vec<u8>, views: &mut Vec<Value>, data: &[u8], target: u32) -> usize {
    bin.resize(bin.len().next_multiple_of(4), 0);
    views.push(json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": data.len(), "target": target }));
    bin.extend_from_slice(data);
    views.len() - 1
}

/// Writes through a temporary file and a rename, so an interrupted run leaves no half file.
fn write_atomic(path: &Path, data: &[u8]) -> Result<()> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, data).with_context(|| format!("writing {}", tmp.display()))?;
    std::fs::rename(&tmp, path).with_context(|| format!("renaming to {}", path.display()))
}
