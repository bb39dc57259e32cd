//! One big still as render-farm jobs (docs/farm.md, "Big stills"): a `render` or `rerender`
//! command line cut into N horizontal bands, one task each (`--tile I/N`), then one `merge` of
//! the bands into the image a single run would have written; as Slurm batch scripts (a job
//! array, then a merge job after it by `afterok`) or an Open Job Description template (a band
//! parameter space, then a merge step depending on it).
//!
//! The command is the user's own, word for word, run in the folder it was given in (its relative
//! paths stay right on any machine that sees that folder at the same path).

use crate::openjd::{Step, int_param, job_template, param, run_script};
use crate::quote::{sh, wrap};
use crate::shot::{Resources, StageResources, Word};
use crate::slurm::{Header, Scripts, array_task, chain_script, command_line, numbered_script, write_scripts};
use crate::yaml::s;
use crate::{Result, bad, write_file};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Flags `--tile` refuses (they need the whole view): refused here too, before any task runs.
const WHOLE_VIEW_FLAGS: [&str; 3] = ["--lens-writer", "--tag", "--layers"];

/// A still to render in bands.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Still {
    /// The `mcctrace` program the tasks run.
    pub mcctrace: PathBuf,
    /// The folder the command runs in (its relative paths start there).
    pub workdir: PathBuf,
    /// The job folder: `slurm/`, `logs/` or the template go here.
    pub dir: PathBuf,
    /// The command after the program: `render …` or `rerender …`, without `--tile`.
    pub command: Vec<String>,
    /// The whole image the command writes (its `--out`), where the merge writes it.
    pub out: PathBuf,
    /// How many bands.
    pub bands: u32,
    /// The image's width and height, for the default resources.
    pub size: (u32, u32),
    /// Its samples per pixel, likewise.
    pub spp: u32,
    /// What each task asks for.
    pub resources: Resources,
}

/// A stage of a still, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StillStage {
    /// One task per band: the command with `--tile I/N`.
    Bands,
    /// `merge` of the bands into the whole EXR and PNG (one task).
    Merge,
}

impl StillStage {
    /// Every stage, in order.
    pub const ALL: [StillStage; 2] = [StillStage::Bands, StillStage::Merge];

    /// Its name in file and job names.
    pub fn name(self) -> &'static str {
        match self {
            StillStage::Bands => "bands",
            StillStage::Merge => "merge",
        }
    }

    fn step_name(self) -> &'static str {
        match self {
            StillStage::Bands => "Bands",
            StillStage::Merge => "Merge",
        }
    }
}

/// Refuses, naming the flag, a still of no bands, or a command that is not a `render` or
/// `rerender`, has a `--tile` of its own or a flag `--tile` refuses.
pub fn check_command(bands: u32, command: &[String]) -> Result<()> {
    if bands == 0 {
        return Err(bad("--bands", "0 bands: need at least 1"));
    }
    match command.first().map(String::as_str) {
        Some("render" | "rerender") => {}
        other => {
            return Err(bad(
                "COMMAND",
                format!(
                    "{}: a still is a `render` or `rerender` command (after --)",
                    other.map_or("nothing".to_owned(), |w| format!("{w:?}"))
                ),
            ));
        }
    }
    let has = |flag: &str| {
        command.iter().any(|w| w == flag || w.strip_prefix(flag).is_some_and(|r| r.starts_with('=')))
    };
    if has("--tile") {
        return Err(bad("--tile", "the farm gives every band task its own --tile I/N: leave it out"));
    }
    if let Some(flag) = WHOLE_VIEW_FLAGS.into_iter().find(|f| has(f)) {
        return Err(bad(
            flag,
            "needs the whole view, so --tile refuses it: render that view in one piece instead",
        ));
    }
    Ok(())
}

fn absolute(path: &Path, flag: &'static str) -> Result<PathBuf> {
    std::path::absolute(path).map_err(|e| bad(flag, format!("{}: {e}", path.display())))
}

impl Still {
    /// The still checked, its paths made absolute; every error names the flag to fix.
    pub fn plan(&self) -> Result<Still> {
        let mut still = self.clone();
        check_command(still.bands, &still.command)?;
        if !still.out.extension().is_some_and(|e| e.eq_ignore_ascii_case("exr")) {
            return Err(bad("--out", format!("{}: a still in bands is one .exr file", still.out.display())));
        }
        still.resources.check()?;
        still.mcctrace = absolute(&still.mcctrace, "--mcctrace")?;
        still.workdir = absolute(&still.workdir, "COMMAND")?;
        still.dir = absolute(&still.dir, "--dir")?;
        still.out = still.workdir.join(&still.out);
        Ok(still)
    }

    /// The command a stage's task runs (after the `mcctrace` program itself).
    pub fn command(&self, stage: StillStage) -> Vec<Word> {
        match stage {
            StillStage::Bands => {
                let mut c: Vec<Word> = self.command.iter().cloned().map(Word::Text).collect();
                c.extend([Word::Text("--tile".into()), Word::Tile(self.bands)]);
                c
            }
            StillStage::Merge => {
                ["merge", "--out", &self.out.display().to_string()].map(|w| Word::Text(w.to_owned())).into()
            }
        }
    }

    /// How many tasks a stage has.
    pub fn tasks(&self, stage: StillStage) -> u32 {
        match stage {
            StillStage::Bands => self.bands,
            StillStage::Merge => 1,
        }
    }

    /// A stage's resources: the still's, or defaults from its size and samples. A band holds the
    /// whole film (adaptive sampling's pilot pass covers it); the merge the image.
    pub fn resources(&self, stage: StillStage) -> StageResources {
        let pixels = u64::from(self.size.0) * u64::from(self.size.1);
        match stage {
            StillStage::Bands => {
                let samples = (pixels * u64::from(self.spp)).div_ceil(u64::from(self.bands.max(1)));
                self.resources.for_task(pixels, samples, 1)
            }
            StillStage::Merge => self.resources.for_task(pixels, 0, 1),
        }
    }

    /// Whether the command sets its own `--threads` (else the farm gives it the task's CPUs).
    fn own_threads(&self) -> bool {
        self.command.iter().any(|w| w == "--threads" || w.starts_with("--threads="))
    }

    /// The batch script of `stage`.
    pub fn slurm_script(&self, stage: StillStage) -> String {
        let what = match stage {
            StillStage::Bands => "one band of the image per array task (finished bands are skipped)",
            StillStage::Merge => "the bands merged into the whole EXR and PNG",
        };
        let array = (stage == StillStage::Bands).then(|| format!("1-{}", self.bands));
        let mut t = String::new();
        Header {
            kind: "still",
            dir: &self.dir,
            stage: stage.name(),
            what,
            array: array.clone(),
            resources: self.resources(stage),
            partition: self.resources.partition.as_deref(),
            after: stage != StillStage::Bands,
            mcctrace: &self.mcctrace,
        }
        .write(&mut t);
        if let Some(ids) = &array {
            let _ = writeln!(t, "# Task i renders band i of {}.", self.bands);
            let _ = writeln!(t, "{}", array_task(ids));
        }
        let _ = writeln!(t, "cd {}", sh(&self.workdir.display().to_string()));
        let threads = stage == StillStage::Bands && !self.own_threads();
        let _ = writeln!(t, "\n{}", command_line(self.command(stage), "", threads));
        t
    }

    /// Writes the stages' batch scripts and `submit.sh` into `DIR/slurm/`.
    pub fn write_slurm(&self) -> Result<Scripts> {
        let stages: Vec<_> = (1..)
            .zip(StillStage::ALL)
            .map(|(n, s)| (s.name(), numbered_script(n, s.name()), self.slurm_script(s)))
            .collect();
        let names: Vec<_> = stages.iter().map(|(name, file, _)| (*name, file.clone())).collect();
        let submit =
            chain_script(&self.dir.join("slurm"), &names, "Re-run it to resume: finished bands are skipped.");
        write_scripts(&self.dir, &stages, &submit)
    }

    /// The bash script a step's task runs: into the work folder, then the command.
    fn openjd_script(&self, stage: StillStage) -> String {
        let mut words = vec![sh(&self.mcctrace.display().to_string())];
        words.extend(self.command(stage).iter().map(|w| match w {
            Word::Text(t) => sh(t),
            _ => "{{Task.Param.Band}}/{{Param.Bands}}".to_owned(),
        }));
        format!(
            "#!/usr/bin/env bash\nset -euo pipefail\ncd {}\nexec {}\n",
            sh(&self.workdir.display().to_string()),
            wrap(&words)
        )
    }

    /// The Open Job Description template: the bands as a parameter space `1-Bands` over a job
    /// parameter, then the merge.
    pub fn openjd_template(&self) -> String {
        let steps = StillStage::ALL
            .iter()
            .map(|&stage| {
                let (command, args, files) = run_script(self.openjd_script(stage));
                let space = (stage == StillStage::Bands).then(|| {
                    crate::yaml::Node::Map(vec![(
                        "taskParameterDefinitions",
                        crate::yaml::Node::List(vec![param("Band", "INT", s("1-{{Param.Bands}}"))]),
                    )])
                });
                Step {
                    name: stage.step_name(),
                    space,
                    command,
                    args,
                    files,
                    after: (stage == StillStage::Merge).then(|| StillStage::Bands.step_name()),
                    resources: self.resources(stage),
                }
                .node()
            })
            .collect();
        job_template(
            &format!("mcctrace farm: still {}", self.out.display()),
            format!("mcctrace still {}", self.out.display()),
            "Written by `mcctrace farm openjd --bands`: the image's bands, one task each, then merged. Edit freely.",
            vec![int_param("Bands", self.bands, 1, "Horizontal bands of the image, one task each.")],
            steps,
        )
    }

    /// Writes the template into the job folder; returns its path.
    pub fn write_openjd(&self) -> Result<PathBuf> {
        let path = self.dir.join(crate::openjd::TEMPLATE_NAME);
        write_file(&path, &self.openjd_template(), false)?;
        Ok(path)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::process::Command;

    fn still(dir: &Path) -> Still {
        Still {
            mcctrace: PathBuf::from("/opt/mcc/bin/mcctrace"),
            workdir: dir.join("work dir"),
            dir: dir.join("big still"),
            command: [
                "render",
                "scene.gltf",
                "--camera",
                "wide",
                "--res",
                "3840x2160",
                "--out",
                "out/big.exr",
            ]
            .map(String::from)
            .into(),
            out: PathBuf::from("out/big.exr"),
            bands: 8,
            size: (3840, 2160),
            spp: 256,
            resources: Resources::default(),
        }
    }

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("mcctrace-farm-still-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// Bad values are refused naming the flag: no bands, a command that is not a render, a
    /// --tile of its own, a flag --tile refuses, an --out that is not one EXR.
    #[test]
    fn refuses_bad_stills_naming_the_flag() {
        let dir = Path::new("/tmp");
        let err = |f: &dyn Fn(&mut Still)| {
            let mut s = still(dir);
            f(&mut s);
            s.plan().unwrap_err().to_string()
        };
        assert!(err(&|s| s.bands = 0).starts_with("--bands: 0 bands"));
        assert!(err(&|s| s.command[0] = "animate".into()).starts_with("COMMAND: \"animate\""));
        assert!(err(&|s| s.command.clear()).starts_with("COMMAND: nothing"));
        assert!(err(&|s| s.command.extend(["--tile".into(), "1/4".into()])).starts_with("--tile: "));
        assert!(err(&|s| s.command.push("--tile=1/4".into())).starts_with("--tile: "));
        assert!(err(&|s| s.command.push("--lens-writer".into())).starts_with("--lens-writer: "));
        assert!(err(&|s| s.command.extend(["--layers".into(), "v.ora".into()])).starts_with("--layers: "));
        assert!(err(&|s| s.out = "out".into()).starts_with("--out: "));
        assert!(err(&|s| s.resources.cpus = Some(0)).starts_with("--cpus-per-task: "));
    }

    /// bash runs the band script as array tasks 1 and 8 and the merge script against a fake
    /// `mcctrace` that records its arguments and folder: each band gets its own --tile, all run
    /// in the work folder; submit.sh chains merge after bands.
    #[test]
    fn scripts_run_each_band_then_the_merge() {
        let dir = scratch("slurm");
        let record = dir.join("calls");
        let fake = dir.join("fake mcctrace");
        let body = format!(
            "#!/usr/bin/env bash\n{{ pwd; printf '%s\\n' \"$@\"; echo; }} >> {}\n",
            sh(&record.display().to_string())
        );
        std::fs::write(&fake, body).unwrap();
        use std::os::unix::fs::PermissionsExt;
        std::fs::set_permissions(&fake, std::fs::Permissions::from_mode(0o755)).unwrap();
        let mut s = still(&dir);
        s.mcctrace = fake;
        std::fs::create_dir_all(&s.workdir).unwrap();
        let plan = s.plan().unwrap();
        let scripts = plan.write_slurm().unwrap();
        assert_eq!(scripts.stages.iter().map(|(n, _)| *n).collect::<Vec<_>>(), ["bands", "merge"]);
        let bands = std::fs::read_to_string(&scripts.stages[0].1).unwrap();
        assert!(bands.contains("#SBATCH --array=1-8\n") && bands.contains("#SBATCH --cpus-per-task=4\n"));
        assert!(!bands.contains("--kill-on-invalid-dep"));
        let merge = std::fs::read_to_string(&scripts.stages[1].1).unwrap();
        assert!(!merge.contains("--array") && merge.contains("#SBATCH --kill-on-invalid-dep=yes\n"));
        for (script, task) in [
            (&scripts.stages[0].1, Some("1")),
            (&scripts.stages[0].1, Some("8")),
            (&scripts.stages[1].1, None),
        ] {
            let mut cmd = Command::new("bash");
            cmd.arg(script).env_remove("SLURM_ARRAY_TASK_ID").env("SLURM_CPUS_PER_TASK", "3");
            if let Some(t) = task {
                cmd.env("SLURM_ARRAY_TASK_ID", t);
            }
            let out = cmd.output().unwrap();
            assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        }
        let calls = std::fs::read_to_string(&record).unwrap();
        let work = plan.workdir.display().to_string();
        let calls: Vec<Vec<&str>> =
            calls.split("\n\n").filter(|c| !c.is_empty()).map(|c| c.lines().collect()).collect();
        let tail = ["--tile", "1/8", "--threads", "3"];
        assert_eq!(calls[0][0], work);
        assert_eq!(
            &calls[0][1..],
            [&plan.command[..].iter().map(String::as_str).collect::<Vec<_>>()[..], &tail].concat()
        );
        assert_eq!(&calls[1][calls[1].len() - 4..], ["--tile", "8/8", "--threads", "3"]);
        let out = plan.workdir.join("out/big.exr").display().to_string();
        assert_eq!(calls[2], [work.as_str(), "merge", "--out", out.as_str()]);
        let submit = std::fs::read_to_string(&scripts.submit).unwrap();
        assert!(submit.contains("bands=$(sbatch --parsable \"${after[@]}\" 1-bands.sbatch)"), "{submit}");
        assert!(submit.contains("after=(--dependency=afterok:$bands)\nmerge=$(sbatch"), "{submit}");
        // A command with its own --threads keeps it.
        let mut own = plan.clone();
        own.command.extend(["--threads".into(), "2".into()]);
        assert!(!own.slurm_script(StillStage::Bands).contains("SLURM_CPUS_PER_TASK"));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn template_has_the_band_space_and_the_merge_after_it() {
        let plan = still(Path::new("/tmp")).plan().unwrap();
        let t = plan.openjd_template();
        assert!(t.contains("range: \"1-{{Param.Bands}}\""), "{t}");
        let tile = t.find("--tile").unwrap();
        assert!(
            t[tile..]
                .trim_start_matches(['-', 't', 'i', 'l', 'e', ' ', '\\', '\n'])
                .starts_with("{{Task.Param.Band}}/{{Param.Bands}}"),
            "{t}"
        );
        let merge = &t[t.find("- name: \"Merge\"").unwrap()..];
        assert!(merge.contains("- dependsOn: \"Bands\""), "{merge}");
        assert!(t.contains("cd '/tmp/work dir'\n"), "{t}");
    }
}
