//! Tests of the OBJ/MTL loader (`obj/mod.rs`).

use super::super::gltf::tests::{TempDir, cornell_dir};
use super::super::{GltfReading, Scene};
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
    // The two texture files do not exist: a warning each, naming it; the slots stay empty.
    assert!(shiny.textures.is_empty() && scene.textures.is_empty());
    let warnings = scene.warnings.join("\n");
    assert!(warnings.contains("quad.obj") && warnings.contains("'shiny'"), "{warnings}");
    assert!(
        warnings.contains("map_Kd 'wood.png': cannot read") && warnings.contains("wood.png"),
        "{warnings}"
    );
    assert!(warnings.contains("map_Bump/bump 'b.png': cannot read"), "{warnings}");
    assert_eq!(scene.warnings.len(), 2, "{warnings}");
}

/// Texture maps with options, emissive maps without Ke, normal maps, dissolve, glass.
#[test]
fn scene_obj_textures_alpha_and_glass() {
    use crate::material::AlphaMode;
    use crate::texture::{TextureRef, Wrap};
    use image::{DynamicImage, ImageBuffer, Luma, Rgb, Rgba};
    let dir = TempDir::new("obj-textures");
    std::fs::create_dir(dir.0.join("maps")).unwrap();
    let save = |name: &str, image: DynamicImage| image.save(dir.0.join(name)).unwrap();
    save("maps/leaf.png", DynamicImage::ImageRgba8(ImageBuffer::from_pixel(2, 2, Rgba([128u8, 255, 0, 0]))));
    save("maps/glow.png", DynamicImage::ImageRgb8(ImageBuffer::from_pixel(1, 1, Rgb([128u8, 128, 128]))));
    save("maps/n.png", DynamicImage::ImageRgb8(ImageBuffer::from_pixel(1, 1, Rgb([128u8, 128, 255]))));
    save("maps/height.png", DynamicImage::ImageLuma8(ImageBuffer::from_pixel(1, 1, Luma([128u8]))));
    dir.write("maps/junk.png", b"junk");
    let mtl = "newmtl leaf\nKd 1 1 1\nmap_Kd -o 0.5 0.25 -s 2 2 -clamp on maps/leaf.png\nmap_d maps/leaf.png\n\
               norm -bm 0.5 -texres 64 maps/n.png\n\
               newmtl glow\nmap_Ke maps/glow.png\nd 0.5\n\
               newmtl tr\nTr 0.25\nbump maps/height.png\nmap_Ka maps/leaf.png\n\
               newmtl glass\nKd 0 0 0\nillum 7\nNi 1.33\nTf 0.9 1 0.9\n\
               newmtl junk\nmap_Kd maps/junk.png\nmap_d other.png\nillum 4\nNi 0\n";
    dir.write("m.mtl", mtl);
    let mut obj = String::from("mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n");
    for name in ["leaf", "glow", "tr", "glass", "junk"] {
        obj += &format!("usemtl {name}\nf 1/1 2/2 3/3\n");
    }
    let scene = Scene::load(&dir.write("t.obj", obj)).unwrap();
    let m = |name: &str| scene.materials.iter().find(|m| m.name == name).unwrap();

    // leaf: sRGB base colour with -o/-s as a transform of the v-down coordinates, clamped;
    // map_d is the map_Kd image, so its alpha cuts out; the normal map with -bm's scale.
    let leaf = m("leaf");
    let base = leaf.textures.base_color.unwrap();
    let transform = crate::texture::uv_transform(Vec2::new(0.5, 1.0 - 2.0 - 0.25), 0.0, Vec2::splat(2.0));
    assert_eq!(
        base,
        TextureRef {
            transform: Some(transform),
            wrap: [Wrap::ClampToEdge; 2],
            ..TextureRef::new(base.texture)
        }
    );
    // An OBJ coordinate (u, v) = (0.1, 0.2) is stored as (0.1, 0.8); MTL reads the image at
    // t = 2·(0.1, 0.2) + (0.5, 0.25) = (0.7, 0.65) from the bottom, i.e. row 0.35 from the top.
    let st = transform.transform_point2(Vec2::new(0.1, 0.8));
    assert!((st - Vec2::new(0.7, 0.35)).length() < 1e-6, "{st}");
    let t = &scene.textures[base.texture as usize];
    let texel = t.linear_texel(0);
    assert!((texel.x - 0.215_860_5).abs() < 1e-6 && texel.w == 0.0, "{texel}");
    assert_eq!(leaf.alpha_mode, AlphaMode::Mask { cutoff: 0.5 });
    let (normal, scale) = leaf.textures.normal.unwrap();
    assert_eq!(scale, 0.5);
    assert!((scene.textures[normal.texture as usize].texels.get(0).x - 128.0 / 255.0).abs() < 1e-6, "linear");

    // glow: Ke 1 under map_Ke; d 0.5 blends.
    let glow = m("glow");
    assert_eq!((glow.emission, glow.alpha, glow.alpha_mode), (Vec3::ONE, 0.5, AlphaMode::Blend));
    assert!(glow.textures.emissive.is_some());
    // tr: Tr 0.25 is d 0.75; the greyscale bump map is a height map, refused.
    let tr = m("tr");
    assert_eq!((tr.alpha, tr.alpha_mode, tr.textures.normal), (0.75, AlphaMode::Blend, None));
    // glass: transmission 1, ior Ni, tinted by Tf (not Kd).
    let glass = m("glass");
    assert_eq!((glass.transmission, glass.ior, glass.base_color), (1.0, 1.33, Vec3::new(0.9, 1.0, 0.9)));
    // It refracts in either reading of glTF: `--gltf-reading spec` does not make it a thin wall.
    let mut spec = scene.clone();
    spec.set_reading(GltfReading::Spec);
    assert!(spec.materials.iter().all(|m| !m.thin_walled) && !glass.thin_walled);
    // junk: the undecodable map is left out (and with it the cut-out); Ni 0 is no glass ior.
    let junk = m("junk");
    assert_eq!((junk.textures.base_color, junk.alpha_mode, junk.ior), (None, AlphaMode::Opaque, 1.5));

    let warnings = scene.warnings.join("\n");
    for needle in [
        "material 'leaf'",
        "options ignored: -texres 64",
        "material 'tr'",
        "height.png is greyscale, a height map",
        "not supported, ignored: map_Ka",
        "map_Kd 'maps/junk.png'",
        "not a PNG, JPEG, TIFF or WebP",
        "map_d (only a map_d naming the map_Kd image is used, as its alpha)",
        "Ni 0 is below 1",
    ] {
        assert!(warnings.contains(needle), "no '{needle}' in\n{warnings}");
    }
    assert!(scene.warnings.iter().all(|w| w.contains("t.obj")), "{warnings}");
    assert_eq!(scene.warnings.len(), 6, "{warnings}");
}

#[test]
fn scene_obj_map_options() {
    use super::MapSpec;
    let s = MapSpec::parse("-s 2 3 -o 0.5 -bm 0.25 -blendu off my file.png").unwrap();
    assert_eq!((s.scale, s.offset, s.bump_scale), ([2.0, 3.0], [0.5, 0.0], Some(0.25)));
    assert_eq!((s.file.as_str(), s.ignored_options.clone()), ("my file.png", vec!["-blendu off".to_owned()]));
    assert!(MapSpec::parse("-bm").unwrap_err().contains("-bm lacks its value"));
    assert!(MapSpec::parse("-o x.png").unwrap_err().contains("-o lacks its value"));
    assert!(MapSpec::parse("-bm 0.5").unwrap_err().contains("no file name"));
    assert_eq!(MapSpec::parse("plain.png").unwrap().transform(), None);
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

#[test]
fn scene_obj_malformed_mtl_values_are_errors_naming_the_library_and_line() {
    let dir = TempDir::new("obj-bad-mtl");
    let obj = "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl red\nf 1 2 3\n";
    // `Ke 4 4` panicked inside tobj 4.0.5 before the pre-scan; `Kd 0.5` means grey.
    for (mtl, want) in [
        ("newmtl red\nKd 0.5\nKe 4 4\n", "line 3: Ke '4 4' is not one or three numbers"),
        ("newmtl red\nKd 0.8 nan 0.1\n", "line 2: Kd '0.8 nan 0.1' is not finite"),
        ("newmtl red\nillum x\n", "line 2: malformed MTL"),
    ] {
        dir.write("m.mtl", mtl);
        let message = Scene::load(&dir.write("tri.obj", obj)).unwrap_err().to_string();
        assert!(message.contains("m.mtl") && message.contains(want), "{mtl:?}: {message}");
        assert!(message.contains("material library of") && message.contains("tri.obj"), "{message}");
    }
    dir.write("m.mtl", "newmtl red\nKd 0.5\nKe 0.25\n");
    let scene = Scene::load(&dir.write("tri.obj", obj)).unwrap();
    assert_eq!(scene.materials[0].base_color, Vec3::splat(0.5));
    assert_eq!(scene.materials[0].emission, Vec3::splat(0.25));
}

#[test]
fn scene_obj_unknown_statements_warn_and_faceless_files_are_refused() {
    let dir = TempDir::new("obj-statements");
    let scene = Scene::load(&dir.write("odd.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nfoo bar\nf 1 2 3\n")).unwrap();
    assert_eq!(scene.mesh.triangle_count(), 1);
    let warnings = scene.warnings.join("\n");
    assert!(warnings.contains("odd.obj: line 4: unknown statement 'foo'; ignored"), "{warnings}");
    for (name, text) in [("empty.obj", ""), ("points.obj", "v 0 0 0\nv 1 0 0\n# no faces\n")] {
        let message = Scene::load(&dir.write(name, text)).unwrap_err().to_string();
        assert!(message.contains(name) && message.contains("no faces"), "{message}");
    }
}
