//! The café of the MCC column's opening example: a couple seated facing each other at a round
//! table, a counter with stools behind, daylight from a window, a ceiling panel and a pendant
//! spot. `mcctrace-scenegen cafe DIR` writes `cafe.gltf` + `cafe.bin`, the texture PNGs and
//! the collage label and region images for the MCC demo; every run writes the same bytes.
//!
//! Units are metres, +y up. The couple's table stands in a "seating group" node (turned a little
//! in the room) holding the table, both chairs, both figures, the table props and the pendant.

mod figures;
mod furniture;
mod masks;
mod materials;
mod mesh;
#[cfg(test)]
mod preview;
mod props;
mod room;
mod staging;
mod textures;

use crate::gltf_writer::{GltfBuilder, look_at_rotation, quat_json, vec3_json, write_atomic, write_json};
use anyhow::{Context, Result};
use glam::{Quat, Vec3};
use materials::Mat;
use mesh::Mesh;
use serde_json::json;
use std::collections::BTreeMap;
use std::path::Path;

/// One glTF mesh: a primitive per material.
pub struct Object {
    pub name: String,
    pub parts: BTreeMap<Mat, Mesh>,
}

impl Object {
    pub fn new(name: &str) -> Object {
        Object { name: name.to_owned(), parts: BTreeMap::new() }
    }

    /// Adds `mesh` to the primitive of material `mat`.
    pub fn add(&mut self, mat: Mat, mesh: Mesh) {
        self.parts.entry(mat).or_default().append(mesh);
    }

    pub fn triangle_count(&self) -> usize {
        self.parts.values().map(Mesh::triangle_count).sum()
    }
}

/// A scene node: an object (or none, for a group), its transform relative to its parent, and
/// its children.
pub struct SceneNode {
    pub name: String,
    pub object: Option<usize>,
    pub translation: Vec3,
    pub rotation: Quat,
    pub children: Vec<usize>,
}

pub struct Scene {
    pub objects: Vec<Object>,
    pub nodes: Vec<SceneNode>,
    pub roots: Vec<usize>,
}

impl Scene {
    fn object(&mut self, o: Object) -> usize {
        self.objects.push(o);
        self.objects.len() - 1
    }

    fn node(&mut self, name: &str, object: Option<usize>, translation: Vec3, rotation: Quat) -> usize {
        self.nodes.push(SceneNode { name: name.to_owned(), object, translation, rotation, children: vec![] });
        self.nodes.len() - 1
    }

    /// Triangles as rendered (instanced meshes counted once per node).
    pub fn rendered_triangles(&self) -> usize {
        self.nodes.iter().filter_map(|n| n.object).map(|o| self.objects[o].triangle_count()).sum()
    }

    /// Triangles stored in the buffer.
    pub fn stored_triangles(&self) -> usize {
        self.objects.iter().map(Object::triangle_count).sum()
    }
}

/// The whole café.
pub fn build() -> Scene {
    let mut s = Scene { objects: vec![], nodes: vec![], roots: vec![] };
    let world = |s: &mut Scene, o: Object| {
        let name = o.name.clone();
        let obj = s.object(o);
        let n = s.node(&name, Some(obj), Vec3::ZERO, Quat::IDENTITY);
        s.roots.push(n);
    };
    world(&mut s, room::room());
    world(&mut s, room::window());
    world(&mut s, room::ceiling_panel());
    world(&mut s, room::painting());
    world(&mut s, furniture::counter());
    world(&mut s, furniture::back_bar(staging::ROOM_Z.1));
    // Instanced props: one mesh, many nodes.
    let bottle = s.object(furniture::bottle(false));
    let carafe = s.object(furniture::bottle(true));
    for (k, (at, is_carafe)) in furniture::bottles(staging::ROOM_Z.1).into_iter().enumerate() {
        let n = s.node(
            &format!("bottle_{}", k + 1),
            Some(if is_carafe { carafe } else { bottle }),
            at,
            Quat::IDENTITY,
        );
        s.roots.push(n);
    }
    let cup_on_saucer = s.object(props::cup(true));
    let cup = s.object(props::cup(false));
    let (bar, tray) = furniture::counter_cups();
    for (k, (at, angle)) in bar.into_iter().enumerate() {
        let n = s.node(&format!("bar_cup_{}", k + 1), Some(cup_on_saucer), at, Quat::from_rotation_y(angle));
        s.roots.push(n);
    }
    for (k, (at, angle)) in tray.into_iter().enumerate() {
        let n = s.node(&format!("tray_cup_{}", k + 1), Some(cup), at, Quat::from_rotation_y(angle));
        s.roots.push(n);
    }
    let stool = s.object(furniture::stool());
    for (k, x) in [-1.5f32, -0.5, 0.5, 1.5].into_iter().enumerate() {
        let n = s.node(
            &format!("bar_stool_{}", k + 1),
            Some(stool),
            Vec3::new(x, 0.0, 1.92),
            Quat::from_rotation_y(0.7 * k as f32),
        );
        s.roots.push(n);
    }
    // The seating group.
    let group = s.node("seating_group", None, staging::GROUP_TRANSLATION, staging::group_rotation());
    s.roots.push(group);
    let mut children = vec![];
    let table = s.object(furniture::table());
    children.push(s.node("table", Some(table), Vec3::ZERO, Quat::IDENTITY));
    let chair = s.object(furniture::chair());
    for (name, style, b) in [("a", &figures::FIGURE_A, false), ("b", &figures::FIGURE_B, true)] {
        let (at, turn) = staging::seat(b);
        children.push(s.node(&format!("chair_{name}"), Some(chair), at, turn));
        let fig = s.object(figures::figure(style));
        children.push(s.node(style.name, Some(fig), at, turn));
    }
    for ((at, angle), who) in props::TABLE_CUPS.into_iter().zip(["a", "b"]) {
        children.push(s.node(&format!("cup_{who}"), Some(cup_on_saucer), at, Quat::from_rotation_y(angle)));
    }
    let props = s.object(props::table_props());
    children.push(s.node("table_props", Some(props), Vec3::ZERO, Quat::IDENTITY));
    let pendant = s.object(room::pendant());
    children.push(s.node("pendant", Some(pendant), Vec3::ZERO, Quat::IDENTITY));
    s.nodes[group].children = children;
    s
}

/// Writes the scene, its textures and the collage images into `dir`.
pub fn cafe(dir: &Path) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let scene = build();
    let textures = textures::all();
    let mut doc = GltfBuilder::new();
    let repeat =
        doc.add_sampler(json!({ "magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497 }));
    let clamp =
        doc.add_sampler(json!({ "magFilter": 9729, "minFilter": 9987, "wrapS": 33071, "wrapT": 33071 }));
    for (k, t) in textures.iter().enumerate() {
        let file = format!("{}.png", t.name);
        write_atomic(&dir.join(&file), &t.png()?)?;
        let image = doc.add_image(&file, t.name);
        let sampler = if k == materials::tex::PAINTING { clamp } else { repeat };
        doc.add_texture(image, sampler);
    }
    for m in Mat::ALL {
        doc.add_material(m.json());
        for e in m.extensions() {
            doc.use_extension(e);
        }
    }
    for o in &scene.objects {
        let mut primitives = vec![];
        for (mat, mesh) in &o.parts {
            let mut attributes = json!({
                "POSITION": doc.vec3_accessor(&mesh.positions, true),
                "NORMAL": doc.vec3_accessor(&mesh.normals, false),
            });
            if mat.textured() {
                attributes["TEXCOORD_0"] = json!(doc.vec2_accessor(&mesh.uvs));
            }
            if mat.normal_mapped() {
                assert_eq!(
                    mesh.tangents.len(),
                    mesh.positions.len(),
                    "{}: a normal-mapped part needs tangents",
                    o.name
                );
                attributes["TANGENT"] = json!(doc.vec4_accessor(&mesh.tangents));
            }
            let indices = doc.index_accessor(&mesh.indices, mesh.positions.len());
            primitives.push(
                json!({ "attributes": attributes, "indices": indices, "material": mat.index(), "mode": 4 }),
            );
        }
        doc.add_mesh(json!({ "name": o.name, "primitives": primitives }));
    }
    for n in &scene.nodes {
        let mut node = json!({ "name": n.name });
        if let Some(o) = n.object {
            node["mesh"] = json!(o);
        }
        if n.translation != Vec3::ZERO {
            node["translation"] = vec3_json(n.translation);
        }
        if n.rotation != Quat::IDENTITY {
            node["rotation"] = quat_json(n.rotation);
        }
        if !n.children.is_empty() {
            node["children"] = json!(n.children);
        }
        doc.add_node(node);
    }
    let mut roots = scene.roots.clone();
    for cam in staging::cameras() {
        let index = doc.add_camera(json!({
            "name": cam.name,
            "type": "perspective",
            "perspective": {
                "yfov": f64::from(cam.yfov_deg).to_radians(),
                "aspectRatio": 16.0 / 9.0,
                "znear": 0.01,
            },
        }));
        roots.push(doc.add_node(json!({
            "name": cam.name,
            "camera": index,
            "translation": vec3_json(cam.eye),
            "rotation": quat_json(look_at_rotation(cam.eye, cam.target, Vec3::Y)),
        })));
    }
    let light = doc.add_light(json!({
        "name": "pendant_spot",
        "type": "spot",
        "color": staging::SPOT_COLOR,
        "intensity": staging::spot_candela(),
        "spot": { "innerConeAngle": staging::SPOT_INNER, "outerConeAngle": staging::SPOT_OUTER },
    }));
    let spot_at = staging::group_to_world().transform_point3(staging::SPOT_POSITION);
    roots.push(doc.add_node(json!({
        "name": "pendant_spot",
        "translation": vec3_json(spot_at),
        // Local −z turned to point straight down.
        "rotation": quat_json(Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2)),
        "extensions": { "KHR_lights_punctual": { "light": light } },
    })));
    let (gltf, bin) = doc.finish("cafe", Some(roots), "cafe.bin");
    write_atomic(&dir.join("cafe.bin"), &bin)?;
    write_json(&dir.join("cafe.gltf"), &gltf)?;
    let (labels, regions) = masks::collage_images();
    write_atomic(&dir.join("collage-mask.png"), &labels)?;
    write_atomic(&dir.join("collage-mask-regions.png"), &regions)?;
    println!(
        "wrote {}: {} triangles rendered ({} stored in {} meshes), {} materials, {} textures, 3 cameras, 1 spot light",
        dir.join("cafe.gltf").display(),
        scene.rendered_triangles(),
        scene.stored_triangles(),
        scene.objects.len(),
        Mat::ALL.len(),
        textures.len(),
    );
    Ok(())
}
