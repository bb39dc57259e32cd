//! OBJ/MTL loader (tobj): one or several OBJ files, or every `*.obj` of a directory, form one
//! scene. Faces are triangulated; positions, normals and texture coordinates go into the mesh.
//!
//! MTL parameters map onto the glTF-style [`Material`]:
//! - `Kd` → base colour; metallic 0.
//! - `Ke` → emitted radiance from the **front face only** (`emission_two_sided = false`): the
//!   counter-clockwise side, as the Cornell reference's one-sided light. OBJ has no way to say
//!   "two-sided emitter", and a one-sided rule is what a light fixture modelled as a quad needs.
//! - `Ks`, `Ns` → the `KHR_materials_specular` layer: specular 1 with specular colour Ks / 0.04,
//!   so the dielectric F0 = min(0.04 · colour, 1) is Ks itself; the Blinn–Phong exponent Ns maps
//!   to the Beckmann-equivalent α = sqrt(2 / (Ns + 2)) and roughness = sqrt(α). No `Ks` (or a
//!   black one) leaves a pure Lambertian surface (specular 0).
//! - Texture maps (`map_Kd` …) are ignored for now, with a warning.
//!
//! A missing or malformed MTL file and an unknown material name are warnings (the surface gets
//! [`Material::default()`]), never errors: the geometry is still worth rendering.

use super::{MeshPart, Scene};
use crate::error::{Result, TracerError};
use crate::material::Material;
use glam::{Vec2, Vec3};
use std::cell::RefCell;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Every `*.obj` file directly in `dir`, sorted by file name, as one scene named after `dir`.
pub(super) fn load_dir(dir: &Path) -> Result<Scene> {
    let mut files = Vec::new();
    for entry in std::fs::read_dir(dir).map_err(|e| TracerError::io(dir, e))? {
        let path = entry.map_err(|e| TracerError::io(dir, e))?.path();
        let is_obj = path.extension().is_some_and(|e| e.eq_ignore_ascii_case("obj"));
        if is_obj && path.is_file() {
            files.push(path);
        }
    }
    if files.is_empty() {
        return Err(TracerError::scene(dir, "the directory holds no .obj files"));
    }
    files.sort_by(|a, b| a.file_name().cmp(&b.file_name()));
    load_files(dir, &files)
}

/// Loads `paths` as one scene whose messages name `first`.
pub(super) fn load_files(first: &Path, paths: &[PathBuf]) -> Result<Scene> {
    let mut loader = Loader {
        scene: Scene { path: first.to_owned(), ..Scene::default() },
        by_key: HashMap::new(),
        default_material: None,
    };
    for path in paths {
        loader.load(path)?;
    }
    Ok(loader.scene)
}

/// Options shared by the real parse and the error-locating re-parses.
fn options() -> tobj::LoadOptions {
    tobj::LoadOptions { triangulate: true, single_index: true, ..Default::default() }
}

struct Loader {
    scene: Scene,
    /// Scene material index of each (MTL file, position in it): parts sharing a library share
    /// its materials instead of each OBJ adding its own copies.
    by_key: HashMap<(PathBuf, usize), u32>,
    /// Index of `Material::default()` once something needed it.
    default_material: Option<u32>,
}

/// A material library tobj loaded for one OBJ file, in load order.
struct Library {
    path: PathBuf,
    count: usize,
}

impl Loader {
    fn warn(&mut self, file: &Path, message: String) {
        self.scene.warnings.push(format!("{}: {message}", file.display()));
    }

    fn load(&mut self, path: &Path) -> Result<()> {
        let bytes = std::fs::read(path).map_err(|e| TracerError::io(path, e))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        // tobj's material callback is `Fn`: it records what it loaded and what failed here.
        let libraries = RefCell::new(Vec::<Library>::new());
        let failures = RefCell::new(Vec::<String>::new());
        let load_mtl = |name: &Path| {
            let file = dir.join(name);
            let result = match std::fs::read(&file) {
                Ok(text) => tobj::load_mtl_buf(&mut &text[..]).inspect_err(|e| {
                    failures
                        .borrow_mut()
                        .push(format!("material library {} is malformed: {e}", file.display()))
                }),
                Err(e) => {
                    failures
                        .borrow_mut()
                        .push(format!("cannot read material library {}: {e}", file.display()));
                    Err(tobj::LoadError::OpenFileFailed)
                }
            };
            if let Ok((materials, _)) = &result {
                libraries.borrow_mut().push(Library { path: file, count: materials.len() });
            }
            result
        };
        let (models, materials) = tobj::load_obj_buf(&mut &bytes[..], &options(), load_mtl).map_err(|e| {
            let at = failing_line(&bytes).map_or_else(String::new, |l| format!(" at line {l}"));
            TracerError::scene(path, format!("malformed OBJ{at}: {e}"))
        })?;
        for failure in failures.take() {
            self.warn(path, format!("{failure}; its materials fall back to the default"));
        }
        let materials = materials.unwrap_or_default();
        self.warn_unknown_names(path, &bytes, &materials);

        // tobj appends each library's materials in load order: recover which file each came from.
        let mut origin = Vec::with_capacity(materials.len());
        for lib in libraries.borrow().iter() {
            origin.extend((0..lib.count).map(|i| (lib.path.clone(), i)));
        }
        for model in &models {
            let material = match model.mesh.material_id {
                Some(id) => match (materials.get(id), origin.get(id)) {
                    (Some(m), Some(key)) => self.material(path, m, key.clone()),
                    _ => self.default_material(),
                },
                None => self.default_material(),
            };
            self.push_model(path, model, material)?;
        }
        Ok(())
    }

    /// Warns about every `usemtl` naming a material no library defines (tobj drops them silently).
    fn warn_unknown_names(&mut self, path: &Path, bytes: &[u8], materials: &[tobj::Material]) {
        let text = String::from_utf8_lossy(bytes);
        let mut reported = Vec::new();
        for (i, line) in text.lines().enumerate() {
            let Some(name) =
                line.trim().strip_prefix("usemtl").filter(|r| r.starts_with(char::is_whitespace))
            else {
                continue;
            };
            let name = name.trim();
            if !materials.iter().any(|m| m.name == name) && !reported.contains(&name) {
                reported.push(name);
                let msg =
                    format!("line {}: material '{name}' is not defined; using the default material", i + 1);
                self.warn(path, msg);
            }
        }
    }

    /// The scene index of an MTL material, converting it on first use.
    fn material(&mut self, obj: &Path, m: &tobj::Material, key: (PathBuf, usize)) -> u32 {
        if let Some(&index) = self.by_key.get(&key) {
            return index;
        }
        let (material, textures) = convert(m);
        if !textures.is_empty() {
            let msg = format!(
                "material '{}' ({}): textures not supported yet; ignoring {}",
                m.name,
                key.0.display(),
                textures.join(", ")
            );
            self.warn(obj, msg);
        }
        self.scene.materials.push(material);
        let index = (self.scene.materials.len() - 1) as u32;
        self.by_key.insert(key, index);
        index
    }

    fn default_material(&mut self) -> u32 {
        *self.default_material.get_or_insert_with(|| {
            self.scene.materials.push(Material::default());
            (self.scene.materials.len() - 1) as u32
        })
    }

    fn push_model(&mut self, path: &Path, model: &tobj::Model, material: u32) -> Result<()> {
        let mesh = &model.mesh;
        let positions: Vec<Vec3> =
            mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])).collect();
        let n = positions.len();
        // tobj leaves the attribute arrays short when only some faces carry normals or texture
        // coordinates; then the part goes without (flat shading) rather than with garbage.
        let normals: Option<Vec<Vec3>> = (mesh.normals.len() == 3 * n && n > 0).then(|| {
            mesh.normals.chunks_exact(3).map(|v| Vec3::new(v[0], v[1], v[2]).normalize_or_zero()).collect()
        });
        // OBJ's v axis points up from the image's bottom; the mesh stores glTF's (down from the top).
        let uvs: Option<Vec<Vec2>> = (mesh.texcoords.len() == 2 * n && n > 0)
            .then(|| mesh.texcoords.chunks_exact(2).map(|t| Vec2::new(t[0], 1.0 - t[1])).collect());
        if normals.is_none() && !mesh.normals.is_empty() {
            self.warn(
                path,
                format!("object '{}': only some vertices have normals; shading it flat", model.name),
            );
        }
        if uvs.is_none() && !mesh.texcoords.is_empty() {
            self.warn(
                path,
                format!("object '{}': only some vertices have texture coordinates; dropped", model.name),
            );
        }
        let part = MeshPart {
            positions: &positions,
            normals: normals.as_deref(),
            uvs: uvs.as_deref(),
            indices: Some(&mesh.indices),
            material,
        };
        self.scene
            .mesh
            .push(part)
            .map_err(|m| TracerError::scene(path, format!("object '{}': {m}", model.name)))
    }
}

/// Maps one MTL material (see the module docs); also returns the texture statements it ignores.
fn convert(m: &tobj::Material) -> (Material, Vec<String>) {
    let default = Material::default();
    let ks = m.specular.map_or(Vec3::ZERO, Vec3::from);
    let (specular, specular_color, roughness) = if ks.max_element() > 0.0 {
        // Ns < 0 is meaningless; clamping keeps the square roots real.
        let ns = m.shininess.unwrap_or(0.0).max(0.0);
        let alpha = (2.0 / (ns + 2.0)).sqrt();
        (1.0, ks / 0.04, alpha.sqrt().clamp(0.0, 1.0))
    } else {
        (0.0, Vec3::ONE, 1.0)
    };
    let material = Material {
        name: m.name.clone(),
        base_color: m.diffuse.map_or(default.base_color, Vec3::from),
        metallic: 0.0,
        roughness,
        specular,
        specular_color,
        emission: m.emissive.map_or(Vec3::ZERO, Vec3::from),
        emission_two_sided: false,
        ..Material::default()
    };
    let known = [
        ("map_Kd", &m.diffuse_texture),
        ("map_Ka", &m.ambient_texture),
        ("map_Ks", &m.specular_texture),
        ("map_Ns", &m.shininess_texture),
        ("map_d", &m.dissolve_texture),
        ("norm/bump", &m.normal_texture),
    ];
    let mut textures: Vec<String> =
        known.iter().filter(|(_, t)| t.is_some()).map(|(k, _)| (*k).to_owned()).collect();
    let mut other: Vec<String> = m
        .unknown_param
        .keys()
        .filter(|k| k.starts_with("map_") || k.as_str() == "disp" || k.as_str() == "refl")
        .cloned()
        .collect();
    other.sort(); // HashMap order is random; warnings must be deterministic
    textures.extend(other);
    (material, textures)
}

/// The 1-based line where parsing `bytes` first fails: the shortest failing prefix, found by
/// bisection (tobj's errors carry no line number). Only run after a parse has failed.
fn failing_line(bytes: &[u8]) -> Option<usize> {
    let ends: Vec<usize> = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i + 1)
        .chain([bytes.len()])
        .collect();
    let fails = |lines: usize| {
        let prefix = bytes.get(..ends[lines - 1]).unwrap_or(bytes);
        tobj::load_obj_buf(&mut &prefix[..], &options(), |_| Err(tobj::LoadError::OpenFileFailed)).is_err()
    };
    let (mut lo, mut hi) = (1, ends.len());
    if !fails(hi) {
        return None;
    }
    while lo < hi {
        let mid = (lo + hi) / 2;
        if fails(mid) { hi = mid } else { lo = mid + 1 }
    }
    Some(lo)
}

#[cfg(test)]
mod tests {
    use super::super::Scene;
    use super::super::gltf::tests::{TempDir, cornell_dir};
    use glam::{Vec2, Vec3};

    const MTL: &str = "newmtl shiny\nKd 0.5 0.25 0.125\nKs 0.04 0.02 0.0\nNs 98\nmap_Kd wood.png\nmap_Bump b.png\n\
                       newmtl lamp\nKd 0 0 0\nKe 2 3 4\n";
    const OBJ: &str = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                       vn 0 0 2\nusemtl shiny\nf 1/1/1 2/2/1 3/3/1 4/4/1\nusemtl lamp\nf 1/1/1 3/3/1 4/4/1\n";

    #[test]
    fn scene_obj_mtl_mapping() {
        let dir = TempDir::new("obj-mtl");
        dir.write("m.mtl", MTL);
        let scene = Scene::load(&dir.write("quad.obj", OBJ)).unwrap();
        // The quad is fan-triangulated; the lamp triangle follows.
        assert_eq!(scene.mesh.triangle_count(), 3);
        let shiny = &scene.materials[scene.mesh.material_ids[0] as usize];
        assert_eq!(shiny.base_color, Vec3::new(0.5, 0.25, 0.125));
        // F0 = 0.04 × specular colour = Ks; α = sqrt(2 / 100), roughness = sqrt(α).
        assert!((shiny.specular_color * 0.04 - Vec3::new(0.04, 0.02, 0.0)).abs().max_element() < 1e-7);
        assert_eq!((shiny.specular, shiny.metallic), (1.0, 0.0));
        assert!((shiny.roughness - 0.02_f32.sqrt().sqrt()).abs() < 1e-6, "{}", shiny.roughness);
        let lamp = &scene.materials[scene.mesh.material_ids[2] as usize];
        assert_eq!(
            (lamp.emission, lamp.emission_two_sided, lamp.specular),
            (Vec3::new(2.0, 3.0, 4.0), false, 0.0)
        );
        assert!(!lamp.has_specular() && shiny.has_specular());
        // Normals renormalised; OBJ's v flipped to the mesh's top-down convention.
        assert!(scene.mesh.normals.iter().all(|n| *n == Vec3::Z));
        let [a, b, _] = scene.mesh.triangles[0];
        assert_eq!(
            (scene.mesh.uvs[a as usize], scene.mesh.uvs[b as usize]),
            (Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0))
        );
        let warnings = scene.warnings.join("\n");
        assert!(warnings.contains("quad.obj") && warnings.contains("'shiny'"), "{warnings}");
        assert!(warnings.contains("textures not supported yet; ignoring map_Kd, norm/bump"), "{warnings}");
        assert_eq!(scene.warnings.len(), 1, "{warnings}");
    }

    #[test]
    fn scene_obj_bad_material_references_are_warnings() {
        let dir = TempDir::new("obj-badmtl");
        let obj = "mtllib missing.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl ghost\nf 1 2 3\n";
        let scene = Scene::load(&dir.write("tri.obj", obj)).unwrap();
        assert_eq!(scene.mesh.triangle_count(), 1);
        assert_eq!(scene.materials, vec![crate::material::Material::default()]);
        let warnings = scene.warnings.join("\n");
        assert!(warnings.contains("tri.obj") && warnings.contains("missing.mtl"), "{warnings}");
        assert!(warnings.contains("line 5: material 'ghost' is not defined"), "{warnings}");
    }

    #[test]
    fn scene_obj_errors_name_file_and_problem() {
        let dir = TempDir::new("obj-errors");
        let empty = dir.0.join("empty");
        std::fs::create_dir(&empty).unwrap();
        std::fs::write(empty.join("notes.txt"), "not an obj").unwrap();
        let message = Scene::load(&empty).unwrap_err().to_string();
        assert!(message.contains("empty") && message.contains("no .obj files"), "{message}");

        let bad = dir.write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 x 0\nf 1 2 3\n");
        let message = Scene::load(&bad).unwrap_err().to_string();
        assert!(
            message.contains("bad.obj") && message.contains("line 3") && message.contains("position"),
            "{message}"
        );
        let range = dir.write("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 3\nf 1 2 9\n");
        let message = Scene::load(&range).unwrap_err().to_string();
        assert!(message.contains("range.obj") && message.contains("line 6"), "{message}");
        let nan = dir.write("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
        let message = Scene::load(&nan).unwrap_err().to_string();
        assert!(message.contains("nan.obj") && message.contains("vertex 1"), "{message}");
        let message = Scene::load(&dir.0.join("absent.obj")).unwrap_err().to_string();
        assert!(message.contains("absent.obj"), "{message}");
        let message = Scene::load_obj_files(&[bad.clone(), dir.0.join("gone.obj")]).unwrap_err().to_string();
        assert!(message.contains("bad.obj"), "the first bad file is named: {message}");
    }

    #[test]
    fn scene_obj_files_are_one_scene() {
        let cornell = cornell_dir();
        let parts = ["light.obj", "floor.obj"].map(|f| cornell.join(f));
        let scene = Scene::load_obj_files(&parts).unwrap();
        assert_eq!(scene.path, parts[0]);
        assert_eq!((scene.mesh.triangle_count(), scene.materials.len()), (4, 2));
        assert!(scene.materials[scene.mesh.material_ids[0] as usize].is_emissive());
        // The directory loader takes the parts in file-name order: back.obj first.
        let dir = Scene::load(&cornell).unwrap();
        assert_eq!(dir.mesh.corners(0)[0], Vec3::new(5.496, 0.0, 5.592));
    }
}
