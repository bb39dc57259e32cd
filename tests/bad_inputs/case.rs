//! The malformed-input corpus (`tests/bad_inputs/`): what a case is, and the builders the
//! case lists (`scene_cases.rs`, `mcc_cases.rs`) use.

use super::encoders::collage_png;
use super::{H, W};
use std::path::Path;

/// What a case must do.
#[derive(Clone, Debug)]
pub(crate) enum Expect {
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
pub(crate) struct Case {
    /// Category, for the summary.
    pub(crate) group: &'static str,
    /// Unique name; also the case's directory.
    pub(crate) name: String,
    /// Files to stage in the case directory: (relative path, bytes).
    pub(crate) files: Vec<(String, Vec<u8>)>,
    /// Directories to create (empty) in the case directory.
    pub(crate) dirs: Vec<String>,
    /// The command line after `mcctrace`; `{dir}` is the case directory, `{out}` its `out/`.
    pub(crate) args: Vec<String>,
    pub(crate) expect: Expect,
    /// Refused before allocating: the peak resident set must stay within [`MEMORY_BUDGET_KB`].
    pub(crate) memory: bool,
}

impl Case {
    pub(crate) fn new(group: &'static str, name: &str) -> Self {
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
    pub(crate) fn file(mut self, path: &str, bytes: impl Into<Vec<u8>>) -> Self {
        self.files.push((path.to_owned(), bytes.into()));
        self
    }

    /// Stages the committed corpus file `corpus_path` under its own file name.
    pub(crate) fn corpus(self, corpus_path: &str) -> Self {
        let name = Path::new(corpus_path).file_name().unwrap().to_str().unwrap().to_owned();
        self.file(&name, corpus_file(corpus_path))
    }

    /// Creates an empty directory.
    pub(crate) fn dir(mut self, path: &str) -> Self {
        self.dirs.push(path.to_owned());
        self
    }

    /// The two good views' ray files in `views/` (text, as committed).
    pub(crate) fn views(self) -> Self {
        self.file("views/frame0000camera01.txt", corpus_file("rays/ok-camera01.txt"))
            .file("views/frame0000camera02.txt", corpus_file("rays/ok-camera02.txt"))
    }

    /// Appends whitespace-separated arguments (placeholders are substituted per token, so
    /// paths with spaces are safe).
    pub(crate) fn args(mut self, template: &str) -> Self {
        self.args.extend(template.split_whitespace().map(str::to_owned));
        self
    }

    /// Sets command-line flags: a `--flag value` pair already on the command line gets the new
    /// value (clap refuses a flag given twice, so appending would test clap, not the value);
    /// anything else is appended.
    pub(crate) fn set(mut self, template: &str) -> Self {
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

    pub(crate) fn fails(mut self, want: &[&str]) -> Self {
        assert!(!want.is_empty(), "{}: a failing case must say what its message holds", self.name);
        self.expect = Expect::Fails(want.iter().map(|s| s.to_string()).collect());
        self
    }

    pub(crate) fn warns(mut self, stderr: &[&str], outputs: &[&str]) -> Self {
        self.expect = Expect::Warns {
            stderr: stderr.iter().map(|s| s.to_string()).collect(),
            outputs: outputs.iter().map(|s| s.to_string()).collect(),
        };
        self
    }

    pub(crate) fn succeeds(mut self, outputs: &[&str]) -> Self {
        self.expect = Expect::Succeeds { outputs: outputs.iter().map(|s| s.to_string()).collect() };
        self
    }

    pub(crate) fn memory(mut self) -> Self {
        self.memory = true;
        self
    }
}

/// The committed corpus file at `path` (relative to `tests/bad_inputs`).
pub(crate) fn corpus_file(path: &str) -> Vec<u8> {
    let full = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad_inputs").join(path);
    std::fs::read(&full).unwrap_or_else(|e| panic!("corpus file {}: {e}", full.display()))
}

/// Render settings every render case uses: tiny and quick.
pub(crate) const QUICK: &str = "--res 8x6 --spp 1 --threads 1";
/// The ad-hoc camera of the OBJ cases.
pub(crate) const OBJ_CAMERA: &str = "--look-from 0.3,0.3,2 --look-at 0.3,0.3,0";
/// Outputs of a render to `out/render.exr`.
pub(crate) const RENDER_OUTPUTS: &[&str] = &["out/render.exr", "out/render.png"];

/// `render FILE` of a staged scene, quiet.
pub(crate) fn render(group: &'static str, name: &str, corpus_path: &str) -> Case {
    let file = Path::new(corpus_path).file_name().unwrap().to_str().unwrap().to_owned();
    Case::new(group, name)
        .corpus(corpus_path)
        .args(&format!("render {{dir}}/{file} {QUICK} -q --out {{out}}/render.exr"))
}

/// `render FILE` of staged bytes, quiet.
pub(crate) fn render_bytes(group: &'static str, name: &str, file: &str, bytes: Vec<u8>) -> Case {
    Case::new(group, name)
        .file(file, bytes)
        .args(&format!("render {{dir}}/{file} {QUICK} -q --out {{out}}/render.exr"))
}

/// `render FILE` of a staged OBJ scene with the ad-hoc camera; `quiet` hides warnings.
pub(crate) fn render_obj(name: &str, corpus_path: &str, quiet: bool) -> Case {
    let file = Path::new(corpus_path).file_name().unwrap().to_str().unwrap().to_owned();
    let q = if quiet { "-q" } else { "" };
    Case::new("OBJ/MTL", name)
        .corpus(corpus_path)
        .args(&format!("render {{dir}}/{file} {OBJ_CAMERA} {QUICK} {q} --out {{out}}/render.exr"))
}

/// `remap` of `collage.png` (staged bytes) against `views/`.
pub(crate) fn remap(group: &'static str, name: &str, collage: Vec<u8>) -> Case {
    Case::new(group, name)
        .file("collage.png", collage)
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
}

/// `remap` of the good collage with camera 1's ray file replaced by `file` (named
/// `frame0000camera01.<ext>`).
pub(crate) fn remap_bad_rays(name: &str, ext: &str, bytes: Vec<u8>) -> Case {
    let group = if ext == "mcr" { "ray file (binary)" } else { "ray file (text)" };
    Case::new(group, name)
        .file("collage.png", collage_png(W, H))
        .file(&format!("views/frame0000camera01.{ext}"), bytes)
        .file("views/frame0000camera02.txt", corpus_file("rays/ok-camera02.txt"))
        .args("remap --collage {dir}/collage.png --rays {dir}/views --out {out}/rerender-frame0000.mcr -q")
}

/// `rerender --lens FILE` of the good triangle scene.
pub(crate) fn rerender_lens(group: &'static str, name: &str, lens: &str, bytes: Vec<u8>) -> Case {
    Case::new(group, name)
        .corpus("gltf/ok-triangle.gltf")
        .file(lens, bytes)
        .args(&format!("rerender {{dir}}/ok-triangle.gltf --lens {{dir}}/{lens} --spp 1 --threads 1 -q --out {{out}}/final.exr"))
}
