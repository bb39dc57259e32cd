//! The malformed-input corpus (issue "Trust", item 3; SPEC §8: "Every error names the file and
//! what is wrong with it; no run leaves a half-written output file behind").
//!
//! Every case runs one `mcctrace` command line on a malformed input and checks that
//!
//! 1. the run fails (`try_run` returns `Err`) — or, for the few inputs the product deliberately
//!    accepts with a warning (a missing texture, a collage with `--ignore-strays` …), that it
//!    succeeds, prints a warning naming the file, and writes its outputs;
//! 2. the message names the file (or the flag) and the problem: substrings chosen per case; and
//!    it does not print a cause twice (`a: b: b`);
//! 3. nothing panicked: the run is wrapped in `catch_unwind`, and the child's stderr must not hold
//!    `panicked at`;
//! 4. no output is left behind: the case's directory holds exactly the files the harness staged
//!    (no output, no `.name.tmp-*` temporary) after a failure, and exactly the staged files plus
//!    the expected outputs after a success;
//! 5. absurd sizes are refused before allocating (cases marked `memory`, see below).
//!
//! **How a case runs.** Each case runs in a child process: this test binary itself, re-executed
//! with the ignored test [`child_process_entry`] selected, which calls
//! `mcctrace_cli::try_run(args)` in-process under `catch_unwind` and writes the outcome to a file.
//! The child is this binary rather than `target/…/mcctrace` because the root package has no
//! binary target: `CARGO_BIN_EXE_mcctrace` does not exist for this test, `cargo test -p
//! mcctrace-suite` does not even build the CLI binary, and guessing a path under the target
//! directory could run a stale build. The test binary always exists and links exactly the code
//! under test.
//!
//! **"Before allocating".** A child process, not an in-process check, because an attempted huge
//! allocation aborts the process (`memory allocation of … bytes failed`), which no `catch_unwind`
//! survives, and because peak memory is per process. Every child runs under `ulimit -v`
//! (an address-space limit of [`ADDRESS_SPACE_LIMIT_KB`], applied by `sh` before it `exec`s the
//! child, with rayon's pool and glibc's malloc arenas bounded so the legitimate reservation is
//! small): any attempt to reserve memory in proportion to a 10^6 × 10^6 claim fails at once,
//! whether or not the pages would ever be touched (a peak-RSS check alone misses a huge `calloc`
//! that overcommit grants and the reader frees again untouched). On top of that, the child reads
//! its peak resident set (`VmHWM` in /proc/self/status) before and after the run, and a `memory`
//! case must not grow it by more than [`MEMORY_BUDGET_KB`]. A child killed by a signal (the abort
//! of a failed allocation, a stack overflow) is reported as such.
//!
//! The committed corpus is `tests/bad_inputs/` (text files as they are: glTF, OBJ, MTL, text ray
//! files, camera lists). Binary inputs (GLB, binary ray files, PNG, EXR) are generated here, byte
//! by byte, by the small encoders at the end of this file, so each case says in code exactly
//! which byte is wrong (and the 10^6 × 10^6 headers cost nothing to commit).
//!
//! Linux only (address-space limits through `sh`, peak memory from /proc).
#![cfg(target_os = "linux")]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// The test the child process runs.
const CHILD_TEST: &str = "child_process_entry";
/// Environment variable carrying the child's command line (arguments separated by U+001F).
const ENV_ARGS: &str = "MCCTRACE_BAD_INPUTS_ARGS";
/// Environment variable naming the file the child writes its outcome to.
const ENV_RESULT: &str = "MCCTRACE_BAD_INPUTS_RESULT";
/// Address-space limit of every child (`ulimit -v`, KiB): 2 GiB. The child's legitimate
/// reservation (code, rayon's two workers' stacks, two malloc arenas, a tiny scene) is far
/// below it; a reservation in proportion to any 10^6 × 10^6 claim is far above it.
const ADDRESS_SPACE_LIMIT_KB: u64 = 2 << 20;
/// How much a `memory` case may grow the child's peak resident set (KiB): 64 MiB.
const MEMORY_BUDGET_KB: u64 = 64 << 10;
/// A case that has not finished after this long is killed and reported.
const CASE_TIMEOUT: Duration = Duration::from_secs(120);
/// Cases run this many at a time.
const PARALLEL: usize = 2;

/// Collage and ray-file size of the corpus (the text ray files in `tests/bad_inputs/rays`).
const W: u32 = 8;
const H: u32 = 6;

// ---------------------------------------------------------------------------------------------
// The child side.

/// Runs one case when started by [`corpus`] (the environment carries the command line); does
/// nothing when run directly.
#[test]
#[ignore = "runs one case of `corpus` inside the child process `corpus` starts"]
fn child_process_entry() {
    let (Ok(args), Ok(result)) = (std::env::var(ENV_ARGS), std::env::var(ENV_RESULT)) else {
        return;
    };
    let args: Vec<String> = args.split('\u{1f}').map(str::to_owned).collect();
    let before = status_kb("VmHWM");
    let outcome = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        mcctrace_cli::try_run(std::iter::once("mcctrace".to_owned()).chain(args))
    }));
    let after = status_kb("VmHWM");
    let (status, message) = match outcome {
        Ok(Ok(())) => ("ok", String::new()),
        Ok(Err(e)) => ("error", format!("{e:#}")),
        Err(payload) => {
            let text = payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "(non-string panic payload)".to_owned());
            ("panic", text)
        }
    };
    std::fs::write(result, format!("{status}\n{before}\n{after}\n{message}")).expect("write the outcome");
}

/// A field of /proc/self/status in KiB (0 when absent).
fn status_kb(field: &str) -> u64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix(field)?.strip_prefix(':'))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse().ok())
        .unwrap_or(0)
}

// ---------------------------------------------------------------------------------------------
// Cases.

/// What a case must do.
#[derive(Clone, Debug)]
enum Expect {
    /// Fail with a message holding every substring (the file or flag, and the problem).
    Fails(Vec<String>),
    /// Succeed, print a warning holding every substring on stderr, and write these outputs
    /// (paths relative to the case directory).
    Warns { stderr: Vec<String>, outputs: Vec<String> },
    /// Succeed and write these outputs (a control: proves the malformed variants fail for
    /// their defect, not for something else).
    Succeeds { outputs: Vec<String> },
}

/// One malformed input and the command line that reads it.
#[derive(Clone, Debug)]
struct Case {
    /// Category, for the summary.
    group: &'static str,
    /// Unique name; also the case's directory.
    name: String,
    /// Files to stage in the case directory: (relative path, bytes).
    files: Vec<(String, Vec<u8>)>,
    /// Directories to create (empty) in the case directory.
    dirs: Vec<String>,
    /// The command line after `mcctrace`; `{dir}` is the case directory, `{out}` its `out/`.
    args: Vec<String>,
    expect: Expect,
    /// Refused before allocating: the peak resident set must stay within [`MEMORY_BUDGET_KB`].
    memory: bool,
}

impl Case {
    fn new(group: &'static str, name: &str) -> Self {
        Self {
            group,
            name: name.to_owned(),
            files: Vec::new(),
            dirs: Vec::new(),
            args: Vec::new(),
            expect: Expect::Fails(Vec::new()),
            memory: false,
        }
    }

    /// Stages `bytes` as `path` (relative to the case directory).
    fn file(mut self, path: &str, bytes: impl Into<Vec<u8>>) -> Self {
        self.files.push((path.to_owned(), bytes.into()));
        self
    }

    /// Stages the committed corpus file `corpus_path` under its own file name.
    fn corpus(self, corpus_path: &str) -> Self {
        let name = Path::new(corpus_path).file_name().unwrap().to_str().unwrap().to_owned();
        self.file(&name, corpus_file(corpus_path))
    }

    /// Creates an empty directory.
    fn dir(mut self, path: &str) -> Self {
        self.dirs.push(path.to_owned());
        self
    }

    /// The two good views' ray files in `views/` (text, as committed).
    fn views(self) -> Self {
        self.file("views/frame0000camera01.txt", corpus_file("rays/ok-camera01.txt"))
            .file("views/frame0000camera02.txt", corpus_file("rays/ok-camera02.txt"))
    }

    /// Appends whitespace-separated arguments (placeholders are substituted per token, so
    /// paths with spaces are safe).
    fn args(mut self, template: &str) -> Self {
        self.args.extend(template.split_whitespace().map(str::to_owned));
        self
    }

    /// Sets command-line flags: a `--flag value` pair already on the command line gets the new
    /// value (clap refuses a flag given twice, so appending would test clap, not the value);
    /// anything else is appended.
    fn set(mut self, template: &str) -> Self {
        let tokens: Vec<&str> = template.split_whitespace().collect();
        let mut k = 0;
        while k < tokens.len() {
            let (flag, value) = (tokens[k], tokens.get(k + 1).filter(|v| !v.starts_with("--")));
            match (flag.starts_with("--"), value) {
                (true, Some(value)) => {
                    match self.args.iter().position(|a| a == flag).filter(|&p| p + 1 < self.args.len()) {
                        Some(p) => self.args[p + 1] = (*value).to_owned(),
                        None => self.args.extend([flag.to_owned(), (*value).to_owned()]),
                    }
                    k += 2;
                }
                _ => {
                    self.args.push(flag.to_owned());
                    k += 1;
                }
            }
        }
        self
    }

    fn fails(mut self, want: &[&str]) -> Self {
        assert!(!want.is_empty(), "{}: a failing case must say what its message holds", self.name);
        self.expect = Expect::Fails(want.iter().map(|s| s.to_string()).collect());
        self
    }

    fn warns(mut self, stderr: &[&str], outputs: &[&str]) -> Self {
        self.expect = Expect::Warns {
            stderr: stderr.iter().map(|s| s.to_string()).collect(),
            outputs: outputs.iter().map(|s| s.to_string()).collect(),
        };
        self
    }

    fn succeeds(mut self, outputs: &[&str]) -> Self {
        self.expect = Expect::Succeeds { outputs: outputs.iter().map(|s| s.to_string()).collect() };
        self
    }

    fn memory(mut self) -> Self {
        self.memory = true;
        self
    }
}

/// The committed corpus file at `path` (relative to `tests/bad_inputs`).
fn corpus_file(path: &str) -> Vec<u8> {
    let full = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs").join(path);
    std::fs::read(&full).unwrap_or_else(|e| panic!("corpus file {}: {e}", full.display()))
}

/// Render settings every render case uses: tiny and quick.
const QUICK: &str = "--res 8x6 --spp 1 --threads 1";
/// The ad-hoc camera of the OBJ cases.
const OBJ_CAMERA: &str = "--look-from 0.3,0.3,2 --look-at 0.3,0.3,0";
/// Outputs of a render to `out/render.exr`.
const RENDER_OUTPUTS: &[&str] = &["out/render.exr", "out/render.png"];

/// `render FILE` of a staged scene, quiet.
fn render(group: &'static str, name: &str, corpus_path: &str) -> Case {
    let file = Path::new(corpus_path).file_name().unwrap().to_str().unwrap().to_owned();
    Case::new(group, name)
        .corpus(corpus_path)
        .args(&format!("render {{dir}}/{file} {QUICK} -q --out {{out}}/render.exr"))
}

/// `render FILE` of staged bytes, quiet.
fn render_bytes(group: &'static str, name: &str, file: &str, bytes: Vec<u8>) -> Case {
    Case::new(group, name)
        .file(file, bytes)
        .args(&format!("render {{dir}}/{file} {QUICK} -q --out {{out}}/render.exr"))
}

/// `render FILE` of a staged OBJ scene with the ad-hoc camera; `quiet` hides warnings.
fn render_obj(name: &str, corpus_path: &str, quiet: bool) -> Case {
    let file = Path::new(corpus_path).file_name().unwrap().to_str().unwrap().to_owned();
    let q = if quiet { "-q" } else { "" };
    Case::new("OBJ/MTL", name)
        .corpus(corpus_path)
        .args(&format!("render {{dir}}/{file} {OBJ_CAMERA} {QUICK} {q} --out {{out}}/render.exr"))
}

/// `remap` of `collage.png` (staged bytes) against `views/`.
fn remap(group: &'static str, name: &str, collage: Vec<u8>) -> Case {
    Case::new(group, name)
        .file("collage.png", collage)
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
}

/// `remap` of the good collage with camera 1's ray file replaced by `file` (named
/// `frame0000camera01.<ext>`).
fn remap_bad_rays(name: &str, ext: &str, bytes: Vec<u8>) -> Case {
    let group = if ext == "mcr" { "ray file (binary)" } else { "ray file (text)" };
    Case::new(group, name)
        .file("collage.png", collage_png(W, H))
        .file(&format!("views/frame0000camera01.{ext}"), bytes)
        .file("views/frame0000camera02.txt", corpus_file("rays/ok-camera02.txt"))
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
}

/// `rerender --lens FILE` of the good triangle scene.
fn rerender_lens(group: &'static str, name: &str, lens: &str, bytes: Vec<u8>) -> Case {
    Case::new(group, name)
        .corpus("gltf/ok-triangle.gltf")
        .file(lens, bytes)
        .args(&format!("rerender {{dir}}/ok-triangle.gltf --lens {{dir}}/{lens} --spp 1 --threads 1 -q --out {{out}}/final.exr"))
}

fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let mut add = |c: Case| cases.push(c);

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
        .succeeds(&["out/final.exr", "out/final.png", "out/rerender-frame0000.mcr"]));

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
    add(render(g, "gltf-viewless-huge-count", "gltf/viewless-huge-count.gltf")
        .fails(&["viewless-huge-count.gltf", "accessor 0", "4000000000"])
        .memory());

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
        "the scene has 1 camera: 0 'front'",
    ]));
    add(triangle("cli-camera-index-out-of-range", "--camera 3").fails(&[
        "ok-triangle.gltf",
        "no camera at index 3",
        "0 'front'",
    ]));
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
            "no camera at index 0",
            "no cameras (give one with --look-from/--look-at",
        ]));
    let tagger = |name: &str, extra: &str| {
        Case::new(g, name)
            .file("view.png", collage_png(W, H))
            .args(&format!("tag {{dir}}/view.png --out {{out}}/tagged.png {extra}"))
    };
    add(tagger("cli-tag-control", "--camera 9").succeeds(&["out/tagged.png"]));
    add(tagger("cli-tag-camera-0", "--camera 0").fails(&["camera id 0 is reserved for 'no camera'"]));
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
    add(rerender_lens(g, "cli-rerender-out-not-exr", "lens.txt", corpus_file("rays/ok-camera01.txt"))
        .set("--out {out}/final.png")
        .fails(&["final.png", "give an .exr file"]));
    add(remap(g, "cli-remap-ease-out-of-range", collage_png(W, H))
        .views()
        .args("--ease 1.5")
        .fails(&["ease control 1.5 must be strictly between 0 and 1"]));
    add(remap(g, "cli-remap-tag-bits-9", collage_png(W, H))
        .views()
        .args("--tag-bits 9")
        .fails(&["9 bits per channel: must be 1 to 8"]));
    add(Case::new(g, "cli-remap-no-rays")
        .file("collage.png", collage_png(W, H))
        .args("remap --collage {dir}/collage.png --out {out}/r.mcr -q")
        .fails(&["give both --collage and --rays"]));

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

    cases
}

// ---------------------------------------------------------------------------------------------
// The parent side.

/// What a child reported.
struct Outcome {
    status: String,
    hwm_before_kb: u64,
    hwm_after_kb: u64,
    message: String,
    stderr: String,
}

/// Runs every case in a child process and checks it; fails with every problem found.
#[test]
fn corpus() {
    let cases = cases();
    let mut names = BTreeSet::new();
    for c in &cases {
        assert!(names.insert(c.name.clone()), "two cases are named {}", c.name);
    }
    let root = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("bad-inputs-{}", std::process::id()));
    let logs = root.join("_logs");
    std::fs::create_dir_all(&logs).expect("create the scratch directory");
    let exe = std::env::current_exe().expect("the test binary's path");

    let start = Instant::now();
    let next = AtomicUsize::new(0);
    let results: Mutex<BTreeMap<usize, (Vec<String>, String)>> = Mutex::new(BTreeMap::new());
    std::thread::scope(|s| {
        for _ in 0..PARALLEL {
            s.spawn(|| {
                loop {
                    let k = next.fetch_add(1, Ordering::Relaxed);
                    let Some(case) = cases.get(k) else { break };
                    let (problems, line) = run_case(case, &exe, &root, &logs);
                    results.lock().unwrap().insert(k, (problems, line));
                }
            });
        }
    });
    let results = results.into_inner().unwrap();

    // The summary: every case's outcome (the message is what the troubleshooting table quotes).
    let mut per_group: BTreeMap<&str, (usize, usize)> = BTreeMap::new();
    let mut failures = Vec::new();
    for (k, (problems, line)) in &results {
        let case = &cases[*k];
        let entry = per_group.entry(case.group).or_default();
        entry.0 += 1;
        let mark = if problems.is_empty() { "ok  " } else { "FAIL" };
        println!("{mark} [{}] {}: {line}", case.group, case.name);
        if !problems.is_empty() {
            entry.1 += 1;
            failures.push(format!("case {} [{}]:\n    {}", case.name, case.group, problems.join("\n    ")));
        }
    }
    println!("\n{} cases in {:.1} s:", cases.len(), start.elapsed().as_secs_f64());
    for (group, (n, failed)) in &per_group {
        println!("  {group:<20} {n:>3} cases, {failed} failed");
    }
    if failures.is_empty() {
        let _ = std::fs::remove_dir_all(&root);
    } else {
        panic!(
            "{} of {} malformed-input cases failed (case directories and logs kept in {}):\n\n{}",
            failures.len(),
            cases.len(),
            root.display(),
            failures.join("\n\n")
        );
    }
}

/// Runs one case; returns its problems (empty: it passed) and a one-line summary.
fn run_case(case: &Case, exe: &Path, root: &Path, logs: &Path) -> (Vec<String>, String) {
    let dir = root.join(&case.name);
    let out = dir.join("out");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&out).expect("create the case directory");
    for (path, bytes) in &case.files {
        let path = dir.join(path);
        std::fs::create_dir_all(path.parent().unwrap()).expect("create a staging directory");
        std::fs::write(&path, bytes).expect("stage a file");
    }
    for d in &case.dirs {
        std::fs::create_dir_all(dir.join(d)).expect("create a staged directory");
    }
    let staged = list_files(&dir);
    let (dir_s, out_s) =
        (dir.to_str().expect("UTF-8 scratch path"), out.to_str().expect("UTF-8 scratch path"));
    let args: Vec<String> =
        case.args.iter().map(|a| a.replace("{dir}", dir_s).replace("{out}", out_s)).collect();

    let mut problems = Vec::new();
    let outcome = match run_child(exe, &args, &logs.join(&case.name)) {
        Ok(o) => o,
        Err(e) => {
            problems.push(e.clone());
            return (problems, e);
        }
    };
    let first_line = outcome.message.lines().next().unwrap_or("").to_owned();
    let summary = match outcome.status.as_str() {
        "ok" => "succeeded".to_owned(),
        "error" => format!("error: {}", outcome.message.replace('\n', " ⏎ ")),
        other => format!("{other}: {first_line}"),
    };
    let summary = summary.replace(dir_s, "<dir>");

    // No panic, whatever the expectation.
    if outcome.status == "panic" {
        problems.push(format!("PANICKED: {}", outcome.message));
    }
    if outcome.stderr.contains("panicked at") {
        problems.push(format!("panic text on stderr:\n{}", indent(&outcome.stderr)));
    }
    // The expectation.
    let new_files: BTreeSet<String> = list_files(&dir).difference(&staged).cloned().collect();
    let expected_outputs: BTreeSet<String> = match &case.expect {
        Expect::Fails(want) => {
            match outcome.status.as_str() {
                "error" => {
                    // An error chain that prints a cause twice ("…: No such file (os error 2):
                    // No such file (os error 2)") hides the message in noise.
                    let parts: Vec<&str> = outcome.message.split(": ").collect();
                    if parts.windows(2).any(|w| w[0] == w[1]) {
                        problems.push(format!("the message repeats itself: {}", outcome.message));
                    }
                    let missing: Vec<&String> =
                        want.iter().filter(|w| !outcome.message.contains(w.as_str())).collect();
                    if !missing.is_empty() {
                        problems.push(format!(
                            "the message lacks {missing:?}:\n{}",
                            indent(&outcome.message.replace(dir_s, "<dir>"))
                        ));
                    }
                }
                "ok" => {
                    problems.push("ACCEPTED: the run succeeded, but this input must be refused".to_owned())
                }
                _ => {}
            }
            BTreeSet::new()
        }
        Expect::Warns { stderr, outputs } => {
            if outcome.status == "error" {
                problems.push(format!(
                    "REFUSED: expected a warning and a render, got an error: {}",
                    outcome.message
                ));
            }
            let missing: Vec<&String> =
                stderr.iter().filter(|w| !outcome.stderr.contains(w.as_str())).collect();
            if !missing.is_empty() {
                problems.push(format!(
                    "stderr lacks {missing:?}:\n{}",
                    indent(&outcome.stderr.replace(dir_s, "<dir>"))
                ));
            }
            outputs.iter().cloned().collect()
        }
        Expect::Succeeds { outputs } => {
            if outcome.status == "error" {
                problems.push(format!("control case failed: {}", outcome.message.replace(dir_s, "<dir>")));
            }
            outputs.iter().cloned().collect()
        }
    };
    // Nothing left behind (after a failure), exactly the outputs (after a success): no
    // temporaries either way.
    if outcome.status != "ok" || !matches!(case.expect, Expect::Fails(_)) {
        let stray: Vec<&String> = new_files.difference(&expected_outputs).collect();
        if !stray.is_empty() {
            problems.push(format!("LEFT BEHIND: files the run should not have written: {stray:?}"));
        }
        if outcome.status == "ok" {
            let absent: Vec<&String> = expected_outputs.difference(&new_files).collect();
            if !absent.is_empty() {
                problems.push(format!("expected outputs missing: {absent:?}"));
            }
        }
    }
    // Memory.
    let grew = outcome.hwm_after_kb.saturating_sub(outcome.hwm_before_kb);
    if case.memory && grew > MEMORY_BUDGET_KB {
        problems.push(format!(
            "ALLOCATED: peak resident set grew by {} MiB (budget {} MiB)",
            grew >> 10,
            MEMORY_BUDGET_KB >> 10
        ));
    }
    let summary = if case.memory { format!("{summary} [peak RSS +{} KiB]", grew) } else { summary };
    (problems, summary)
}

/// Starts the child for `args` under the address-space limit and collects its outcome.
fn run_child(exe: &Path, args: &[String], log_stem: &Path) -> Result<Outcome, String> {
    let result = log_stem.with_extension("result");
    let (stdout, stderr) = (log_stem.with_extension("stdout"), log_stem.with_extension("stderr"));
    let _ = std::fs::remove_file(&result);
    let joined = args.join("\u{1f}");
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {ADDRESS_SPACE_LIMIT_KB} && exec \"$0\" \"$@\""))
        .arg(exe)
        .args([CHILD_TEST, "--exact", "--ignored", "--nocapture", "--test-threads=1", "-q"])
        .env(ENV_ARGS, &joined)
        .env(ENV_RESULT, &result)
        .env("RAYON_NUM_THREADS", "2")
        .env("MALLOC_ARENA_MAX", "2")
        .env("RUST_BACKTRACE", "0")
        .env_remove("RUST_LOG")
        .stdin(Stdio::null())
        .stdout(std::fs::File::create(&stdout).map_err(|e| e.to_string())?)
        .stderr(std::fs::File::create(&stderr).map_err(|e| e.to_string())?)
        .spawn()
        .map_err(|e| format!("cannot start the child process through sh: {e}"))?;
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait().map_err(|e| e.to_string())? {
            break status;
        }
        if start.elapsed() > CASE_TIMEOUT {
            let _ = child.kill();
            let _ = child.wait();
            return Err(format!("HUNG: no answer after {} s; killed", CASE_TIMEOUT.as_secs()));
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    let stderr_text = std::fs::read_to_string(&stderr).unwrap_or_default();
    let Ok(text) = std::fs::read_to_string(&result) else {
        use std::os::unix::process::ExitStatusExt;
        let how = match status.signal() {
            Some(6) => "CRASHED: killed by SIGABRT (e.g. a failed allocation)".to_owned(),
            Some(11) => "CRASHED: killed by SIGSEGV (e.g. a stack overflow)".to_owned(),
            Some(sig) => format!("CRASHED: killed by signal {sig}"),
            None => format!("CRASHED: exited with {status} without an outcome"),
        };
        return Err(format!("{how}; stderr:\n{}", indent(&tail(&stderr_text, 2000))));
    };
    let mut parts = text.splitn(4, '\n');
    let status_word = parts.next().unwrap_or("").to_owned();
    let before = parts.next().and_then(|v| v.parse().ok()).unwrap_or(0);
    let after = parts.next().and_then(|v| v.parse().ok()).unwrap_or(0);
    let message = parts.next().unwrap_or("").to_owned();
    Ok(Outcome {
        status: status_word,
        hwm_before_kb: before,
        hwm_after_kb: after,
        message,
        stderr: stderr_text,
    })
}

/// Every file under `dir`, as paths relative to it (directories themselves are not listed).
fn list_files(dir: &Path) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for entry in entries.flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else {
                found.insert(path.strip_prefix(dir).unwrap().to_string_lossy().into_owned());
            }
        }
    }
    found
}

fn indent(text: &str) -> String {
    text.lines().map(|l| format!("      | {l}")).collect::<Vec<_>>().join("\n")
}

fn tail(text: &str, max: usize) -> String {
    let start = text.len().saturating_sub(max);
    let start = (start..text.len()).find(|&i| text.is_char_boundary(i)).unwrap_or(text.len());
    text[start..].to_owned()
}

// ---------------------------------------------------------------------------------------------
// Generators of the binary inputs: tiny hand-written encoders, so every byte is deliberate and
// the output never changes with a dependency's version.

/// The triangle scene's buffer: 3 positions (VEC3 f32), 3 texture coordinates (VEC2 f32),
/// 3 u16 indices and 2 bytes of padding: 68 bytes (the same data as the committed
/// `gltf/ok-triangle.gltf`'s data URI).
fn triangle_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 1.] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b.extend_from_slice(&[0, 0]);
    b
}

/// The triangle scene for GLB: `ok-triangle.gltf` with its buffer in the BIN chunk.
const GLB_JSON: &str = r#"{"asset":{"version":"2.0","generator":"mcctrace bad_inputs corpus"},"scene":0,"scenes":[{"nodes":[0,1]}],"nodes":[{"name":"triangle","mesh":0},{"name":"front","camera":0,"translation":[0.3,0.3,2.0]}],"cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.01}}],"meshes":[{"name":"triangle","primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],"materials":[{"name":"glow","pbrMetallicRoughness":{"baseColorFactor":[0.8,0.8,0.8,1.0],"metallicFactor":0.0},"emissiveFactor":[1.0,1.0,1.0]}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"},{"bufferView":2,"componentType":5123,"count":3,"type":"SCALAR"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24},{"buffer":0,"byteOffset":60,"byteLength":6}],"buffers":[{"byteLength":68}]}"#;

/// A GLB container: header, the JSON chunk (space-padded) and an optional BIN chunk.
fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes()); // total length, set below
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while bin.len() % 4 != 0 {
            bin.push(0);
        }
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    let len = out.len() as u32;
    out[8..12].copy_from_slice(&len.to_le_bytes());
    out
}

/// The binary ray file magic (`mcc::ray_file` documents the layout).
const MCR_MAGIC: &[u8; 8] = b"\x89MCR\r\n\x1a\n";

/// A binary ray file: magic, version, width, height, frame, camera, flags, then the records.
fn mcr(
    width: u32,
    height: u32,
    frame: u32,
    camera: u32,
    flags: u32,
    version: u32,
    rays: &[[f32; 6]],
) -> Vec<u8> {
    let mut out = MCR_MAGIC.to_vec();
    for v in [version, width, height, frame, camera, flags] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for r in rays {
        for v in r {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// The rays of a (good) text ray file, in row-major order.
fn parse_text_rays(text: &[u8]) -> Vec<[f32; 6]> {
    let text = std::str::from_utf8(text).unwrap();
    let mut lines = text.lines();
    let header: Vec<usize> = lines.next().unwrap().split_whitespace().map(|v| v.parse().unwrap()).collect();
    let (w, h) = (header[0], header[1]);
    let mut rays = vec![[0f32; 6]; w * h];
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split_whitespace().collect();
        let (i, j): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        for (slot, v) in rays[j * w + i].iter_mut().zip(&f[2..]) {
            *slot = v.parse().unwrap();
        }
    }
    rays
}

/// `rgb` with camera `id` in its 2 low bits per channel (SPEC §4, b = 2).
fn tag(rgb: [u8; 3], id: u32) -> [u8; 3] {
    let part = |k: u32| ((id >> (2 * k)) & 3) as u8;
    [(rgb[0] & !3) | part(0), (rgb[1] & !3) | part(1), (rgb[2] & !3) | part(2)]
}

/// The collage's pixel at (x, y): columns 0–3 camera 1, 4–5 background, 6 and beyond camera 2.
fn collage_pixel(x: u32, y: u32) -> [u8; 3] {
    match x {
        0..=3 => tag([200, 120 + 8 * y as u8, 60], 1),
        4 | 5 => [0, 0, 0],
        _ => tag([40, 160, 220 - 8 * y as u8], 2),
    }
}

/// The good collage, `width × height` (8 × 6 matches the ray files).
fn collage_png(width: u32, height: u32) -> Vec<u8> {
    let mut rgb = Vec::new();
    for y in 0..height {
        for x in 0..width {
            rgb.extend_from_slice(&collage_pixel(x, y));
        }
    }
    png(width, height, 2, 8, &rgb)
}

/// The good collage with column 4 blended half-way between camera 1 and the background, as an
/// antialiased selection edge leaves it: 6 pixels whose low bits name no camera with a ray file.
fn antialiased_png() -> Vec<u8> {
    let mut rgb = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let p = if x == 4 {
                let c = collage_pixel(3, y);
                // Half of camera 1's colour; force the low bits to a pattern that is no camera.
                let blended = [c[0] / 2, c[1] / 2, c[2] / 2];
                let id = [blended[0] & 3, blended[1] & 3, blended[2] & 3];
                if matches!(id, [1, 0, 0] | [2, 0, 0]) {
                    [blended[0] & !3, blended[1] & !3, blended[2] | 1]
                } else {
                    blended
                }
            } else {
                collage_pixel(x, y)
            };
            rgb.extend_from_slice(&p);
        }
    }
    png(W, H, 2, 8, &rgb)
}

/// The good collage with the top two rows of camera 2's columns tagged as camera 5, which has no
/// ray file: 4 pixels.
fn unknown_id_png() -> Vec<u8> {
    let mut rgb = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let p = if x >= 6 && y < 2 { tag(collage_pixel(x, y), 5) } else { collage_pixel(x, y) };
            rgb.extend_from_slice(&p);
        }
    }
    png(W, H, 2, 8, &rgb)
}

/// The good collage as 16-bit RGB: every value widened exactly (v · 257), or with pixel (2, 3)'s
/// red one code off when `inexact`.
fn collage_png16(inexact: bool) -> Vec<u8> {
    let mut bytes = Vec::new();
    for y in 0..H {
        for x in 0..W {
            for (c, v) in collage_pixel(x, y).into_iter().enumerate() {
                let mut wide = v as u16 * 257;
                if inexact && (x, y, c) == (2, 3, 0) {
                    wide += 1;
                }
                bytes.extend_from_slice(&wide.to_be_bytes());
            }
        }
    }
    png(W, H, 2, 16, &bytes)
}

/// A PNG of `width × height` with colour type `color_type` (0 grey, 2 RGB, 6 RGBA) and
/// `depth` bits per sample; `samples` are the rows' bytes without filter bytes. Deflate
/// "stored" blocks: no compression, byte-stable.
fn png(width: u32, height: u32, color_type: u8, depth: u8, samples: &[u8]) -> Vec<u8> {
    let channels = match color_type {
        0 => 1,
        2 => 3,
        4 => 2,
        6 => 4,
        _ => panic!("colour type {color_type}"),
    };
    let row = (width as usize * channels * depth as usize).div_ceil(8);
    assert_eq!(samples.len(), row * height as usize, "PNG sample count");
    let mut raw = Vec::new();
    for r in samples.chunks(row) {
        raw.push(0); // filter: none
        raw.extend_from_slice(r);
    }
    let mut z = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65535).collect();
    for (k, block) in blocks.iter().enumerate() {
        z.push(u8::from(k + 1 == blocks.len()));
        z.extend_from_slice(&(block.len() as u16).to_le_bytes());
        z.extend_from_slice(&(!(block.len() as u16)).to_le_bytes());
        z.extend_from_slice(block);
    }
    z.extend_from_slice(&adler32(&raw).to_be_bytes());
    let mut out = png_start(width, height, depth, color_type);
    png_chunk(&mut out, b"IDAT", &z);
    png_chunk(&mut out, b"IEND", &[]);
    out
}

/// A PNG that is only a (valid) header claiming `width × height` 8-bit pixels, then IEND: what
/// a corrupt or hostile file looks like to a reader that trusts its header.
fn png_header_only(width: u32, height: u32, color_type: u8) -> Vec<u8> {
    let mut out = png_start(width, height, 8, color_type);
    png_chunk(&mut out, b"IEND", &[]);
    out
}

fn png_start(width: u32, height: u32, depth: u8, color_type: u8) -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[depth, color_type, 0, 0, 0]);
    png_chunk(&mut out, b"IHDR", &ihdr);
    out
}

fn png_chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

fn adler32(bytes: &[u8]) -> u32 {
    let (mut a, mut b) = (1u32, 0u32);
    for &x in bytes {
        a = (a + u32::from(x)) % 65521;
        b = (b + a) % 65521;
    }
    (b << 16) | a
}

/// A single-part scan-line OpenEXR file, uncompressed, channels B, G, R as f32, claiming
/// `width × height` pixels. With `pixels` (row-major RGB) the offset table and scan lines
/// follow; without, the file ends after the header (a 10^6 × 10^6 claim in ~330 bytes).
fn exr(width: u32, height: u32, pixels: Option<&[[f32; 3]]>) -> Vec<u8> {
    fn attribute(out: &mut Vec<u8>, name: &str, kind: &str, value: &[u8]) {
        out.extend_from_slice(name.as_bytes());
        out.push(0);
        out.extend_from_slice(kind.as_bytes());
        out.push(0);
        out.extend_from_slice(&(value.len() as i32).to_le_bytes());
        out.extend_from_slice(value);
    }
    let mut out = vec![0x76, 0x2f, 0x31, 0x01];
    out.extend_from_slice(&2u32.to_le_bytes()); // version 2, single-part scan lines
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&2i32.to_le_bytes()); // FLOAT
        channels.extend_from_slice(&[0, 0, 0, 0]); // pLinear, reserved
        channels.extend_from_slice(&1i32.to_le_bytes()); // x sampling
        channels.extend_from_slice(&1i32.to_le_bytes()); // y sampling
    }
    channels.push(0);
    attribute(&mut out, "channels", "chlist", &channels);
    attribute(&mut out, "compression", "compression", &[0]); // NO_COMPRESSION
    let window: Vec<u8> =
        [0i32, 0, width as i32 - 1, height as i32 - 1].iter().flat_map(|v| v.to_le_bytes()).collect();
    attribute(&mut out, "dataWindow", "box2i", &window);
    attribute(&mut out, "displayWindow", "box2i", &window);
    attribute(&mut out, "lineOrder", "lineOrder", &[0]); // INCREASING_Y
    attribute(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute(&mut out, "screenWindowCenter", "v2f", &[0u8; 8]);
    attribute(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0); // end of header
    let Some(pixels) = pixels else { return out };
    assert_eq!(pixels.len(), (width * height) as usize, "EXR pixel count");
    // Offset table (one scan line per block without compression), then the blocks: y, size,
    // then the line's samples channel by channel (B, G, R).
    let line_bytes = width as usize * 3 * 4;
    let table_end = out.len() + 8 * height as usize;
    for y in 0..height as usize {
        out.extend_from_slice(&((table_end + y * (8 + line_bytes)) as u64).to_le_bytes());
    }
    for y in 0..height as usize {
        out.extend_from_slice(&(y as i32).to_le_bytes());
        out.extend_from_slice(&(line_bytes as i32).to_le_bytes());
        let row = &pixels[y * width as usize..(y + 1) * width as usize];
        for c in [2, 1, 0] {
            for p in row {
                out.extend_from_slice(&p[c].to_le_bytes());
            }
        }
    }
    out
}
