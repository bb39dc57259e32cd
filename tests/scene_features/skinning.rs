//! Skinned and morphing meshes posed where Blender poses them: the Khronos sample models, loaded and
//! posed at a scene time, against the vertices of Blender's evaluated mesh at the same frame
//! (`benches/peers/cycles/posed.py`, Blender 5.0.1's importer; tests/data/posed/README.md).

use glam::Vec3;
use std::path::{Path, PathBuf};

/// The sample corpus beside the checkout, or `None` (a note, and a failure under CI).
fn sample(name: &str) -> Option<PathBuf> {
    let path =
        Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("../shared/gltf-samples/{name}/glTF/{name}.gltf"));
    if path.exists() {
        return Some(path);
    }
    assert!(std::env::var_os("MCCTRACE_CI").is_none(), "{} is missing under CI", path.display());
    eprintln!("skipped: {} is not here", path.display());
    None
}

/// Blender's posed vertices (little-endian f32 triples, glTF axes).
fn blender(file: &str) -> Vec<Vec3> {
    let bytes =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/posed").join(file)).unwrap();
    bytes
        .chunks_exact(12)
        .map(|c| {
            let f = |i: usize| f32::from_le_bytes(c[i..i + 4].try_into().unwrap());
            Vec3::new(f(0), f(4), f(8))
        })
        .collect()
}

/// The largest distance from a point of `a` to its nearest point of `b` (brute force).
fn one_sided(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter()
        .map(|p| b.iter().map(|q| p.distance_squared(*q)).fold(f32::MAX, f32::min))
        .fold(0.0, f32::max)
        .sqrt()
}

/// Poses `name` at each time and compares with Blender's vertices: both point sets within
/// `tolerance` × the model's extent of each other (Hausdorff distance).
fn check(name: &str, stem: &str, times_ms: &[u32], tolerance: f32) {
    let Some(path) = sample(name) else { return };
    let scene = super::harness::load(&path);
    // The pose at load (t = 0): some compared time must differ from it, so the check has teeth.
    let bind: Vec<Vec3> = scene.mesh.positions.clone();
    let mut most_moved = 0.0f32;
    for &ms in times_ms {
        let posed = scene.at_time(ms as f32 / 1000.0).unwrap();
        let ours = &posed.mesh.positions;
        let theirs = blender(&format!("{stem}-t{ms}.f32"));
        let (lo, hi) = posed.bounds().unwrap();
        let extent = (hi - lo).max_element();
        let d = one_sided(ours, &theirs).max(one_sided(&theirs, ours));
        assert!(d <= tolerance * extent, "{name} at {ms} ms: {d} from Blender's pose (extent {extent})");
        let moved = ours.iter().zip(&bind).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
        most_moved = most_moved.max(moved / extent);
    }
    assert!(most_moved > 100.0 * tolerance, "{name}: no compared time moves the mesh ({most_moved})");
}

#[test]
fn rigged_simple_is_posed_as_blender_poses_it() {
    check("RiggedSimple", "rigged_simple", &[250, 1000, 1750], 1e-5);
}

#[test]
fn rigged_figure_is_posed_as_blender_poses_it() {
    // Its samplers have two keys, at 0 and 1.25 s: between them Blender interpolates each
    // quaternion component and glTF slerps (docs/cycles.md), so the frames compared are the keys.
    check("RiggedFigure", "rigged_figure", &[0, 1250], 1e-5);
}

#[test]
fn cesium_man_is_posed_as_blender_poses_it() {
    check("CesiumMan", "cesium_man", &[250, 1000, 1625], 1e-5);
}

#[test]
fn simple_skin_is_posed_as_blender_poses_it() {
    check("SimpleSkin", "simple_skin", &[1000, 2500, 4250], 1e-5);
}

#[test]
fn animated_morph_cube_is_morphed_as_blender_morphs_it() {
    check("AnimatedMorphCube", "animated_morph_cube", &[500, 1250, 2000], 1e-5);
}

#[test]
fn simple_morph_is_morphed_as_blender_morphs_it() {
    check("SimpleMorph", "simple_morph", &[500, 1500, 2500], 1e-5);
}

#[test]
fn animated_morph_sphere_is_morphed_as_blender_morphs_it() {
    check("AnimatedMorphSphere", "animated_morph_sphere", &[1000, 3000, 5500], 1e-5);
}

#[test]
fn morph_primitives_test_takes_its_mesh_weights() {
    // Static: the mesh's default weight 0.5 displaces both primitives at load.
    let Some(path) = sample("MorphPrimitivesTest") else { return };
    let scene = super::harness::load(&path);
    let theirs = blender("morph_primitives-t0.f32");
    let ours = &scene.mesh.positions;
    let (lo, hi) = scene.bounds().unwrap();
    let d = one_sided(ours, &theirs).max(one_sided(&theirs, ours));
    assert!(d <= 1e-5 * (hi - lo).max_element(), "{d} from Blender's mesh");
}

#[test]
fn fox_plays_its_first_take_as_blender_does() {
    // Three takes over the same joints (Survey, Walk, Run): the first plays, as Blender's
    // importer makes it the active action.
    check("Fox", "fox", &[500, 1500, 2750], 1e-5);
}

#[test]
fn recursive_skeletons_are_posed_as_blender_poses_them() {
    // Keys at 0, 1 and 2 s: between them Blender interpolates each quaternion component and
    // glTF slerps (as for RiggedFigure), so the frames compared are the keys.
    check("RecursiveSkeletons", "recursive_skeletons", &[1000, 2000], 1e-5);
}

/// Every Khronos sample that skins, morphs or animates its nodes loads without a warning and
/// poses without one over its clip (held past the end), every vertex finite.
#[test]
fn the_animated_samples_load_and_pose_without_warnings() {
    let names = [
        "CesiumMan",
        "Fox",
        "RiggedFigure",
        "RiggedSimple",
        "SimpleSkin",
        "RecursiveSkeletons",
        "AnimatedMorphCube",
        "AnimatedMorphSphere",
        "MorphPrimitivesTest",
        "SimpleMorph",
        "InterpolationTest",
    ];
    for name in names {
        let Some(path) = sample(name) else { continue };
        let scene = super::harness::load(&path);
        for t in [0.0, 0.3, 1.0, 2.5, 100.0] {
            let posed = scene.at_time(t).unwrap_or_else(|e| panic!("{name} at {t} s: {e}"));
            assert!(posed.warnings.is_empty(), "{name} at {t} s: {:?}", posed.warnings);
            assert!(posed.mesh.positions.iter().all(|p| p.is_finite()), "{name} at {t} s");
        }
    }
}
