//! The malformed-input corpus (`tests/bad_inputs/`): scene, environment-map, camera-list and empty-file cases.

use super::case::*;
use super::encoders::*;

/// Scenes (glTF, GLB, OBJ/MTL), environment maps, camera lists and empty files.
pub(crate) fn scene_cases(add: &mut impl FnMut(Case)) {
    // ---- glTF (text, committed) -------------------------------------------------------------
    let g = "glTF";
    add(render(g, "gltf-control", "gltf/ok-triangle.gltf").succeeds(RENDER_OUTPUTS));
    add(render(g, "gltf-truncated-json", "gltf/truncated-json.gltf").fails(&[
        "truncated-json.gltf",
        "malformed glTF JSON",
        "EOF",
    ]));
    add(render(g, "gltf-not-json", "gltf/not-json.gltf").fails(&["not-json.gltf", "malformed glTF JSON"]));
    add(render(g, "gltf-wrong-type", "gltf/wrong-type.gltf").fails(&[
        "wrong-type.gltf",
        "malformed glTF JSON",
        "invalid type",
        "three",
    ]));
    add(render(g, "gltf-nodes-not-array", "gltf/nodes-not-array.gltf").fails(&[
        "nodes-not-array.gltf",
        "malformed glTF JSON",
        "invalid type",
    ]));
    add(render(g, "gltf-dangling-accessor", "gltf/dangling-accessor.gltf").fails(&[
        "dangling-accessor.gltf",
        "POSITION",
        "Index out of range",
    ]));
    add(render(g, "gltf-dangling-node", "gltf/dangling-node.gltf").fails(&[
        "dangling-node.gltf",
        "scenes[0].nodes[2]",
        "Index out of range",
    ]));
    add(render(g, "gltf-dangling-material", "gltf/dangling-material.gltf").fails(&[
        "dangling-material.gltf",
        "material",
        "Index out of range",
    ]));
    add(render(g, "gltf-accessor-past-buffer", "gltf/accessor-past-buffer.gltf")
        .fails(&["accessor-past-buffer.gltf", "accessor 0"]));
    add(render(g, "gltf-view-past-buffer", "gltf/view-past-buffer.gltf")
        .fails(&["view-past-buffer.gltf", "buffer view 0"]));
    add(render(g, "gltf-index-out-of-range", "gltf/index-out-of-range.gltf")
        .fails(&["index-out-of-range.gltf", "index 7 out of range for 3 vertices"]));
    add(render(g, "gltf-nan-vertex", "gltf/nan-vertex.gltf")
        .fails(&["nan-vertex.gltf", "vertex 1 has a non-finite position"]));
    add(render(g, "gltf-missing-buffer", "gltf/missing-buffer.gltf").fails(&[
        "missing-buffer.gltf",
        "buffer 0",
        "no-such-buffer.bin",
    ]));
    add(render(g, "gltf-short-buffer", "gltf/short-buffer.gltf").fails(&[
        "short-buffer.gltf",
        "buffer 0",
        "68 bytes but the glTF declares 6800",
    ]));
    add(render(g, "gltf-bad-data-uri", "gltf/bad-data-uri.gltf").fails(&[
        "bad-data-uri.gltf",
        "buffer 0",
        "invalid base64 character",
    ]));
    add(render(g, "gltf-version-1", "gltf/version-1.gltf")
        .fails(&["version-1.gltf", "glTF version 1.0 is not supported"]));
    add(render(g, "gltf-required-extension", "gltf/required-draco.gltf")
        .fails(&["required-draco.gltf", "requires extension KHR_draco_mesh_compression"]));
    // Draco listed only as used: its accessors have no data of their own, which was refused
    // as "all-zero accessors" without naming Draco (issue 41, item 9).
    add(render(g, "gltf-draco-used-only", "gltf/draco-used-only.gltf").fails(&[
        "draco-used-only.gltf",
        "accessor 0",
        "compressed with Draco (KHR_draco_mesh_compression",
        "no Draco decoder",
        "without Draco mesh compression",
    ]));
    add(render(g, "gltf-camera-without-projection", "gltf/camera-without-projection.gltf")
        .fails(&["camera-without-projection.gltf", "lacks the projection object"]));
    add(render(g, "gltf-node-cycle", "gltf/node-cycle.gltf")
        .fails(&["node-cycle.gltf", "reached twice in the node hierarchy"]));
    add(Case::new(g, "gltf-missing-texture")
        .corpus("gltf/missing-texture.gltf")
        .args(&format!("render {{dir}}/missing-texture.gltf {QUICK} --out {{out}}/render.exr"))
        .warns(&["warning:", "missing-texture.gltf", "no-such-texture.png"], RENDER_OUTPUTS));
    add(Case::new(g, "scene-missing-file")
        .args(&format!("render {{dir}}/no-such-scene.gltf {QUICK} -q --out {{out}}/render.exr"))
        .fails(&["no-such-scene.gltf", "No such file"]));
    add(render_bytes(g, "scene-unknown-format", "scene.fbx", b"Kaydara FBX Binary  \0".to_vec())
        .fails(&["scene.fbx", "unknown scene format"]));

    // ---- GLB (binary, generated) ------------------------------------------------------------
    let g = "GLB";
    let good = glb(GLB_JSON.as_bytes(), Some(&triangle_buffer()));
    add(render_bytes(g, "glb-control", "ok.glb", good.clone()).succeeds(RENDER_OUTPUTS));
    let mut bad_magic = good.clone();
    bad_magic[..4].copy_from_slice(b"glTX");
    add(render_bytes(g, "glb-bad-magic", "bad-magic.glb", bad_magic).fails(&["bad-magic.glb", "malformed"]));
    // The file ends 20 bytes into the BIN chunk; the header's total length is made to agree.
    let mut cut = good[..good.len() - 20].to_vec();
    let len = cut.len() as u32;
    cut[8..12].copy_from_slice(&len.to_le_bytes());
    add(render_bytes(g, "glb-truncated-chunk", "truncated-chunk.glb", cut).fails(&[
        "truncated-chunk.glb",
        "malformed GLB",
        "declares 68 bytes but only 48 remain",
    ]));
    let mut long = good.clone();
    let len = good.len() as u32 + 100;
    long[8..12].copy_from_slice(&len.to_le_bytes());
    add(render_bytes(g, "glb-wrong-total-length", "wrong-total-length.glb", long).fails(&[
        "wrong-total-length.glb",
        "malformed GLB",
        "header declares",
    ]));
    // The JSON chunk claims 8 bytes more than it has: it swallows the BIN chunk's header.
    let mut chunk = good.clone();
    let json_len = u32::from_le_bytes(chunk[12..16].try_into().unwrap()) + 8;
    chunk[12..16].copy_from_slice(&json_len.to_le_bytes());
    add(render_bytes(g, "glb-wrong-chunk-length", "wrong-chunk-length.glb", chunk)
        .fails(&["wrong-chunk-length.glb", "malformed GLB"]));
    let mut v1 = good.clone();
    v1[4..8].copy_from_slice(&1u32.to_le_bytes());
    add(render_bytes(g, "glb-version-1", "version-1.glb", v1)
        .fails(&["version-1.glb", "GLB container version 1 is not supported"]));
    add(render_bytes(
        g,
        "glb-short-bin",
        "short-bin.glb",
        glb(GLB_JSON.as_bytes(), Some(&triangle_buffer()[..40])),
    )
    .fails(&["short-bin.glb", "buffer 0 (the GLB binary chunk) has 40 bytes but the glTF declares 68"]));
    add(render_bytes(g, "glb-no-bin", "no-bin.glb", glb(GLB_JSON.as_bytes(), None))
        .fails(&["no-bin.glb", "refers to the GLB binary chunk, but there is none"]));
    add(render_bytes(g, "glb-truncated-header", "truncated-header.glb", good[..10].to_vec())
        .fails(&["truncated-header.glb", "GLB header is truncated"]));

    // ---- OBJ / MTL (text, committed) --------------------------------------------------------
    add(render_obj("obj-control", "obj/ok-triangle.obj", true).succeeds(RENDER_OUTPUTS));
    // Unknown statements are skipped with a warning naming file and line, not refused: the OBJ
    // specification says unknown statements are ignored, and every importer does so (a file
    // from a newer exporter must still load).
    add(render_obj("obj-garbage-lines", "obj/garbage-lines.obj", false).warns(
        &["warning:", "garbage-lines.obj", "line 4: unknown statement 'this'", "line 5"],
        RENDER_OUTPUTS,
    ));
    add(render_obj("obj-bad-number", "obj/bad-number.obj", true).fails(&["bad-number.obj", "line 2"]));
    add(render_obj("obj-face-out-of-range", "obj/face-out-of-range.obj", true)
        .fails(&["face-out-of-range.obj", "line 4"]));
    add(render_obj("obj-face-index-zero", "obj/face-index-zero.obj", true)
        .fails(&["face-index-zero.obj", "line 4: vertex index 0 in '0' is invalid (OBJ counts from 1)"]));
    // Index 0 and relative indices before the first element overflowed tobj's index arithmetic
    // (a panic in builds with overflow checks); the loader refuses them first.
    add(render_obj("obj-texcoord-index-zero", "obj/texcoord-index-zero.obj", true)
        .fails(&["texcoord-index-zero.obj", "line 6: texture coordinate index 0 in '1/0' is invalid"]));
    add(render_obj("obj-relative-index-before-first", "obj/relative-before-first.obj", true).fails(&[
        "relative-before-first.obj",
        "line 5: relative vertex index -4 in '-4' reaches before the first (only 3 defined so far)",
    ]));
    add(render_obj("obj-nan-vertex", "obj/nan-vertex.obj", true)
        .fails(&["nan-vertex.obj", "vertex 1 has a non-finite position"]));
    // Its garbage line is only a warning (above); what makes it unusable is that it has no faces.
    add(render_obj("obj-no-geometry", "obj/no-geometry.obj", true).fails(&["no-geometry.obj", "no faces"]));
    add(render_obj("mtl-malformed-values", "obj/malformed-mtl.obj", false)
        .corpus("obj/malformed-values.mtl")
        .fails(&["malformed-values.mtl", "line 2: Kd '0.8 zero 0.1' is not one or three numbers"]));
    add(render_obj("mtl-nan-values", "obj/nan-mtl.obj", false)
        .corpus("obj/nan-values.mtl")
        .fails(&["nan-values.mtl", "line 2: Kd '0.8 nan 0.1' is not finite"]));
    // Two numbers made tobj 4.0.5 panic (`parse_float3`'s unwrap); the loader refuses them first.
    add(render_obj("mtl-two-number-colour", "obj/two-number-mtl.obj", false)
        .corpus("obj/two-number-colour.mtl")
        .fails(&[
            "two-number-colour.mtl",
            "line 3: Ke '4 4' is not one or three numbers",
            "two-number-mtl.obj",
        ]));
    add(render_obj("mtl-colour-without-numbers", "obj/no-number-mtl.obj", false)
        .corpus("obj/no-number-colour.mtl")
        .fails(&["no-number-colour.mtl", "line 2: Kd '' is not one or three numbers"]));
    // MTL's one-number form `Kd 0.5` (grey) is valid: a control for the two cases above.
    add(render_obj("mtl-one-number-colour", "obj/grey-mtl.obj", false)
        .corpus("obj/grey.mtl")
        .succeeds(RENDER_OUTPUTS));
    add(render_obj("mtl-missing-texture", "obj/missing-texture.obj", false)
        .corpus("obj/missing-texture.mtl")
        .warns(&["warning:", "missing-texture.mtl", "no-such-map.png", "cannot read"], RENDER_OUTPUTS));
    add(render_obj("mtl-missing-library", "obj/missing-mtl.obj", false)
        .warns(&["warning:", "missing-mtl.obj", "no-such-library.mtl"], RENDER_OUTPUTS));
    add(render_obj("mtl-unknown-material", "obj/empty-mtl.obj", false)
        .corpus("obj/empty.mtl")
        .warns(&["warning:", "empty-mtl.obj", "material 'red' is not defined"], RENDER_OUTPUTS));
    add(Case::new("OBJ/MTL", "obj-empty-directory")
        .dir("objs")
        .args(&format!("render {{dir}}/objs {OBJ_CAMERA} {QUICK} -q --out {{out}}/render.exr"))
        .fails(&["objs", "holds no .obj files"]));

    // ---- environment maps (EXR, generated) ---------------------------------------------------
    let g = "EXR";
    let sky = exr(2, 1, Some(&[[0.5, 0.6, 0.7], [0.1, 0.2, 0.3]]));
    let env = |name: &str, file: &str, bytes: Vec<u8>| {
        Case::new(g, name).corpus("gltf/ok-triangle.gltf").file(file, bytes).args(&format!(
            "render {{dir}}/ok-triangle.gltf --env-map {{dir}}/{file} {QUICK} -q --out {{out}}/render.exr"
        ))
    };
    add(env("env-exr-control", "sky.exr", sky.clone()).succeeds(RENDER_OUTPUTS));
    add(env("env-exr-truncated", "sky.exr", sky[..sky.len() - 10].to_vec()).fails(&["sky.exr", "OpenEXR"]));
    add(env("env-exr-garbage", "sky.exr", b"not an OpenEXR file at all".to_vec())
        .fails(&["sky.exr", "not a readable OpenEXR header"]));
    add(env("env-exr-empty", "sky.exr", Vec::new()).fails(&["sky.exr", "not a readable OpenEXR header"]));
    let mut nan_sky = sky.clone();
    let at = nan_sky.len() - 4; // the last float of the last scan line (R of pixel (1, 0))
    nan_sky[at..].copy_from_slice(&f32::NAN.to_le_bytes());
    add(env("env-exr-nan", "sky.exr", nan_sky)
        .fails(&["sky.exr", "pixel (1, 0) of the environment image is not finite"]));
    add(env("env-png-empty", "sky.png", Vec::new()).fails(&["sky.png", "empty"]));

    // ---- camera lists (JSON, committed) ------------------------------------------------------
    let g = "camera list";
    let cams = |name: &str, file: &str| {
        Case::new(g, name)
            .corpus("obj/ok-triangle.obj")
            .corpus(&format!("cameras/{file}"))
            .args(&format!("render {{dir}}/ok-triangle.obj --cameras-file {{dir}}/{file} --camera front {QUICK} -q --out {{out}}/render.exr"))
    };
    add(cams("cameras-control", "ok-cameras.json").succeeds(RENDER_OUTPUTS));
    add(cams("cameras-truncated", "truncated-cameras.json").fails(&[
        "truncated-cameras.json",
        "malformed camera-list JSON",
        "EOF",
    ]));
    add(cams("cameras-wrong-type", "wrong-type-cameras.json")
        .fails(&["wrong-type-cameras.json", "look_from"]));
    add(cams("cameras-zero-fov", "zero-fov-cameras.json").fails(&[
        "zero-fov-cameras.json",
        "camera 0 ('front')",
        "\"fov\" 0° must be in (0°, 180°)",
    ]));
    add(cams("cameras-empty", "empty-cameras.json").fails(&[
        "empty-cameras.json",
        "malformed camera-list JSON",
        "EOF",
    ]));

    // ---- empty files of every kind (one line each; the kinds above have theirs too) ----------
    let g = "empty file";
    add(render_bytes(g, "empty-gltf", "empty.gltf", Vec::new()).fails(&["empty.gltf", "malformed glTF JSON"]));
    add(render_bytes(g, "empty-glb", "empty.glb", Vec::new()).fails(&["empty.glb", "malformed"]));
    add(Case::new(g, "empty-obj")
        .file("empty.obj", Vec::new())
        .args(&format!("render {{dir}}/empty.obj {OBJ_CAMERA} {QUICK} -q --out {{out}}/render.exr"))
        .fails(&["empty.obj", "no faces"]));
    add(remap(g, "empty-collage", Vec::new()).views().fails(&["collage.png", "cannot decode the image"]));
    add(Case::new(g, "empty-lens-txt")
        .corpus("gltf/ok-triangle.gltf")
        .file("lens.txt", Vec::new())
        .args("rerender {dir}/ok-triangle.gltf --lens {dir}/lens.txt --spp 1 -q --out {out}/final.exr")
        .fails(&["lens.txt", "empty file"]));
    add(Case::new(g, "empty-lens-mcr")
        .corpus("gltf/ok-triangle.gltf")
        .file("lens.mcr", Vec::new())
        .args("rerender {dir}/ok-triangle.gltf --lens {dir}/lens.mcr --spp 1 -q --out {out}/final.exr")
        .fails(&["lens.mcr", "empty file"]));
    add(Case::new(g, "empty-compose-mask")
        .file("mask.png", Vec::new())
        .dir("views")
        .args("collage --mask {dir}/mask.png --views {dir}/views --out {out}/collage.png")
        .fails(&["mask.png", "cannot decode the image"]));
    add(Case::new(g, "empty-texture")
        .corpus("gltf/missing-texture.gltf")
        .file("no-such-texture.png", Vec::new())
        .args(&format!("render {{dir}}/missing-texture.gltf {QUICK} --out {{out}}/render.exr"))
        .warns(&["warning:", "missing-texture.gltf", "no-such-texture.png", "empty"], RENDER_OUTPUTS));
}
