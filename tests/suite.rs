//! mcctrace's end-to-end tests, built as one test binary (`[[test]] suite` in the top-level
//! Cargo.toml, `autotests = false`): each file or folder here is a module of it. One binary links
//! the tracer, MCC and CLI crates once instead of once per file, which is most of a fresh test
//! build. Run one module with a filter: `cargo test --release -p mcctrace-suite --test suite --
//! golden::`. The one exception is the studio page's browser test, which times the page and so
//! runs alone in a binary of its own (tests/page.rs).
//!
//! A file added to `tests/` runs only once it is declared below
//! (`every_test_file_is_a_module` fails until it is).

mod animation;
mod bad_inputs;
mod common;
mod cornell_reference;
mod cycles_parity;
mod denoise;
mod determinism;
mod farm;
mod first_use;
mod furnace;
mod fuzz_properties;
mod glass;
mod gltf_samples;
mod golden;
mod layers;
mod lens_shaders;
mod light_tree;
mod mcc_pipeline;
mod robustness;
mod scene_features;
mod seamless_blend;
mod stress;
mod stress_mcc;
mod studio;
mod week_of_use;

/// The test binaries' roots: this one, and `page`, the browser test that must run alone
/// (tests/page.rs).
const ROOTS: [&str; 2] = ["suite", "page"];

/// With `autotests = false`, Cargo no longer builds `tests/*.rs` as binaries of their own: a test
/// file that no root declares would silently never run.
#[test]
fn every_test_file_is_a_module() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    let root: String = ROOTS
        .iter()
        .map(|r| std::fs::read_to_string(dir.join(format!("{r}.rs"))).expect("read a test root"))
        .collect();
    let mut undeclared = Vec::new();
    for entry in std::fs::read_dir(&dir).expect("list tests/") {
        let path = entry.expect("list tests/").path();
        let name = path.file_stem().and_then(|s| s.to_str()).unwrap_or_default().to_owned();
        let module = if path.is_dir() {
            path.join("mod.rs").is_file()
        } else {
            path.extension().is_some_and(|e| e == "rs") && !ROOTS.contains(&name.as_str())
        };
        if module && !root.lines().any(|l| l.trim() == format!("mod {name};")) {
            undeclared.push(path.display().to_string());
        }
    }
    assert!(
        undeclared.is_empty(),
        "not declared as modules in tests/suite.rs or tests/page.rs, so never run: {undeclared:?}"
    );
}
