//! The checks every fuzz target runs, shared by the cargo-fuzz targets (`fuzz/fuzz_targets/`)
//! and the stable-Rust proptest fallback (`tests/fuzz_properties.rs`): a crate of its own so that
//! both link it. It uses only `std`, `tracer` and `mcc` (and `mcc::image`), the crates both builds
//! have.
//!
//! The property for every reader: any bytes give `Ok` or `Err`, never a panic, a hang or an
//! unbounded allocation; and what a reader accepts is self-consistent (the assertions below). A
//! failed assertion is a finding, the same as a panic inside the product.
//!
//! Readers that only take a path get the bytes through files in a scratch folder of this process
//! and thread (`scratch`), created once and overwritten on every call: each target writes the
//! same file names every time, so an input can never see a file left by another input.

use mcc::image::DynamicImage;
use mcc::{Collage, CollageOptions, RayFile, RayFormat, Regions, StrayPolicy, TagCode};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use tracer::scene::Scene;

/// A scratch folder for this process and thread, `<tmp>/mcctrace-fuzz-<pid>-<thread>/<target>/`,
/// created on first use and reused afterwards (temp_dir honours `TMPDIR`).
pub fn scratch(target: &str) -> PathBuf {
    thread_local! {
        static ROOT: PathBuf = {
            let thread = format!("{:?}", std::thread::current().id());
            let thread: String = thread.chars().filter(char::is_ascii_digit).collect();
            std::env::temp_dir().join(format!("mcctrace-fuzz-{}-{thread}", std::process::id()))
        };
    }
    let dir = ROOT.with(|root| root.join(target));
    if !dir.is_dir() {
        std::fs::create_dir_all(&dir).expect("cannot create the fuzzing scratch folder");
    }
    dir
}

/// Removes this thread's scratch folder (the proptest fallback tidies up; a libFuzzer process
/// leaves its few small files to the temporary folder `.ci/run` gives it as TMPDIR).
pub fn remove_scratch() {
    let root = scratch("x");
    if let Some(root) = root.parent() {
        let _ = std::fs::remove_dir_all(root);
    }
}

fn write(path: &Path, bytes: &[u8]) {
    std::fs::write(path, bytes).expect("cannot write a fuzzing scratch file");
}

/// Splits `data` at `SEPARATOR` lines into at most `n` parts (missing parts are empty): how the
/// OBJ target carries the OBJ, its MTL and a texture in one input.
pub fn split_parts(data: &[u8], n: usize) -> Vec<&[u8]> {
    let mut parts = Vec::with_capacity(n);
    let mut rest = data;
    while parts.len() + 1 < n {
        match rest.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
            Some(at) => {
                parts.push(&rest[..at]);
                rest = &rest[at + SEPARATOR.len()..];
            }
            None => break,
        }
    }
    parts.push(rest);
    parts.resize(n, &[]);
    parts
}

/// Separates the parts of an OBJ-target input (a line of its own).
pub const SEPARATOR: &[u8] = b"\n#%%mcctrace-fuzz%%\n";

// ---------------------------------------------------------------------------------------------
// Ray files (docs/design/mcc.md §4.2): `RayFile::parse` in memory and `RayFile::read` from a file.

/// Ray files: bytes → `RayFile::parse` and `RayFile::read` (must agree); an accepted file
/// re-encodes and re-reads bit for bit in both encodings.
pub fn ray_file(data: &[u8]) {
    let name = Path::new("fuzz.mcr");
    let parsed = RayFile::parse(data, name);
    let path = scratch("ray_file").join("fuzz.mcr");
    write(&path, data);
    let read = RayFile::read(&path);
    match (&parsed, &read) {
        (Ok(a), Ok(b)) => assert_eq!(a, b, "RayFile::parse and RayFile::read disagree"),
        (Err(a), Err(b)) => {
            // Errors must be printable (their Display walks the path and the message).
            let _ = (a.to_string(), b.to_string());
        }
        (a, b) => panic!(
            "RayFile::parse and RayFile::read disagree: parse {:?}, read {:?}",
            a.as_ref().map(|_| "Ok"),
            b.as_ref().map(|_| "Ok")
        ),
    }
    let Ok(file) = parsed else { return };
    assert_eq!(file.rays.len() as u64, file.width as u64 * file.height as u64);
    assert!(file.first_defect().is_none(), "an accepted file has an invalid ray");
    let bits = |f: &RayFile| -> Vec<u32> {
        f.rays
            .iter()
            .flat_map(|r| r.origin.to_array().into_iter().chain(r.direction.to_array()))
            .map(f32::to_bits)
            .collect()
    };
    for format in [RayFormat::Binary, RayFormat::Text] {
        let mut bytes = Vec::new();
        file.encode(&mut bytes, format).expect("encoding into memory cannot fail");
        let again = RayFile::parse(&bytes, name)
            .unwrap_or_else(|e| panic!("an accepted ray file does not re-read as {format:?}: {e}"));
        assert_eq!((again.width, again.height), (file.width, file.height), "{format:?} round trip");
        assert_eq!(bits(&again), bits(&file), "{format:?} round trip is not bit for bit");
        if format == RayFormat::Binary {
            assert_eq!(again, file, "binary round trip");
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Collages and region images (docs/design/mcc.md §4.5, §4.6): image bytes → `Collage::load` /
// `Collage::decode` with several camera sets and tag codes, and `Regions::load` /
// `Regions::from_image`.

/// Collages and regions: the bytes are an image file (PNG, JPEG or TIFF, told by content).
pub fn collage(data: &[u8]) {
    let path = scratch("collage").join("collage.png");
    write(&path, data);
    let known: BTreeSet<u32> = [1, 2, 3, 5, 9, 63].into_iter().collect();
    // The product's own path: `Collage::load` reads through `mcc::png::read_image`.
    let loaded = Collage::load(&path, Some(&known), CollageOptions::default());
    let Ok(image) = mcc::png::read_image(&path) else {
        assert!(loaded.is_err(), "Collage::load accepted an image read_image refuses");
        return;
    };
    if let Ok((c, strays)) = &loaded {
        assert!(strays.is_empty(), "the refusing policy returned strays");
        check_collage(c, &image, Some(&known));
    }
    // Every tag width, both stray policies, with and without a camera set; the bits come from
    // the input so one run covers them all over time without multiplying the cost of each run.
    let bits = 1 + data.len() as u8 % 8;
    let tag = TagCode::new(bits).expect("1..=8 bits is a valid tag code");
    for (known, strays) in [(None, StrayPolicy::Refuse), (Some(&known), StrayPolicy::Background)] {
        match Collage::decode(&image, &path, known, CollageOptions { tag, strays, ..Default::default() }) {
            Ok((c, report)) => {
                check_collage(&c, &image, known);
                let _ = report.to_string();
                assert!(report.first.len() <= report.count.min(mcc::collage::STRAY_LOCATIONS));
            }
            Err(e) => {
                let _ = e.to_string();
            }
        }
    }
    // Region images: the same bytes as a region image of their own size.
    match Regions::load(&path, image.width(), image.height()) {
        Ok(regions) => check_regions(&regions, &image),
        Err(e) => {
            let _ = e.to_string();
        }
    }
}

fn check_collage(c: &Collage, image: &DynamicImage, known: Option<&BTreeSet<u32>>) {
    assert_eq!((c.width, c.height), (image.width(), image.height()));
    assert_eq!(c.ids.len() as u64, c.width as u64 * c.height as u64);
    if let Some(known) = known {
        assert!(c.cameras().is_subset(known), "a decoded id names no known camera");
    }
}

fn check_regions(r: &Regions, image: &DynamicImage) {
    assert_eq!((r.width, r.height), (image.width(), image.height()));
    assert!(r.check_size(r.width, r.height).is_ok());
    assert!(r.count() >= 1 || r.index.is_empty());
    for (k, info) in r.info.iter().enumerate() {
        let (x, y) = info.first;
        assert_eq!(r.at(x, y) as usize, k, "a region's first pixel belongs to another region");
        let _ = info.to_string();
    }
    assert!(r.index.iter().all(|&i| (i as usize) < r.count()));
}

// ---------------------------------------------------------------------------------------------
// Layered collages (crates/mcc/src/layers/): OpenRaster archives and PSD documents.

/// Layered collages: the bytes are read both as `collage.ora` and as `collage.psd` (each reader
/// tells its format by content first, so a zip lands in the OpenRaster reader and `8BPS` in the
/// PSD reader whatever the name; the other name sends the same bytes to the other reader). An
/// accepted file gives a collage of its canvas size naming only known cameras, and regions
/// covering it.
pub fn layers(data: &[u8]) {
    let dir = scratch("layers");
    let known: BTreeSet<u32> = [1, 2, 3].into_iter().collect();
    for name in ["collage.ora", "collage.psd"] {
        let path = dir.join(name);
        write(&path, data);
        let names = mcc::layers::CameraNames::ids(Some(known.clone()));
        match mcc::layers::open_collage(&path, None, &names, CollageOptions::default()) {
            Ok(opened) => {
                let c = &opened.collage;
                assert_eq!(c.ids.len() as u64, c.width as u64 * c.height as u64);
                assert!(c.cameras().is_subset(&known), "a layer painted an unknown camera");
                assert!(opened.strays.is_empty(), "a layered collage reported strays");
                assert_eq!((opened.regions.width, opened.regions.height), (c.width, c.height));
                assert!(opened.regions.index.iter().all(|&i| (i as usize) < opened.regions.count()));
                for note in &opened.notes {
                    assert!(!note.is_empty());
                }
            }
            Err(e) => {
                let message = e.to_string();
                assert!(message.contains(name), "the error does not name the file: {message}");
            }
        }
        // The same bytes as a layered region image of a small collage.
        if let Err(e) = mcc::layers::load_regions(&path, 6, 4) {
            let _ = e.to_string();
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Scenes (docs/design/tracer.md §3.1): `Scene::load` of a .gltf/.glb file, and of an OBJ file with its MTL
// and a texture.

/// glTF: the bytes are a `.gltf` (JSON) or `.glb` file (the loader tells them by the GLB magic,
/// not by the name). An accepted scene is validated by the loader; an animated one must also
/// flatten (or refuse) at other times without panicking.
pub fn gltf(data: &[u8]) {
    let path = scratch("gltf").join("scene.gltf");
    write(&path, data);
    check_scene(Scene::load(&path));
}

/// OBJ: the bytes are `scene.obj`, then after a [`SEPARATOR`] line `m.mtl`, then after another
/// the image file `t.png` (each may be missing: an empty file is written). The OBJ names its
/// library with `mtllib m.mtl`, the library its textures with `map_Kd t.png` etc.
pub fn obj(data: &[u8]) {
    let dir = scratch("obj");
    let parts = split_parts(data, 3);
    write(&dir.join("m.mtl"), parts[1]);
    write(&dir.join("t.png"), parts[2]);
    let path = dir.join("scene.obj");
    write(&path, parts[0]);
    check_scene(Scene::load(&path));
}

fn check_scene(result: tracer::Result<Scene>) {
    let scene = match result {
        Ok(scene) => scene,
        Err(e) => {
            let _ = e.to_string();
            return;
        }
    };
    scene.validate().expect("Scene::load returned a scene its own validate refuses");
    for w in &scene.warnings {
        assert!(!w.is_empty());
    }
    let _ = (scene.bounds(), scene.describe_cameras(), scene.duration());
    if scene.animation.is_some() {
        let end = scene.duration();
        for t in [0.0, 0.37 * end, end, end + 1.0, -1.0, f32::INFINITY, f32::NAN] {
            match scene.at_time(t) {
                Ok(s) => s.validate().expect("Scene::at_time returned a scene validate refuses"),
                Err(e) => {
                    let _ = e.to_string();
                }
            }
        }
    }
}
