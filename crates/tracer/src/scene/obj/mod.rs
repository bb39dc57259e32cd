//! OBJ/MTL loader (tobj): one or several OBJ files, or every `*.obj` of a directory, form one
//! scene. Faces are triangulated; positions, normals and texture coordinates go into the mesh
//! (OBJ's v runs up from the image's bottom: it is flipped to glTF's v-down convention).
//!
//! MTL parameters map onto the glTF-style [`Material`]:
//! - `Kd` → base colour; metallic 0. `map_Kd` → sRGB base colour texture.
//! - `Ke` → emitted radiance from the **front face only** (`emission_two_sided = false`): the
//!   counter-clockwise side, as the Cornell reference's one-sided light. OBJ has no way to say
//!   "two-sided emitter", and a one-sided rule is what a light fixture modelled as a quad needs.
//!   `map_Ke` → sRGB emissive texture (scaling `Ke`; `Ke` 1 when only the map is given).
//! - `Ks`, `Ns` → the `KHR_materials_specular` layer: specular 1 with specular colour Ks / 0.04,
//!   so the dielectric F0 = min(0.04 · colour, 1) is Ks itself; the Blinn–Phong exponent Ns maps
//!   to the Beckmann-equivalent α = sqrt(2 / (Ns + 2)) and roughness = sqrt(α). No `Ks` (or a
//!   black one) leaves a pure Lambertian surface (specular 0). `illum` 3 and 5 (ray-traced
//!   reflection) keep this mapping.
//! - `map_Bump`, `bump`, `norm` → a **tangent-space normal map** (glTF's convention), with `-bm`
//!   as its scale. MTL's `bump` is classically a height map, which this renderer cannot use: a
//!   greyscale image there is reported and ignored; an RGB one is taken for the normal map that
//!   modern exporters write.
//! - `d` (dissolve) → alpha, and `Tr` = 1 − d when `d` is absent; alpha below 1 makes the
//!   material `AlphaMode::Blend`. `map_d` naming the `map_Kd` image uses that image's alpha as a
//!   cut-out (`AlphaMode::Mask` at 0.5, or `Blend` with d < 1).
//! - `illum` 4, 6, 7 (refraction, glass) → transmission 1 with the index of refraction `Ni`
//!   (1.5 when absent or below 1). Glass is tinted by `Tf` (white when absent): `Kd`, a diffuse
//!   colour, does not apply to it.
//! - Texture options: `-o` and `-s` (offset, scale of u and v) become a texture transform,
//!   `-clamp on` clamps, `-bm` scales a normal map; other options are reported and ignored.
//!   Texture files are found relative to the MTL file.
//! - Other maps (`map_Ka`, `map_Ks`, `map_Ns`, `disp`, `refl` …) are ignored, with a warning.
//!
//! A missing MTL file, an unknown material name, a missing or undecodable texture and an unknown
//! OBJ statement are warnings (the surface gets [`Material::default()`], the slot is left empty,
//! the line is skipped): the geometry is still worth rendering. A **malformed** MTL value (`Kd`
//! with two numbers, `Ns x`, a NaN) is an error naming the MTL file and line (`precheck`): the
//! file says something definite that cannot be read, and a silently grey surface would hide it.
//! An OBJ without faces is an error: there is nothing to render.

mod precheck;

use super::images::{self, ColorSpace};
use super::{MeshPart, Scene};
use crate::error::{Result, TracerError};
use crate::material::{AlphaMode, Material, Volume};
use crate::texture::{Filter, TextureRef, Wrap};
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
        textures: HashMap::new(),
    };
    for path in paths {
        loader.load(path)?;
    }
    if loader.scene.mesh.triangle_count() == 0 {
        let what = if paths.len() == 1 { "the OBJ file has" } else { "the OBJ files have" };
        return Err(TracerError::scene(
            first,
            format!("{what} no faces (`f` statements): no triangles to render"),
        ));
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
    /// Scene texture of each (image file, colour space) read so far; `None` once it failed
    /// (reported once).
    textures: HashMap<(PathBuf, ColorSpace), Option<u32>>,
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
        precheck::check_faces(&bytes).map_err(|m| TracerError::scene(path, format!("malformed OBJ: {m}")))?;
        let dir = path.parent().unwrap_or(Path::new("."));
        // tobj's material callback is `Fn`: it records what it loaded and what failed here.
        let libraries = RefCell::new(Vec::<Library>::new());
        let failures = RefCell::new(Vec::<String>::new());
        // A malformed library: (its file, what is wrong); the load fails with the first.
        let malformed = RefCell::new(Vec::<(PathBuf, String)>::new());
        let load_mtl = |name: &Path| {
            let file = dir.join(name);
            let result = match std::fs::read(&file) {
                Ok(text) => {
                    // The pre-scan refuses what would panic tobj (module docs of `precheck`).
                    let parsed = precheck::prescan_mtl(&text).and_then(|text| {
                        tobj::load_mtl_buf(&mut &text[..]).map_err(|e| {
                            let fails = |p: &[u8]| tobj::load_mtl_buf(&mut &p[..]).is_err();
                            match precheck::failing_line(&text, fails) {
                                Some(l) => format!("line {l}: malformed MTL: {e}"),
                                None => format!("malformed MTL: {e}"),
                            }
                        })
                    });
                    parsed.map_err(|m| {
                        malformed.borrow_mut().push((file.clone(), m));
                        tobj::LoadError::MaterialParseError
                    })
                }
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
            let fails = |prefix: &[u8]| {
                let no_mtl = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
                tobj::load_obj_buf(&mut &prefix[..], &options(), no_mtl).is_err()
            };
            let at =
                precheck::failing_line(&bytes, fails).map_or_else(String::new, |l| format!(" at line {l}"));
            TracerError::scene(path, format!("malformed OBJ{at}: {e}"))
        })?;
        if let Some((mtl, message)) = malformed.take().into_iter().next() {
            let message = format!("{message} (material library of {})", path.display());
            return Err(TracerError::scene(mtl, message));
        }
        for warning in precheck::unknown_statements(&bytes) {
            self.warn(path, warning);
        }
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
        let mtl = key.0.clone();
        let label = format!("material '{}' ({})", m.name, mtl.display());
        let Converted { mut material, maps, ignored, notes } = convert(m);
        for note in notes {
            self.warn(obj, format!("{label}: {note}"));
        }
        if !ignored.is_empty() {
            let msg = format!("{label}: not supported, ignored: {}", ignored.join(", "));
            self.warn(obj, msg);
        }
        let dir = mtl.parent().unwrap_or(Path::new(".")).to_owned();
        for (slot, statement, spec) in maps {
            let what = format!("{label}: {statement} '{}'", spec.file);
            if !spec.ignored_options.is_empty() {
                self.warn(obj, format!("{what}: options ignored: {}", spec.ignored_options.join(" ")));
            }
            let space = if slot == Slot::Normal { ColorSpace::Linear } else { ColorSpace::Srgb };
            let Some(reference) = self.texture(obj, &dir, &spec, space, &what, slot == Slot::Normal) else {
                continue;
            };
            let t = &mut material.textures;
            match slot {
                Slot::BaseColor => t.base_color = Some(reference),
                Slot::Emissive => t.emissive = Some(reference),
                Slot::Normal => t.normal = Some((reference, spec.bump_scale.unwrap_or(1.0))),
            }
        }
        // A cut-out needs the base colour texture's alpha; without it, nothing is cut.
        if material.textures.base_color.is_none() && matches!(material.alpha_mode, AlphaMode::Mask { .. }) {
            material.alpha_mode = AlphaMode::Opaque;
        }
        self.scene.materials.push(material);
        let index = (self.scene.materials.len() - 1) as u32;
        self.by_key.insert(key, index);
        index
    }

    /// Reads the image of a texture statement (relative to the MTL's folder `dir`) into a scene
    /// texture, once per file and colour space; `None` (with a warning naming it) when it cannot
    /// be used. `normal` refuses greyscale images (height maps).
    fn texture(
        &mut self,
        obj: &Path,
        dir: &Path,
        spec: &MapSpec,
        space: ColorSpace,
        what: &str,
        normal: bool,
    ) -> Option<TextureRef> {
        // MTL files written on Windows separate folders with backslashes.
        let relative = if cfg!(windows) { spec.file.clone() } else { spec.file.replace('\\', "/") };
        let file = dir.join(relative);
        let index = match self.textures.get(&(file.clone(), space)) {
            Some(found) => *found,
            None => {
                let decoded = std::fs::read(&file)
                    .map_err(|e| format!("cannot read {}: {e}", file.display()))
                    .and_then(|bytes| images::decode(&bytes).map_err(|m| format!("{}: {m}", file.display())))
                    .and_then(|image| {
                        if normal && images::is_greyscale(&image) {
                            Err(format!(
                                "{} is greyscale, a height map; only tangent-space normal maps are supported",
                                file.display()
                            ))
                        } else {
                            Ok(image)
                        }
                    });
                let index = match decoded {
                    Ok(image) => {
                        let texture = images::to_texture(file.display().to_string(), &image, space);
                        self.scene.textures.push(texture);
                        Some((self.scene.textures.len() - 1) as u32)
                    }
                    Err(m) => {
                        self.warn(obj, format!("{what}: {m}; the texture is left out"));
                        None
                    }
                };
                self.textures.insert((file, space), index);
                index
            }
        }?;
        let wrap = if spec.clamp { Wrap::ClampToEdge } else { Wrap::Repeat };
        Some(TextureRef {
            texture: index,
            uv_set: 0,
            transform: spec.transform(),
            wrap: [wrap; 2],
            filter: Filter::Linear,
        })
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

/// A material slot an MTL texture statement fills.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Slot {
    BaseColor,
    Emissive,
    Normal,
}

/// A texture statement's file and options.
#[derive(Clone, Debug, Default, PartialEq)]
struct MapSpec {
    file: String,
    /// `-o u v`: offset in MTL's (v-up) texture space.
    offset: [f32; 2],
    /// `-s u v`: scale.
    scale: [f32; 2],
    /// `-clamp on`.
    clamp: bool,
    /// `-bm`: normal-map scale.
    bump_scale: Option<f32>,
    /// Options read but not supported, as written.
    ignored_options: Vec<String>,
}

impl MapSpec {
    /// Parses `[options] file`: the options MTL defines, each with its arguments; the rest of the
    /// line is the file name (which may contain spaces).
    fn parse(value: &str) -> Result<Self, String> {
        let mut spec = Self { scale: [1.0; 2], ..Self::default() };
        let words: Vec<&str> = value.split_whitespace().collect();
        let mut i = 0;
        let number = |w: &str| w.parse::<f32>().ok().filter(|v| v.is_finite());
        while let Some(&word) = words.get(i) {
            // Options with their fixed argument counts; -o, -s, -t take one to three numbers.
            let fixed = match word {
                "-blendu" | "-blendv" | "-boost" | "-texres" | "-clamp" | "-bm" | "-imfchan" | "-type"
                | "-cc" => 1,
                "-mm" => 2,
                "-o" | "-s" | "-t" => 0,
                _ => break,
            };
            let args: Vec<&str> = if fixed > 0 {
                words
                    .get(i + 1..i + 1 + fixed)
                    .ok_or_else(|| format!("option {word} lacks its value"))?
                    .to_vec()
            } else {
                words[i + 1..].iter().take(3).take_while(|w| number(w).is_some()).copied().collect()
            };
            if args.is_empty() {
                return Err(format!("option {word} lacks its value"));
            }
            let nums: Vec<f32> = args.iter().filter_map(|w| number(w)).collect();
            let want_numbers = matches!(word, "-o" | "-s" | "-bm");
            if want_numbers && nums.len() != args.len() {
                return Err(format!("option {word} needs numbers, not '{}'", args.join(" ")));
            }
            match word {
                "-o" => spec.offset = [nums[0], nums.get(1).copied().unwrap_or(0.0)],
                "-s" => spec.scale = [nums[0], nums.get(1).copied().unwrap_or(1.0)],
                "-bm" => spec.bump_scale = Some(nums[0]),
                "-clamp" => spec.clamp = args[0] == "on",
                _ => spec.ignored_options.push(format!("{word} {}", args.join(" "))),
            }
            i += 1 + args.len();
        }
        spec.file = words[i.min(words.len())..].join(" ");
        if spec.file.is_empty() {
            return Err("no file name".to_owned());
        }
        Ok(spec)
    }

    /// `-o`/`-s` as a texture transform of the mesh's v-down coordinates. MTL applies them in
    /// its v-up space, t = s·uv + o; with v' = 1 − v the lookup row is 1 − t_v =
    /// s_v·v' + (1 − s_v − o_v).
    fn transform(&self) -> Option<glam::Affine2> {
        let ([ou, ov], [su, sv]) = (self.offset, self.scale);
        if (ou, ov, su, sv) == (0.0, 0.0, 1.0, 1.0) {
            return None;
        }
        Some(crate::texture::uv_transform(Vec2::new(ou, 1.0 - sv - ov), 0.0, Vec2::new(su, sv)))
    }
}

/// An MTL material mapped (see the module docs), with the textures still to be read.
struct Converted {
    material: Material,
    /// Texture statements to resolve: slot, statement name, file and options.
    maps: Vec<(Slot, &'static str, MapSpec)>,
    /// Statements not supported, by name.
    ignored: Vec<String>,
    /// Other things worth a warning (bad values, malformed statements).
    notes: Vec<String>,
}

/// Maps one MTL material (see the module docs).
fn convert(m: &tobj::Material) -> Converted {
    let default = Material::default();
    let mut notes = Vec::new();
    let mut ignored = Vec::new();
    let ks = m.specular.map_or(Vec3::ZERO, Vec3::from);
    let (specular, specular_color, roughness) = if ks.max_element() > 0.0 {
        // Ns < 0 is meaningless; clamping keeps the square roots real.
        let ns = m.shininess.unwrap_or(0.0).max(0.0);
        let alpha = (2.0 / (ns + 2.0)).sqrt();
        (1.0, ks / 0.04, alpha.sqrt().clamp(0.0, 1.0))
    } else {
        (0.0, Vec3::ONE, 1.0)
    };
    let param = |key: &str| m.unknown_param.get(key).map(String::as_str);
    let float3 = |key: &str, notes: &mut Vec<String>| -> Option<Vec3> {
        let text = param(key)?;
        let v: Vec<f32> = text.split_whitespace().filter_map(|w| w.parse().ok()).collect();
        match v[..] {
            [x] => Some(Vec3::splat(x)),
            [x, y, z] => Some(Vec3::new(x, y, z)),
            _ => {
                notes.push(format!("{key} '{text}' is not one or three numbers; ignored"));
                None
            }
        }
    };

    // Texture statements.
    let mut maps = Vec::new();
    let mut map = |slot: Slot, statement: &'static str, value: Option<&str>, notes: &mut Vec<String>| {
        let value = value?;
        match MapSpec::parse(value) {
            Ok(spec) => {
                maps.push((slot, statement, spec.clone()));
                Some(spec)
            }
            Err(e) => {
                notes.push(format!("{statement} '{value}': {e}; ignored"));
                None
            }
        }
    };
    let base_map = map(Slot::BaseColor, "map_Kd", m.diffuse_texture.as_deref(), &mut notes);
    let emissive_map = map(Slot::Emissive, "map_Ke", param("map_Ke"), &mut notes);
    // tobj files `map_Bump` and `bump` as the normal texture and leaves `norm` unparsed.
    let (bump_name, bump) = match (&m.normal_texture, param("norm")) {
        (Some(b), _) => ("map_Bump/bump", Some(b.as_str())),
        (None, n) => ("norm", n),
    };
    map(Slot::Normal, bump_name, bump, &mut notes);

    // Alpha: d, else 1 − Tr.
    let tr = param("Tr").map(|t| t.trim().parse::<f32>().map(|tr| 1.0 - tr).map_err(|_| t));
    let alpha = match (m.dissolve, tr) {
        (Some(d), _) => Some(d),
        (None, Some(Ok(a))) => Some(a),
        (None, Some(Err(t))) => {
            notes.push(format!("Tr '{t}' is not a number; ignored"));
            None
        }
        (None, None) => None,
    };
    let alpha = match alpha {
        Some(a) if a.is_finite() && (0.0..=1.0).contains(&a) => a,
        Some(a) => {
            notes.push(format!("dissolve (d or 1 − Tr) {a} is outside [0, 1]; clamped"));
            if a.is_finite() { a.clamp(0.0, 1.0) } else { 1.0 }
        }
        None => 1.0,
    };
    // map_d: only as the alpha of the map_Kd image (a cut-out).
    let cut_out = match (&m.dissolve_texture, &base_map) {
        (Some(d), Some(kd)) if MapSpec::parse(d).is_ok_and(|d| d.file == kd.file) => true,
        (Some(_), _) => {
            ignored.push("map_d (only a map_d naming the map_Kd image is used, as its alpha)".to_owned());
            false
        }
        (None, _) => false,
    };
    let alpha_mode = if alpha < 1.0 {
        AlphaMode::Blend
    } else if cut_out {
        AlphaMode::Mask { cutoff: 0.5 }
    } else {
        AlphaMode::Opaque
    };

    // Glass.
    let glass = matches!(m.illumination_model, Some(4 | 6 | 7));
    let ior = match m.optical_density {
        Some(ni) if ni.is_finite() && ni >= 1.0 => ni,
        Some(ni) if glass => {
            notes.push(format!("Ni {ni} is below 1; glass uses the index of refraction 1.5"));
            1.5
        }
        _ => 1.5,
    };
    let base_color = if glass {
        float3("Tf", &mut notes).unwrap_or(Vec3::ONE)
    } else {
        m.diffuse.map_or(default.base_color, Vec3::from)
    };
    let emission = match (m.emissive, &emissive_map) {
        (Some(ke), _) => Vec3::from(ke),
        (None, Some(_)) => Vec3::ONE,
        (None, None) => Vec3::ZERO,
    };

    let known =
        [("map_Ka", &m.ambient_texture), ("map_Ks", &m.specular_texture), ("map_Ns", &m.shininess_texture)];
    ignored.extend(known.iter().filter(|(_, t)| t.is_some()).map(|(k, _)| (*k).to_owned()));
    let mut other: Vec<String> = m
        .unknown_param
        .keys()
        .filter(|k| {
            (k.starts_with("map_") && k.as_str() != "map_Ke")
                || matches!(k.as_str(), "disp" | "refl" | "decal")
        })
        .cloned()
        .collect();
    other.sort(); // HashMap order is random; warnings must be deterministic
    ignored.extend(other);

    let material = Material {
        name: m.name.clone(),
        base_color,
        metallic: 0.0,
        roughness,
        specular,
        specular_color,
        emission,
        emission_two_sided: false,
        alpha,
        alpha_mode,
        transmission: if glass { 1.0 } else { 0.0 },
        ior,
        // OBJ's refracting illum models bound a solid in every reading: a volume of some
        // thickness, without absorption, keeps `--gltf-reading spec` from making it a thin wall.
        volume: glass.then_some(Volume {
            thickness: f32::INFINITY,
            colour: Vec3::ONE,
            distance: f32::INFINITY,
        }),
        ..Material::default()
    };
    Converted { material, maps, ignored, notes }
}

#[cfg(test)]
mod tests;
