//! The bundled scenes are what this generator writes: running `mcctrace-scenegen` into a scratch
//! folder reproduces every generated file in `scenes/cafe/` and the Cornell box's glTF twin in
//! `scenes/cornell/` byte for byte. A change to the generator that alters a scene fails here
//! until the scene is regenerated and committed (the command is in the scenes' READMEs).

use std::path::{Path, PathBuf};
use std::process::Command;

/// The repository's `scenes/` folder.
fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

/// An empty scratch folder for one test, removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mcctrace-scenegen-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create the scratch folder");
        Self(dir)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs the generator binary with `args`, failing the test on a non-zero exit.
fn scenegen(args: &[&str]) {
    let out =
        Command::new(env!("CARGO_BIN_EXE_mcctrace-scenegen")).args(args).output().expect("run scenegen");
    assert!(out.status.success(), "scenegen {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
}

/// The names of the files in `dir`, sorted.
fn files(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("list a folder")
        .map(|e| e.expect("list a folder").file_name().into_string().expect("UTF-8 file name"))
        .collect();
    names.sort();
    names
}

/// Checks that each of `names` in `generated` equals the committed file of that name in
/// `committed`, byte for byte.
fn assert_same_files(generated: &Path, committed: &Path, names: &[String]) {
    let differing: Vec<&String> = names
        .iter()
        .filter(|name| {
            let ours = std::fs::read(generated.join(name)).expect("read a generated file");
            std::fs::read(committed.join(name)).ok() != Some(ours)
        })
        .collect();
    assert!(
        differing.is_empty(),
        "regenerating {} changes {differing:?}: commit the regenerated scene or fix the generator",
        committed.display()
    );
}

#[test]
fn cafe_regenerates_byte_identical() {
    let scratch = Scratch::new("cafe");
    scenegen(&["cafe", scratch.0.to_str().expect("UTF-8 scratch path")]);
    let written = files(&scratch.0);
    // Every generated file of the folder is written (only its README is not).
    let committed: Vec<String> =
        files(&scenes().join("cafe")).into_iter().filter(|n| n != "README.md").collect();
    assert_eq!(written, committed, "the generator writes other files than scenes/cafe holds");
    assert_same_files(&scratch.0, &scenes().join("cafe"), &written);
}

#[test]
fn cornell_gltf_regenerates_byte_identical() {
    let scratch = Scratch::new("cornell");
    let cornell = scenes().join("cornell");
    // The generator reads the OBJ parts and their material library from the folder it writes to.
    for name in files(&cornell).into_iter().filter(|n| n.ends_with(".obj") || n.ends_with(".mtl")) {
        std::fs::copy(cornell.join(&name), scratch.0.join(&name)).expect("copy a Cornell part");
    }
    scenegen(&["cornell", scratch.0.to_str().expect("UTF-8 scratch path")]);
    assert_same_files(&scratch.0, &cornell, &["cornell.gltf".to_owned(), "cornell.bin".to_owned()]);
}
