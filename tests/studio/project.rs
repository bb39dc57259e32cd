//! Saving and the final render: the saved project is what the batch commands read, "render
//! final" equals `mcctrace rerender` on it bit for bit, the idle preview equals the rerender at
//! the preview settings, and a reopened project is the session saved.

use super::{Client, Msg, RES, SETTINGS, decode, rerender, scene, scratch, start, two_strokes};
use serde_json::json;
use std::path::Path;
use tracer::image_io::{linear_to_srgb8, read_exr_rgb};

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn saved_projects_feed_the_batch_commands_bit_for_bit() {
    let dir = scratch("project");
    let project = dir.join("proj");
    let running = start(&project);
    let mut client = Client::connect(&running).await;
    // Raw samples: the preview is compared with `mcctrace rerender` bit for bit (denoising, on
    // by default when the library is installed, has its own test: tests/studio_page/).
    client.request(json!({"type": "denoise", "on": false})).await;
    let state = two_strokes(&mut client).await;
    let seq = state["seq"].as_u64().unwrap();
    let painted = {
        client.send(json!({"type": "hello"})).await;
        let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
        decode(&labels["data"])
    };

    // The idle preview, at its last sample count, is the rerender of the same collage.
    let (_, preview) = client.preview(seq, SETTINGS.preview_spp).await;
    let saved = client.request(json!({"type": "save"})).await;
    assert_eq!(saved["type"], "saved", "{saved}");
    let (collage, _) =
        mcc::Collage::load(&project.join("collage.png"), None, mcc::CollageOptions::default()).unwrap();
    let ids: Vec<u8> = collage.ids.iter().map(|&i| i as u8).collect();
    assert_eq!(ids, painted, "collage.png decodes to the painted labels");
    for f in ["collage-regions.png", "studio.json", "keys/frame0000.png", "views/frame0000camera02.mcr"] {
        assert!(project.join(f).is_file(), "{f} saved");
    }
    let batch = dir.join("batch-preview.exr");
    rerender(&project, RES, SETTINGS.preview_spp, &batch);
    let expected: Vec<u8> =
        read_exr_rgb(&batch).unwrap().pixels.iter().flat_map(|p| p.to_array().map(linear_to_srgb8)).collect();
    let shown = image::load_from_memory(&preview).unwrap().to_rgb8().into_raw();
    assert_eq!(shown, expected, "the idle preview is the batch rerender at the preview settings");

    // "Render final" at another size equals `mcctrace rerender` on the saved files, bit for bit.
    let (res, spp) = ([40, 24], 3);
    let id = client.send(json!({"type": "render_final", "res": res, "spp": spp})).await;
    let mut progressed = false;
    let done = loop {
        match client.recv().await {
            Msg::Json(v) if v["type"] == "progress" && v["job"] == "final" => progressed = true,
            Msg::Json(v) if v["id"] == json!(id) => break v,
            _ => {}
        }
    };
    assert_eq!(done["type"], "final", "{done}");
    assert!(progressed, "the final render reports progress");
    let batch = dir.join("batch-final.exr");
    rerender(&project, res, spp, &batch);
    let ours = read_exr_rgb(Path::new(done["exr"].as_str().unwrap())).unwrap();
    let theirs = read_exr_rgb(&batch).unwrap();
    assert_eq!((ours.width, ours.height), (res[0], res[1]));
    let bits = |i: &tracer::image::RgbImage| {
        i.pixels.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
    };
    assert!(bits(&ours) == bits(&theirs), "render final and mcctrace rerender differ");
    // Issue 41, item 17: and its EXR header is `rerender`'s but for the time it took.
    let header = |path: &Path| {
        let mut text = tracer::image_io::read_exr(path).unwrap().metadata;
        assert!(text.remove("mcctrace/seconds").is_some(), "{} records its time", path.display());
        text
    };
    assert_eq!(header(Path::new(done["exr"].as_str().unwrap())), header(&batch));

    // A second key at frame 5, then reopen: the cameras (the edited copy too) and maps return.
    let state = client.request(json!({"type": "frame", "frame": 5})).await;
    assert_eq!(state["frames"], json!([0, 5]));
    client.paint([0, 0, 4, 4], &[1; 16]).await;
    client.request(json!({"type": "frame", "frame": 0})).await;
    assert_eq!(client.request(json!({"type": "save"})).await["type"], "saved");
    assert!(project.join("keys/frame0005.png").is_file());
    // `keys` takes the saved keys as they are (each with its own cameras' views): every frame
    // from one key to the other gets its rays.
    let lens = dir.join("lens");
    let key = |f: u32| format!("{f}={}", project.join(::studio::project::key_collage(f)).display());
    let (views, out) = (project.join("views").display().to_string(), lens.display().to_string());
    crate::common::mcctrace(&[
        "keys",
        "--rays",
        &views,
        "--key",
        &key(0),
        "--key",
        &key(5),
        "--frames",
        "0..=5",
        "--out",
        &out,
    ])
    .expect("mcctrace keys on the saved keys");
    for f in 0..=5 {
        assert!(lens.join(format!("rerender-frame{f:04}.mcr")).is_file(), "keys wrote frame {f}'s rays");
    }
    let cameras = client.hello().await["cameras"].clone();
    drop(client);
    drop(running);
    let config = ::studio::Config { engine: SETTINGS, ..::studio::Config::new(None, project.clone()) };
    let reopened = ::studio::serve(config).unwrap();
    let mut client = Client::connect(&reopened).await;
    let state = client.hello().await;
    assert_eq!(state["cameras"], cameras);
    assert_eq!(state["frames"], json!([0, 5]));
    let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
    assert_eq!(decode(&labels["data"]), painted);
    drop(reopened);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// An existing collage cut in an editor opens in the studio through the batch remapper's reader:
/// the OpenRaster file Krita saved and the PSD GIMP saved (tests/data/layers/README.md gives
/// their edits, whose analytic boundaries are checked here) and a tagged PNG.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn opens_layered_and_tagged_collages_cut_elsewhere() {
    let data = crate::common::repo_root().join("tests/data/layers");
    let cafe = crate::common::repo_root().join("scenes/cafe/cafe.gltf");
    for file in ["krita-edited.ora", "gimp-edited.psd"] {
        let dir = scratch(&format!("open-{file}"));
        // The Krita file's layers are named after the Cornell box's cameras (`cornell (camera
        // 1)`): on the café they are renamed after its cameras, whose name a studio reads.
        let collage = if file.ends_with(".ora") {
            let mut entries = crate::layers::unzip(&data.join(file));
            let stack = entries.iter_mut().find(|(n, _)| n == "stack.xml").unwrap();
            let xml = String::from_utf8(stack.1.clone()).unwrap();
            stack.1 = xml.replace("\"cornell (", "\"left (").replace("\"corner (", "\"right (").into_bytes();
            crate::layers::rezip(&dir.join(file), &entries);
            dir.join(file)
        } else {
            data.join(file)
        };
        let config = ::studio::Config {
            res: Some([64, 48]),
            engine: SETTINGS,
            collage: Some(collage),
            ..::studio::Config::new(Some(cafe.clone()), dir.clone())
        };
        let running = ::studio::serve(config).unwrap_or_else(|e| panic!("{file}: {e}"));
        let mut client = Client::connect(&running).await;
        client.send(json!({"type": "hello"})).await;
        let Msg::Json(labels) = client
            .until(|m| matches!(m, Msg::Json(v) if v["type"] == "labels" && v["layer"] == "labels"))
            .await
        else {
            unreachable!()
        };
        let labels = decode(&labels["data"]);
        let at = |x: usize, y: usize| labels[y * 64 + x];
        // Camera 1 left of its erased edge and in its patch, camera 2 right, the erased corner
        // background.
        assert_eq!((at(5, 20), at(20, 40), at(55, 33)), (1, 1, 1), "{file}");
        assert_eq!((at(40, 20), at(60, 40), at(45, 20)), (2, 2, 2), "{file}");
        assert_eq!((at(50, 5), at(63, 0)), (0, 0), "{file}");
        drop(running);
        std::fs::remove_dir_all(&dir).unwrap();
    }
    // A tagged collage: a file the studio saved, opened as `--collage` on a new session.
    let dir = scratch("open-tagged");
    let painted: Vec<u8> = (0..RES[0] * RES[1]).map(|p| if p % RES[0] < 10 { 1 } else { 0 }).collect();
    let running = start(&dir);
    let mut client = Client::connect(&running).await;
    client.hello().await;
    client.paint([0, 0, RES[0], RES[1]], &painted).await;
    assert_eq!(client.request(json!({"type": "save"})).await["type"], "saved");
    drop(running);
    let config = ::studio::Config {
        res: Some(RES),
        engine: SETTINGS,
        collage: Some(dir.join("collage.png")),
        ..::studio::Config::new(Some(scene()), dir.join("again"))
    };
    let running = ::studio::serve(config).unwrap();
    let mut client = Client::connect(&running).await;
    client.send(json!({"type": "hello"})).await;
    let Msg::Json(labels) =
        client.until(|m| matches!(m, Msg::Json(v) if v["type"] == "labels" && v["layer"] == "labels")).await
    else {
        unreachable!()
    };
    assert_eq!(decode(&labels["data"]), painted);
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// "Render final" with a shutter blurs what moves as `mcctrace rerender --shutter` does, bit for
/// bit (the sliding square of tests/animation/, lit by its emissive backdrop), and differs from
/// the final without it; a shutter out of 0 ≤ open ≤ close ≤ 1 is refused, naming it.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn render_final_blurs_within_the_shutter_as_rerender_does() {
    let dir = scratch("final-shutter");
    let scene = crate::animation::motion_blur::write_lit_sliding_square(&dir, &[(0.0, -12.0), (1.0, 12.0)]);
    let project = dir.join("proj");
    let config = ::studio::Config {
        res: Some([32, 32]),
        frame: 12,
        engine: super::SETTINGS,
        ..::studio::Config::new(Some(scene.clone()), project.clone())
    };
    let running = ::studio::serve(config).expect("the studio starts");
    let mut client = Client::connect(&running).await;
    client.request(json!({"type": "denoise", "on": false})).await;
    client.hello().await;
    client.paint([0, 0, 32, 32], &[1; 32 * 32]).await;
    let (res, spp) = ([32, 32], 16);
    let mut finals = Vec::new();
    for shutter in [Some([0.0, 0.5]), None] {
        let request = match shutter {
            Some(s) => json!({"type": "render_final", "res": res, "spp": spp, "shutter": s}),
            None => json!({"type": "render_final", "res": res, "spp": spp}),
        };
        let id = client.send(request).await;
        let done = client.until(|m| matches!(m, Msg::Json(v) if v["id"] == json!(id))).await;
        let Msg::Json(done) = done else { unreachable!() };
        assert_eq!(done["type"], "final", "{done}");
        let exr = Path::new(done["exr"].as_str().unwrap());
        finals.push(read_exr_rgb(exr).unwrap());
        let _ = std::fs::rename(exr, dir.join(format!("final-{}.exr", finals.len())));
    }
    let batch = dir.join("batch.exr");
    crate::common::mcctrace(&[
        "rerender",
        &scene.display().to_string(),
        "--collage",
        &project.join("collage.png").display().to_string(),
        "--rays",
        &project.join("views").display().to_string(),
        "--frame",
        "12",
        "--shutter",
        "0..0.5",
        "--res",
        "32x32",
        "--spp",
        &spp.to_string(),
        "--quiet",
        "--out",
        &batch.display().to_string(),
    ])
    .expect("mcctrace rerender --shutter");
    let bits = |i: &tracer::image::RgbImage| {
        i.pixels.iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>()
    };
    assert!(bits(&finals[0]) == bits(&read_exr_rgb(&batch).unwrap()), "final --shutter and rerender differ");
    assert!(bits(&finals[0]) != bits(&finals[1]), "the shutter changed nothing");
    for bad in [[0.5, 0.2], [0.0, 1.5], [-0.1, 0.5]] {
        let reply =
            client.request(json!({"type": "render_final", "res": res, "spp": 1, "shutter": bad})).await;
        assert_eq!(reply["type"], "error", "{bad:?} → {reply}");
        assert!(reply["message"].as_str().unwrap().contains("shutter"), "{reply}");
    }
    drop(client);
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}
