//! The malformed-input corpus (`tests/bad_inputs/`): ray-file, collage, absurd-size and command-line cases.

use super::case::*;
use super::encoders::*;
use super::{H, W};

/// Ray files, collages and region images, absurd sizes and command-line values.
pub(crate) fn mcc_cases(add: &mut impl FnMut(Case)) {
    // ---- ray files, text (committed), read by `remap` and by `rerender --lens` ---------------
    let text_rays: &[(&str, &str, &[&str])] = &[
        (
            "truncated-rays.txt",
            "truncated",
            // The file holds rows 0–2 and pixels (0..=3, 3): 28 records, so (4, 3) is the first gap.
            &["pixel (4, 3)", "no record (the file has 28 of 48): truncated"],
        ),
        // Line 1 is the header, lines 2–29 are whole records, line 30 stops after 4 fields.
        (
            "cut-mid-line-rays.txt",
            "cut-mid-line",
            &["line 30", "4 fields, want 8", "ends in the middle of this record: truncated"],
        ),
        (
            "duplicate-pixel.txt",
            "duplicate-pixel",
            &["line 22 (pixel (3, 2))", "a second record for this pixel"],
        ),
        ("nan-rays.txt", "nan", &["line 15 (pixel (5, 1))", "origin", "not finite"]),
        ("non-unit-rays.txt", "non-unit", &["line 9 (pixel (7, 0))", "not unit"]),
        ("pixel-outside-rays.txt", "pixel-outside", &["line 7", "column 8 is outside the image (0..8)"]),
        ("garbage-rays.txt", "garbage", &["neither a binary ray file", "line 1 must be `width height`"]),
    ];
    for &(file, what, want) in text_rays {
        let mut want = want.to_vec();
        want.insert(0, "frame0000camera01.txt");
        add(remap_bad_rays(&format!("rays-text-{what}"), "txt", corpus_file(&format!("rays/{file}")))
            .fails(&want));
    }
    add(remap_bad_rays("rays-text-wrong-size", "txt", corpus_file("rays/wrong-size-rays.txt"))
        .fails(&["frame0000camera01.txt", "camera 1's ray file is 10x6, but the collage is 8x6"]));
    add(remap_bad_rays("rays-text-empty", "txt", Vec::new()).fails(&["frame0000camera01.txt", "empty file"]));
    add(rerender_lens("ray file (text)", "lens-text-nan", "lens.txt", corpus_file("rays/nan-rays.txt"))
        .fails(&["lens.txt", "line 15 (pixel (5, 1))", "not finite"]));
    add(rerender_lens(
        "ray file (text)",
        "lens-text-control",
        "lens.txt",
        corpus_file("rays/ok-camera01.txt"),
    )
    .succeeds(&["out/final.exr", "out/final.png"]));

    // ---- ray files, binary (generated from the committed text files) ------------------------
    let good_rays = parse_text_rays(&corpus_file("rays/ok-camera01.txt"));
    let good_mcr = mcr(W, H, 0, 1, 0, 1, &good_rays);
    add(Case::new("ray file (binary)", "rays-binary-control")
        .file("collage.png", collage_png(W, H))
        .file("views/frame0000camera01.mcr", good_mcr.clone())
        .file("views/frame0000camera02.txt", corpus_file("rays/ok-camera02.txt"))
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
        .succeeds(&["out/rerender-frame0000.mcr"]));
    add(remap_bad_rays("rays-binary-truncated", "mcr", good_mcr[..good_mcr.len() - 30].to_vec()).fails(&[
        "frame0000camera01.mcr",
        "1154 bytes, but a 8x6 binary ray file is 1184 bytes (truncated)",
    ]));
    let mut trailing = good_mcr.clone();
    trailing.extend_from_slice(b"extra");
    add(remap_bad_rays("rays-binary-trailing-bytes", "mcr", trailing)
        .fails(&["frame0000camera01.mcr", "trailing bytes after the last record"]));
    let mut nan = good_rays.clone();
    nan[13][1] = f32::NAN;
    add(remap_bad_rays("rays-binary-nan", "mcr", mcr(W, H, 0, 1, 0, 1, &nan)).fails(&[
        "frame0000camera01.mcr",
        "record 13 (pixel (5, 1))",
        "not finite",
    ]));
    let mut non_unit = good_rays.clone();
    non_unit[7][3..].copy_from_slice(&[0.5, 0.5, -0.5]);
    add(remap_bad_rays("rays-binary-non-unit", "mcr", mcr(W, H, 0, 1, 0, 1, &non_unit)).fails(&[
        "frame0000camera01.mcr",
        "record 7 (pixel (7, 0))",
        "not unit",
    ]));
    let wide: Vec<[f32; 6]> = (0..10 * H).map(|k| good_rays[(k % 8) as usize]).collect();
    add(remap_bad_rays("rays-binary-wrong-size", "mcr", mcr(10, H, 0, 1, 0, 1, &wide))
        .fails(&["frame0000camera01.mcr", "camera 1's ray file is 10x6, but the collage is 8x6"]));
    let mut garbage = MCR_MAGIC.to_vec();
    garbage.extend((0..200u32).map(|k| (k.wrapping_mul(2654435761) >> 24) as u8));
    add(remap_bad_rays("rays-binary-garbage", "mcr", garbage).fails(&[
        "frame0000camera01.mcr",
        "binary ray file version",
        "is not supported",
    ]));
    add(remap_bad_rays("rays-binary-unknown-flags", "mcr", mcr(W, H, 0, 1, 6, 1, &good_rays))
        .fails(&["frame0000camera01.mcr", "unknown flags 0x6"]));
    add(remap_bad_rays("rays-binary-version-7", "mcr", mcr(W, H, 0, 1, 0, 7, &good_rays))
        .fails(&["frame0000camera01.mcr", "version 7 is not supported"]));
    add(remap_bad_rays("rays-binary-truncated-header", "mcr", good_mcr[..20].to_vec())
        .fails(&["frame0000camera01.mcr", "truncated binary header: 20 bytes"]));
    add(remap_bad_rays("rays-binary-empty", "mcr", Vec::new())
        .fails(&["frame0000camera01.mcr", "empty file"]));
    add(rerender_lens("ray file (binary)", "lens-binary-truncated", "lens.mcr", good_mcr[..100].to_vec())
        .fails(&["lens.mcr", "(truncated)"]));
    add(Case::new("ray file (binary)", "rays-two-files-one-camera")
        .views()
        .file("collage.png", collage_png(W, H))
        .file("views/frame0000camera01.mcr", good_mcr.clone())
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
        .fails(&["views", "two ray files for frame 0, camera 1"]));
    add(Case::new("ray file (binary)", "rays-none-for-frame")
        .views()
        .file("collage.png", collage_png(W, H))
        .args("remap --collage {dir}/collage.png --rays {dir}/views --frame 7 --out {out}/rerender-frame0007.mcr -q")
        .fails(&["views", "no ray files for frame 7"]));
    add(Case::new("ray file (binary)", "rays-missing-directory")
        .file("collage.png", collage_png(W, H))
        .args("remap --collage {dir}/collage.png --rays {dir}/no-such-views --out {out}/rerender-frame0000.mcr -q")
        .fails(&["no-such-views", "No such file"]));

    // ---- collages and regions (PNG, generated) -----------------------------------------------
    let g = "collage";
    add(remap(g, "collage-control", collage_png(W, H)).views().succeeds(&["out/rerender-frame0000.mcr"]));
    add(remap(g, "collage-antialiased", antialiased_png()).views().fails(&[
        "collage.png",
        "6 non-background pixel(s) carry no usable camera id",
        "first at (4, 0), (4, 1), (4, 2)",
        "antialiased selection edge",
    ]));
    add(remap(g, "collage-antialiased-ignored", antialiased_png())
        .views()
        .args("--ignore-strays")
        .succeeds(&["out/rerender-frame0000.mcr"]));
    // The same, not quiet: the warning must say what was ignored.
    add(Case::new(g, "collage-antialiased-ignored-warns")
        .views()
        .file("collage.png", antialiased_png())
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr --ignore-strays")
        .warns(&["warning:", "collage.png", "treated as background", "6 non-background pixel(s)"], &[
            "out/rerender-frame0000.mcr",
        ]));
    add(remap(g, "collage-unknown-id", unknown_id_png()).views().fails(&[
        "collage.png",
        "4 non-background pixel(s)",
        "ids with no ray file: 5 ×4",
        "first at (6, 0)",
    ]));
    // No tags at all (issue 41, item 8): said in two lines, with what works instead, not as a
    // list of every id the noise decodes to.
    let untagged_advice = "Cut the collage from the tagged PNGs of `render --tag` with hard-edged selections";
    add(remap(g, "collage-untagged", untagged_png(W, H)).views().fails(&[
        "collage.png",
        "non-background pixels name no camera with a ray file",
        "its pixels carry no camera tags",
        untagged_advice,
        "(.ora or .psd, as `render --layers` writes it",
    ]));
    add(Case::new(g, "collage-jpeg")
        .views()
        .file("collage.jpg", untagged_jpeg(W, H))
        .args("remap --collage {dir}/collage.jpg --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
        .fails(&["collage.jpg", "the collage is a JPEG", untagged_advice]));
    add(remap(g, "collage-resampled", untagged_png(10, H)).views().fails(&[
        "collage.png",
        "the collage is 10x6 but the views are 8x6: it was resampled",
        untagged_advice,
    ]));
    add(remap(g, "collage-wrong-size", collage_png(10, H))
        .views()
        .fails(&["frame0000camera01.txt", "ray file is 8x6, but the collage is 10x6"]));
    add(remap(g, "collage-16-bit-exact", collage_png16(false))
        .views()
        .succeeds(&["out/rerender-frame0000.mcr"]));
    add(remap(g, "collage-16-bit-inexact", collage_png16(true)).views().fails(&[
        "collage.png",
        "16-bit collage: pixel (2, 3)",
        "save the collage as 8-bit",
    ]));
    add(remap(g, "collage-greyscale", png(W, H, 0, 8, &vec![90; (W * H) as usize]))
        .views()
        .fails(&["collage.png", "greyscale image cannot carry camera tags"]));
    add(remap(g, "collage-all-background", png(W, H, 2, 8, &vec![0; (W * H * 3) as usize]))
        .views()
        .fails(&["collage.png: has no camera pixels"]));
    add(remap(g, "collage-not-an-image", b"GIMP would never write this\n".to_vec())
        .views()
        .fails(&["collage.png", "cannot decode the image"]));
    let whole = collage_png(W, H);
    add(remap(g, "collage-truncated", whole[..whole.len() / 2].to_vec())
        .views()
        .fails(&["collage.png", "cannot decode the image"]));
    add(remap(g, "collage-empty", Vec::new()).views().fails(&["collage.png", "cannot decode the image"]));
    add(Case::new(g, "collage-missing")
        .views()
        .args("remap --collage {dir}/no-such-collage.png --rays {dir}/views --out {out}/r.mcr -q")
        .fails(&["no-such-collage.png", "No such file"]));
    add(remap(g, "regions-missing", collage_png(W, H))
        .views()
        .args("--regions {dir}/no-such-regions.png")
        .fails(&["no-such-regions.png", "No such file"]));
    add(remap(g, "regions-wrong-size", collage_png(W, H))
        .views()
        .file("regions.png", png(6, H, 2, 8, &vec![255; (6 * H * 3) as usize]))
        .args("--regions {dir}/regions.png")
        .fails(&["regions.png", "the region image is 6x6, but the collage is 8x6"]));
    add(remap(g, "regions-beside-wrong-size", collage_png(W, H))
        .views()
        .file("collage-regions.png", png(W, 4, 2, 8, &vec![255; (W * 4 * 3) as usize]))
        .fails(&["collage-regions.png", "the region image is 8x4, but the collage is 8x6"]));
    add(remap(g, "regions-empty", collage_png(W, H))
        .views()
        .file("collage-regions.png", Vec::new())
        .fails(&["collage-regions.png", "cannot decode the image"]));
    add(Case::new(g, "rerender-collage-control")
        .views()
        .corpus("gltf/ok-triangle.gltf")
        .file("collage.png", collage_png(W, H))
        .args("rerender {dir}/ok-triangle.gltf --collage {dir}/collage.png --rays {dir}/views --spp 1 --threads 1 -q --out {out}/final.exr")
        .succeeds(&["out/final.exr", "out/final.png", "out/final.mcr"]));

    // ---- absurd sizes: refused before allocating (memory-checked) ---------------------------
    let g = "absurd size";
    add(Case::new(g, "render-res-1e6")
        .corpus("gltf/ok-triangle.gltf")
        .args("render {dir}/ok-triangle.gltf --res 1000000x1000000 --spp 1 --threads 1 -q --out {out}/render.exr")
        .fails(&["resolution 1000000x1000000", "at most 268435456 pixels"])
        .memory());
    add(rerender_lens(g, "rerender-res-1e6", "lens.txt", corpus_file("rays/ok-camera01.txt"))
        .args("--res 1000000x1000000")
        .fails(&["resolution 1000000x1000000", "at most 268435456 pixels"])
        .memory());
    add(remap_bad_rays("rays-text-absurd-header", "txt", corpus_file("rays/absurd-header-rays.txt"))
        .fails(&["frame0000camera01.txt", "line 1: size 1000000x1000000 is beyond the limits"])
        .memory());
    add(remap_bad_rays(
        "rays-text-large-header-short-file",
        "txt",
        corpus_file("rays/large-header-short-rays.txt"),
    )
    .fails(&["frame0000camera01.txt", "cannot hold the 60000x2000 = 120000000 records line 1 announces"])
    .memory());
    add(remap_bad_rays("rays-binary-absurd-header", "mcr", mcr(1_000_000, 1_000_000, 0, 1, 0, 1, &[]))
        .fails(&["frame0000camera01.mcr", "header: size 1000000x1000000 is beyond the limits"])
        .memory());
    // 65536 × 2048 = 2^27 pixels passes the size limits: the exact-length check must refuse the
    // 56-byte file before 3 GiB of rays are allocated.
    add(remap_bad_rays(
        "rays-binary-large-header-short-file",
        "mcr",
        mcr(65536, 2048, 0, 1, 0, 1, &good_rays[..1]),
    )
    .fails(&[
        "frame0000camera01.mcr",
        "56 bytes, but a 65536x2048 binary ray file is 3221225504 bytes (truncated)",
    ])
    .memory());
    add(rerender_lens(
        g,
        "lens-binary-absurd-header",
        "lens.mcr",
        mcr(1_000_000, 1_000_000, 0, 0, 1, 1, &[]),
    )
    .fails(&["lens.mcr", "size 1000000x1000000 is beyond the limits"])
    .memory());
    add(remap(g, "collage-png-absurd-header", png_header_only(1_000_000, 1_000_000, 2))
        .views()
        .fails(&["collage.png", "cannot decode the image"])
        .memory());
    add(remap(g, "regions-png-absurd-header", collage_png(W, H))
        .views()
        .file("collage-regions.png", png_header_only(1_000_000, 1_000_000, 2))
        .fails(&["collage-regions.png", "cannot decode the image"])
        .memory());
    add(Case::new(g, "tag-png-absurd-header")
        .file("view.png", png_header_only(1_000_000, 1_000_000, 2))
        .args("tag {dir}/view.png --camera 3 --out {out}/tagged.png")
        .fails(&["view.png", "cannot decode the image"])
        .memory());
    add(Case::new(g, "compose-mask-absurd-header")
        .file("mask.png", png_header_only(1_000_000, 1_000_000, 2))
        .dir("views")
        .args("collage --mask {dir}/mask.png --views {dir}/views --out {out}/collage.png")
        .fails(&["mask.png", "cannot decode the image"])
        .memory());
    add(Case::new(g, "env-map-exr-absurd-header")
        .corpus("gltf/ok-triangle.gltf")
        .file("sky.exr", exr(1_000_000, 1_000_000, None))
        .args(&format!(
            "render {{dir}}/ok-triangle.gltf --env-map {{dir}}/sky.exr {QUICK} -q --out {{out}}/render.exr"
        ))
        .fails(&["sky.exr", "header claims 1000000 × 1000000 pixels"])
        .memory());
    add(Case::new(g, "env-map-png-absurd-header")
        .corpus("gltf/ok-triangle.gltf")
        .file("sky.png", png_header_only(1_000_000, 1_000_000, 2))
        .args(&format!(
            "render {{dir}}/ok-triangle.gltf --env-map {{dir}}/sky.png {QUICK} -q --out {{out}}/render.exr"
        ))
        .fails(&["sky.png", "claims 1000000 × 1000000 pixels"])
        .memory());
    add(Case::new(g, "gltf-texture-absurd-header")
        .corpus("gltf/huge-texture.gltf")
        .file("absurd-texture.png", png_header_only(1_000_000, 1_000_000, 2))
        .args(&format!("render {{dir}}/huge-texture.gltf {QUICK} --out {{out}}/render.exr"))
        .warns(&["warning:", "huge-texture.gltf", "absurd-texture.png", "1000000 × 1000000"], RENDER_OUTPUTS)
        .memory());
    // Headers claiming 16384 × 16384 (exactly the MAX_PIXELS cap, so allowed) in a 59-byte file
    // whose IDAT holds only a zlib header: refused for what the file can hold, before the decoder
    // (which reserves the image once it finds an IDAT) takes 1 GiB as 8-bit RGB, or 2 GiB as
    // 16-bit RGBA, past the child's address space.
    let truncated_max = |color_type: u8, depth: u8| {
        let mut png = png_start(16384, 16384, depth, color_type);
        png_chunk(&mut png, b"IDAT", &[0x78, 0x9c]);
        png_chunk(&mut png, b"IEND", &[]);
        png
    };
    let short_claim = "header claims 16384 × 16384 pixels but the file is only 59 bytes";
    add(remap(g, "collage-png-truncated-max-header", truncated_max(2, 8))
        .views()
        .fails(&["collage.png", "cannot decode the image", short_claim])
        .memory());
    add(Case::new(g, "gltf-texture-truncated-max-header")
        .corpus("gltf/huge-texture.gltf")
        .file("absurd-texture.png", truncated_max(6, 16))
        .args(&format!("render {{dir}}/huge-texture.gltf {QUICK} --out {{out}}/render.exr"))
        .warns(&["warning:", "huge-texture.gltf", "absurd-texture.png", short_claim], RENDER_OUTPUTS)
        .memory());
    add(render(g, "gltf-viewless-huge-count", "gltf/viewless-huge-count.gltf")
        .fails(&["viewless-huge-count.gltf", "accessor 0", "4000000000"])
        .memory());

    // ---- command-line values ------------------------------------------------------------------
    let g = "CLI value";
    let triangle = |name: &str, extra: &str| {
        Case::new(g, name)
            .corpus("gltf/ok-triangle.gltf")
            .args(&format!("render {{dir}}/ok-triangle.gltf {QUICK} -q --out {{out}}/render.exr"))
            .set(extra)
    };
    add(triangle("cli-spp-0", "--spp 0").fails(&["0 samples per pixel", "must be 1 ..= 65536"]));
    add(triangle("cli-spp-too-many", "--spp 100000")
        .fails(&["100000 samples per pixel", "must be 1 ..= 65536"]));
    add(triangle("cli-res-zero", "--res 0x6").fails(&["--res", "'0x6' has a zero dimension"]));
    add(triangle("cli-res-garbage", "--res big").fails(&["--res", "'big' is not WIDTHxHEIGHT"]));
    add(triangle("cli-threads-0", "--threads 0").fails(&["--threads must be at least 1"]));
    add(triangle("cli-unknown-camera", "--camera back").fails(&[
        "ok-triangle.gltf",
        "no camera named 'back'",
        "the scene has 1 camera: 1 'front'",
    ]));
    add(triangle("cli-camera-number-out-of-range", "--camera 3").fails(&[
        "ok-triangle.gltf",
        "no camera number 3",
        "1 'front'",
    ]));
    // Cameras are numbered from 1, as views are (issue 41, item 11): 0 was the first camera
    // once, so it is refused rather than read as another.
    add(triangle("cli-camera-0", "--camera 0").fails(&[
        "--camera 0: cameras are numbered from 1",
        "the first camera is --camera 1",
        "ok-triangle.gltf has 1 camera: 1 'front'",
    ]));
    add(triangle("cli-camera-number-1", "--camera 1").succeeds(RENDER_OUTPUTS));
    add(triangle("cli-fov-on-scene-camera", "--fov 30").fails(&["--fov applies to ad-hoc cameras"]));
    add(triangle("cli-first-id-0", "--first-id 0").fails(&["--first-id must be at least 1"]));
    add(triangle("cli-tag-first-id-64", "--tag --first-id 64")
        .fails(&["camera id 64 does not fit in 2 bits per channel (ids 1 … 63)"]));
    add(triangle("cli-tag-bits-9", "--tag --tag-bits 9")
        .fails(&["tag code", "9 bits per channel: must be 1 to 8"]));
    add(triangle("cli-out-not-exr", "--out {out}/render.png")
        .fails(&["render.png", "expected an .exr file or a directory"]));
    add(Case::new(g, "cli-fov-0")
        .corpus("obj/ok-triangle.obj")
        .args(&format!(
            "render {{dir}}/ok-triangle.obj {OBJ_CAMERA} --fov 0 {QUICK} -q --out {{out}}/render.exr"
        ))
        .fails(&["camera 'ad-hoc'", "field of view 0.000° must be in (0°, 180°)"]));
    add(Case::new(g, "cli-look-at-equals-look-from")
        .corpus("obj/ok-triangle.obj")
        .args(&format!("render {{dir}}/ok-triangle.obj --look-from 1,1,1 --look-at 1,1,1 {QUICK} -q --out {{out}}/render.exr"))
        .fails(&["camera look-at"]));
    add(Case::new(g, "cli-obj-without-camera")
        .corpus("obj/ok-triangle.obj")
        .args(&format!("render {{dir}}/ok-triangle.obj {QUICK} -q --out {{out}}/render.exr"))
        .fails(&[
            "ok-triangle.obj",
            "no camera number 1 (index 0)",
            "no cameras (give one with --look-from/--look-at",
        ]));
    let tagger = |name: &str, extra: &str| {
        Case::new(g, name)
            .file("view.png", collage_png(W, H))
            .args(&format!("tag {{dir}}/view.png --out {{out}}/tagged.png {extra}"))
    };
    add(tagger("cli-tag-control", "--camera 9").succeeds(&["out/tagged.png"]));
    add(tagger("cli-tag-camera-0", "--camera 0").fails(&["camera id 0 is reserved for 'no camera'"]));
    add(tagger("cli-tag-tag-bits", "--camera 9 --tag-bits 3").succeeds(&["out/tagged.png"]));
    add(tagger("cli-tag-camera-64-2-bits", "--camera 64 --bits 2")
        .fails(&["camera id 64 does not fit in 2 bits per channel (ids 1 … 63)"]));
    add(tagger("cli-tagger-bits-9", "--camera 3 --bits 9").fails(&["9 bits per channel: must be 1 to 8"]));
    add(tagger("cli-tag-empty-image", "--camera 3")
        .file("view.png", Vec::new())
        .fails(&["view.png", "cannot decode the image"]));
    add(rerender_lens(g, "cli-crop-larger-than-image", "lens.txt", corpus_file("rays/ok-camera01.txt"))
        .args("--crop 3")
        .fails(&["--crop 3 leaves nothing of a 8x6 image"]));
    add(Case::new(g, "cli-crop-larger-than-image-collage")
        .views()
        .corpus("gltf/ok-triangle.gltf")
        .file("collage.png", collage_png(W, H))
        .args("rerender {dir}/ok-triangle.gltf --collage {dir}/collage.png --rays {dir}/views --crop 3 --spp 1 --threads 1 -q --out {out}/final.exr")
        .fails(&["--crop 3 leaves nothing of a 8x6 image"]));
    add(Case::new(g, "cli-spp-0-collage")
        .views()
        .corpus("gltf/ok-triangle.gltf")
        .file("collage.png", collage_png(W, H))
        .args("rerender {dir}/ok-triangle.gltf --collage {dir}/collage.png --rays {dir}/views --spp 0 -q --out {out}/final.exr")
        .fails(&["0 samples per pixel"]));
    add(rerender_lens(g, "cli-rerender-shutter-reversed", "lens.txt", corpus_file("rays/ok-camera01.txt"))
        .args("--shutter 0.5..0.2")
        .fails(&["--shutter", "shutter '0.5..0.2': need 0 ≤ OPEN ≤ CLOSE ≤ 1"]));
    add(rerender_lens(g, "cli-rerender-out-not-exr", "lens.txt", corpus_file("rays/ok-camera01.txt"))
        .set("--out {out}/final.png")
        .fails(&["final.png", "give an .exr file"]));
    add(remap(g, "cli-remap-ease-out-of-range", collage_png(W, H))
        .views()
        .args("--ease 1.5")
        .fails(&["ease control 1.5 must be strictly between 0 and 1"]));
    // Range errors name their flag, as clap's own do (issue 27).
    add(triangle("cli-spp-0-names-the-flag", "--spp 0").fails(&["'--spp <SPP>'", "0 samples per pixel"]));
    add(triangle("cli-spp-times-split", "--spp 30000 --split 3")
        .fails(&["--spp 30000 with --split 3", "must be 1 ..= 21845"]));
    add(remap(g, "cli-remap-ease-names-the-flag", collage_png(W, H))
        .views()
        .args("--ease 1.5")
        .fails(&["'--ease <EASE>'", "ease control 1.5"]));
    add(remap(g, "cli-remap-tag-bits-names-the-flag", collage_png(W, H))
        .views()
        .args("--tag-bits 0")
        .fails(&["'--tag-bits <TAG_BITS>'", "0 bits per channel: must be 1 to 8"]));
    // What is done without a word gets one (issue 27): a ray file named .png, a stretched
    // rerender, the lens writer's file named by the view rather than by --out.
    add(Case::new(g, "cli-remap-out-extension")
        .views()
        .file("collage.png", collage_png(W, H))
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/e.png -q")
        .warns(&["warning: --out", "e.png", "binary ray file", ".mcr"], &["out/e.png"]));
    add(Case::new(g, "cli-remap-names-found-regions")
        .views()
        .file("collage.png", collage_png(W, H))
        .file("collage-regions.png", collage_png(W, H))
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr")
        .warns(&["regions: ", "collage-regions.png", "found beside"], &["out/rerender-frame0000.mcr"]));
    add(rerender_lens(g, "cli-rerender-res-stretches", "lens.txt", corpus_file("rays/ok-camera01.txt"))
        .args("--res 8x8")
        .warns(
            &["warning: --res 8x8", "8x6 collage pixels", "stretched"],
            &["out/final.exr", "out/final.png"],
        ));
    add(Case::new(g, "cli-render-lens-writer-says-where")
        .corpus("gltf/ok-triangle.gltf")
        .args(&format!("render {{dir}}/ok-triangle.gltf {QUICK} --lens-writer --out {{out}}/single.exr"))
        .warns(
            &["rays -> ", "frame0000camera01.mcr"],
            &["out/single.exr", "out/single.png", "out/frame0000camera01.mcr"],
        ));
    add(remap(g, "cli-remap-tag-bits-9", collage_png(W, H))
        .views()
        .args("--tag-bits 9")
        .fails(&["9 bits per channel: must be 1 to 8"]));
    // `A..B` once meant A..=B-1 without a word (issue 41, item 10).
    add(Case::new(g, "cli-frames-exclusive-range")
        .views()
        .file("collage.png", collage_png(W, H))
        .args("keys --key 0={dir}/collage.png --rays {dir}/views --frames 5..12 -q --out {out}/lens")
        .fails(&["'--frames <A..=B>'", "'5..12' is ambiguous", "5..=12 to include frame 12", "5..=11"]));
    add(Case::new(g, "cli-remap-no-rays")
        .file("collage.png", collage_png(W, H))
        .args("remap --collage {dir}/collage.png --out {out}/r.mcr -q")
        .fails(&["give both --collage and --rays"]));
}
