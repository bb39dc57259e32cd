//! One big still on the real schedulers (docs/farm.md, "Big stills"): `mcctrace farm slurm
//! --bands N -- render …` submitted to the one-node Slurm (a job array of bands, then the merge
//! after it), and `mcctrace farm openjd --bands N -- rerender --lens …` run by `openjd run`,
//! each give the files of a single local run of the same command bit for bit (every layer's
//! pixels, the header but the seconds, the PNG's bytes); `openjd check` accepts the template;
//! bad values are refused naming the flag. The commands use relative paths: they run in the
//! folder the farm command ran in.

use super::bands::{CORNELL, assert_same_image, cornell_lens, run};
use super::cluster::Cluster;
use super::wrapper;
use crate::common::external::external;
use crate::common::{Scratch, repo_root};
use std::path::Path;
use std::process::Command;

/// Runs `program ARGS` in `cwd`, panicking with its output on failure.
fn run_in(cwd: &Path, program: &Path, args: &[&str]) {
    let out = Command::new(program).args(args).current_dir(cwd).output().expect("run mcctrace");
    assert!(
        out.status.success(),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A Cornell box still at 24x10, 4 spp with AOVs, written to `out` (relative).
fn render_words(out: &str) -> Vec<String> {
    let scene = repo_root().join(CORNELL).display().to_string();
    ["render", &scene, "--res", "24x10", "--spp", "4", "--aovs", "--max-depth", "3", "--out", out, "--quiet"]
        .map(String::from)
        .into()
}

/// The farm command's words: `farm SCHEDULER --bands N --dir DIR …options -- COMMAND`.
fn farm_words(scheduler: &str, bands: u32, dir: &Path, program: &Path, command: &[String]) -> Vec<String> {
    let mut a: Vec<String> = vec!["farm".into(), scheduler.into(), "--bands".into(), bands.to_string()];
    a.extend(["--dir".into(), dir.display().to_string(), "--cpus-per-task".into(), "1".into()]);
    a.extend(["--mcctrace".into(), program.display().to_string(), "--".into()]);
    a.extend(command.iter().cloned());
    a
}

/// The still on a real Slurm in 4 bands of 3, 3, 2 and 2 rows: the merged files are the single
/// run's.
#[test]
fn slurm_renders_a_still_in_bands_to_the_single_render() {
    let Some(cluster) = Cluster::find() else { return };
    let dir = Scratch::new("farm-still-slurm");
    let program = wrapper(dir.dir());
    let words = |out: &str| render_words(out);
    run_in(dir.dir(), &program, &words("single/big.exr").iter().map(String::as_str).collect::<Vec<_>>());
    let jobs_dir = dir.path("still jobs");
    let jobs = cluster.submit_in(
        dir.dir(),
        &program,
        &farm_words("slurm", 4, &jobs_dir, &program, &words("farm/big.exr")),
    );
    assert_eq!(jobs.iter().map(|(s, _)| s.as_str()).collect::<Vec<_>>(), ["bands", "merge"], "{jobs:?}");
    cluster.wait(&jobs, &jobs_dir);
    cluster.assert_completed(&jobs, &jobs_dir);
    assert_same_image(&dir.path("farm/big.exr"), &dir.path("single/big.exr"), "Slurm still in 4 bands");
    assert!(dir.path("farm/big.tile4of4.exr").is_file(), "the bands stay for a re-run to skip");
}

/// The template of a rerender through a lens file in 13 bands (more than its 10 rows: three are
/// empty) passes `openjd check`, and `openjd run` gives the single run's files.
#[test]
fn openjd_template_renders_a_still_in_bands_to_the_single_render() {
    let Some(openjd) = external("openjd") else { return };
    let dir = Scratch::new("farm-still-openjd");
    let program = wrapper(dir.dir());
    cornell_lens(&dir, "24x10");
    let scene = repo_root().join(CORNELL).display().to_string();
    let words = |out: &str| -> Vec<String> {
        let lens = "views/frame0000camera01.mcr";
        ["rerender", &scene, "--lens", lens, "--spp", "3", "--adaptive", "--out", out, "--quiet"]
            .map(String::from)
            .into()
    };
    run_in(dir.dir(), &program, &words("single/big.exr").iter().map(String::as_str).collect::<Vec<_>>());
    let jobs_dir = dir.path("still jobs");
    let farm = farm_words("openjd", 13, &jobs_dir, &program, &words("farm/big.exr"));
    run_in(dir.dir(), &program, &farm.iter().map(String::as_str).collect::<Vec<_>>());
    let template = jobs_dir.join(farm::openjd::TEMPLATE_NAME);
    for verb in ["check", "run"] {
        let out = Command::new(&openjd).arg(verb).arg(&template).output().expect("run openjd");
        assert!(
            out.status.success(),
            "openjd {verb} failed:\n{}{}\n{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
            std::fs::read_to_string(&template).unwrap()
        );
    }
    assert_same_image(&dir.path("farm/big.exr"), &dir.path("single/big.exr"), "OpenJD still in 13 bands");
}

/// Bad values are refused before anything is written, naming the flag.
#[test]
fn bad_still_flags_are_refused_naming_the_flag() {
    let dir = Scratch::new("farm-still-bad");
    let jobs = dir.s("jobs");
    fn render<'a>(extra: &[&'a str]) -> Vec<&'a str> {
        let mut c = vec!["render", CORNELL, "--res", "24x10", "--out", "big.exr"];
        c.extend(extra);
        c
    }
    let cases: [(&str, Vec<&str>, &str); 8] = [
        ("slurm", [&["--bands", "0", "--dir", &jobs, "--"][..], &render(&[])].concat(), "--bands: 0 bands"),
        (
            "openjd",
            [&["--bands", "2", "--dir", &jobs, "--"][..], &render(&["--tile", "1/2"])].concat(),
            "--tile: ",
        ),
        (
            "slurm",
            [&["--bands", "2", "--dir", &jobs, "--"][..], &render(&["--lens-writer"])].concat(),
            "--lens-writer: ",
        ),
        ("slurm", [&["--bands", "2", "--dir", &jobs, "--"][..], &render(&["--tag"])].concat(), "--tag: "),
        (
            "openjd",
            [&["--bands", "2", "--dir", &jobs, "--"][..], &["animate", CORNELL][..]].concat(),
            "COMMAND",
        ),
        (
            "slurm",
            [&["--bands", "2", "--dir", &jobs, "--"][..], &render(&["--camera", "a", "--camera", "b"])]
                .concat(),
            "--camera: ",
        ),
        ("slurm", [&["--bands", "2", "--dir", &jobs, "--"][..], &render(&["--spp", "x"])].concat(), "--spp"),
        (
            "slurm",
            [&["--bands", "2", "--dir", &jobs, "--spp", "4", "--"][..], &render(&[])].concat(),
            "--spp",
        ),
    ];
    for (scheduler, args, needle) in cases {
        let args = [&["farm", scheduler][..], &args].concat();
        let (ok, err) = run(&args);
        assert!(!ok && err.contains(needle), "{args:?}: {err}");
    }
    assert!(!dir.path("jobs").exists(), "a refused still writes nothing");
}
