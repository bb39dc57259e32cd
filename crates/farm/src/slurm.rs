//! The shot as Slurm batch scripts (docs/farm.md, "Schedulers"): one script per stage in
//! `DIR/slurm/`, the views and the frames as job arrays, each stage after the one before by
//! `--dependency=afterok`, and `submit.sh` to submit them in order. [`submit`] does what
//! `submit.sh` does and returns the job ids.
//!
//! Every script is plain bash a user can read and edit: `set -euo pipefail`, the values that
//! differ from task to task in arrays indexed by `SLURM_ARRAY_TASK_ID`, `--requeue` (a task
//! re-run from the start writes the same files: every output is written atomically and finished
//! frames are skipped), and a failed stage cancels the ones after it (`--kill-on-invalid-dep`).

use crate::quote::{sh, sh_words, wrap};
use crate::shot::{Plan, Stage, Word};
use crate::{FarmError, Result, write_file};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The scripts written for a shot.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scripts {
    /// The batch script of each stage, in order.
    pub stages: Vec<(Stage, PathBuf)>,
    /// The script that submits them in order.
    pub submit: PathBuf,
}

/// A submitted stage.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Submitted {
    /// The stage.
    pub stage: Stage,
    /// Its Slurm job id (an array's, for the views and frames).
    pub job_id: String,
}

/// The batch script of `stage`, the file name it is written under.
pub fn script_name(stage: Stage) -> String {
    let n = Stage::ALL.iter().position(|&s| s == stage).unwrap_or(0) + 1;
    format!("{n}-{}.sbatch", stage.name())
}

/// A job name: the shot folder's name (letters, digits, `-`, `_`) and the stage.
fn job_name(plan: &Plan, stage: Stage) -> String {
    let shot = plan.shot.dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let shot: String =
        shot.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect();
    if shot.is_empty() { format!("mcc-{}", stage.name()) } else { format!("mcc-{shot}-{}", stage.name()) }
}

/// A `#SBATCH` value: sbatch reads these lines itself and takes double quotes around a value.
fn directive_value(v: &str) -> String {
    if v.contains([' ', '\t']) { format!("\"{v}\"") } else { v.to_owned() }
}

/// The command as a bash line; per-task values come from the script's variables.
fn command_line(plan: &Plan, stage: Stage) -> String {
    let mut words = vec![r#""$MCCTRACE""#.to_owned()];
    for w in plan.command(stage) {
        words.push(match w {
            Word::Text(t) => sh(&t),
            Word::KeyFrame => r#""${frames[i]}""#.into(),
            Word::Camera => r#""${cameras[i]}""#.into(),
            Word::ViewId => r#""${ids[i]}""#.into(),
            Word::Frames => r#""$first..=$last""#.into(),
            Word::ShotFrames => sh(&plan.shot.frames.to_string()),
        });
    }
    // Slurm tells the task how many CPUs it has; without it, the renders take all of a shared
    // node's (`keys` has no such flag).
    if stage != Stage::Keys {
        words.push(r#"--threads "${SLURM_CPUS_PER_TASK:-1}""#.into());
    }
    wrap(&words)
}

/// The batch script of `stage`.
pub fn script(plan: &Plan, stage: Stage) -> String {
    let s = &plan.shot;
    let r = plan.resources(stage);
    let tasks = plan.tasks(stage);
    let what = match stage {
        Stage::Views => "the source views of every key frame, one array task per key frame and camera",
        Stage::Keys => {
            "`keys`: every key's collage remapped against its views, every frame's rays in-betweened"
        }
        Stage::Frames => {
            "the output frames, one array task per chunk of frames (finished frames are skipped)"
        }
        Stage::Check => "every frame checked over the whole shot, and the preview",
    };
    let mut t = String::new();
    let _ = writeln!(t, "#!/usr/bin/env bash");
    let _ = writeln!(t, "# mcctrace farm, shot {}: {what}.", s.dir.display());
    let _ = writeln!(
        t,
        "# Written by `mcctrace farm slurm`; edit freely. submit.sh submits the stages in order."
    );
    let _ = writeln!(t, "#SBATCH --job-name={}", job_name(plan, stage));
    if matches!(stage, Stage::Views | Stage::Frames) {
        let _ = writeln!(t, "#SBATCH --array=0-{}", tasks.saturating_sub(1));
    }
    let _ = writeln!(t, "#SBATCH --cpus-per-task={}", r.cpus);
    let _ = writeln!(t, "#SBATCH --mem={}M", r.mem_mib);
    let _ = writeln!(t, "#SBATCH --time={}", r.time_minutes);
    if let Some(p) = &s.resources.partition {
        let _ = writeln!(t, "#SBATCH --partition={p}");
    }
    let log = plan.path("logs").join(if tasks > 1 || stage == Stage::Frames || stage == Stage::Views {
        "%x-%A_%a.out"
    } else {
        "%x-%j.out"
    });
    let _ = writeln!(t, "#SBATCH --output={}", directive_value(&log.display().to_string()));
    let _ = writeln!(t, "#SBATCH --requeue");
    if stage != Stage::Views {
        let _ = writeln!(t, "#SBATCH --kill-on-invalid-dep=yes");
    }
    let _ = writeln!(t, "set -euo pipefail\n");
    let _ = writeln!(t, "MCCTRACE={}", sh(&s.mcctrace.display().to_string()));
    match stage {
        Stage::Views => {
            let col = |f: &dyn Fn(&crate::ViewTask) -> String| {
                plan.views.iter().map(|v| sh(&f(v))).collect::<Vec<_>>().join(" ")
            };
            let _ = writeln!(
                t,
                "# Task i renders camera cameras[i] of key frame frames[i] as view number ids[i]."
            );
            let _ = writeln!(t, "frames=({})", col(&|v| v.frame.to_string()));
            let _ = writeln!(t, "cameras=({})", col(&|v| v.camera.clone()));
            let _ = writeln!(t, "ids=({})", col(&|v| v.id.to_string()));
            let _ = writeln!(
                t,
                "i=${{SLURM_ARRAY_TASK_ID:?run this as an array task: sbatch --array=0-{}}}",
                tasks - 1
            );
        }
        Stage::Frames => {
            let _ = writeln!(t, "# Task i renders CHUNK frames from FIRST + i * CHUNK, up to LAST.");
            let _ = writeln!(t, "FIRST={} LAST={} CHUNK={}", s.frames.first, s.frames.last, s.chunk);
            let _ = writeln!(
                t,
                "i=${{SLURM_ARRAY_TASK_ID:?run this as an array task: sbatch --array=0-{}}}",
                tasks - 1
            );
            let _ = writeln!(t, "first=$((FIRST + i * CHUNK))");
            let _ = writeln!(t, "last=$((first + CHUNK - 1))");
            let _ = writeln!(t, "if ((last > LAST)); then last=$LAST; fi");
        }
        Stage::Keys | Stage::Check => {}
    }
    let _ = writeln!(t, "\n{}", command_line(plan, stage));
    t
}

/// `submit.sh`: submits the stages in order, each after the one before, and prints their ids.
pub fn submit_script(plan: &Plan) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "#!/usr/bin/env bash");
    let _ =
        writeln!(t, "# Submits the shot's stages in order, each after the one before succeeded (afterok).");
    let _ =
        writeln!(t, "# Written by `mcctrace farm slurm`. Re-run it to resume: finished frames are skipped.");
    let _ = writeln!(t, "set -euo pipefail");
    let _ = writeln!(t, "cd {}", sh(&plan.path("slurm").display().to_string()));
    let _ = writeln!(t, "after=()");
    for stage in Stage::ALL {
        let name = stage.name();
        let _ = writeln!(t, "{name}=$(sbatch --parsable \"${{after[@]}}\" {})", script_name(stage));
        let _ = writeln!(t, "{name}=${{{name}%%;*}}");
        let _ = writeln!(t, "echo \"{name}: job ${name}\"");
        if stage != Stage::Check {
            let _ = writeln!(t, "after=(--dependency=afterok:${name})");
        }
    }
    t
}

/// Writes the stage scripts and `submit.sh` into `DIR/slurm/` (and makes `DIR/logs/`, where the
/// tasks' output goes: Slurm does not create it).
pub fn write(plan: &Plan) -> Result<Scripts> {
    let dir = plan.path("slurm");
    let logs = plan.path("logs");
    std::fs::create_dir_all(&logs)
        .map_err(|e| FarmError::Write { path: logs.clone(), message: e.to_string() })?;
    let mut stages = Vec::new();
    for stage in Stage::ALL {
        let path = dir.join(script_name(stage));
        write_file(&path, &script(plan, stage), true)?;
        stages.push((stage, path));
    }
    let submit = dir.join("submit.sh");
    write_file(&submit, &submit_script(plan), true)?;
    Ok(Scripts { stages, submit })
}

/// Submits the scripts with `sbatch` (`sbatch` on PATH, or the program given), each stage after
/// the one before; returns the job ids in stage order.
pub fn submit(scripts: &Scripts, sbatch: Option<&Path>) -> Result<Vec<Submitted>> {
    let sbatch = sbatch.unwrap_or(Path::new("sbatch"));
    let mut done: Vec<Submitted> = Vec::new();
    for (stage, script) in &scripts.stages {
        let fail = |message: String| FarmError::Submit { script: script.clone(), message };
        let mut cmd = Command::new(sbatch);
        cmd.arg("--parsable");
        if let Some(before) = done.last() {
            cmd.arg(format!("--dependency=afterok:{}", before.job_id));
        }
        if let Some(dir) = script.parent() {
            cmd.current_dir(dir);
        }
        let out =
            cmd.arg(script).output().map_err(|e| fail(format!("cannot run {}: {e}", sbatch.display())))?;
        let stdout = String::from_utf8_lossy(&out.stdout);
        if !out.status.success() {
            let said = String::from_utf8_lossy(&out.stderr);
            let earlier = done.iter().map(|s| format!("{} {}", s.stage.name(), s.job_id)).collect::<Vec<_>>();
            return Err(fail(format!(
                "sbatch exited with {}: {}{}",
                out.status,
                said.trim(),
                if earlier.is_empty() {
                    String::new()
                } else {
                    format!(" (already submitted: {})", earlier.join(", "))
                }
            )));
        }
        // --parsable prints `ID` or `ID;CLUSTER`.
        let id = stdout.trim().split(';').next().unwrap_or_default().to_owned();
        if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
            return Err(fail(format!("sbatch printed {:?}, not a job id", stdout.trim())));
        }
        done.push(Submitted { stage: *stage, job_id: id });
    }
    Ok(done)
}

/// The same, as the words a user types (for messages).
pub fn submit_hint(scripts: &Scripts) -> String {
    sh_words(&[scripts.submit.display().to_string()])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shot::tests::Fixture;
    use std::os::unix::fs::PermissionsExt;

    /// An executable shell script at `path`.
    fn program(path: &Path, body: &str) {
        std::fs::write(path, format!("#!/usr/bin/env bash\n{body}")).unwrap();
        std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
    }

    /// Runs a generated script with bash as array task `task` (if any); returns the argument
    /// lists its fake `mcctrace` was called with.
    fn run(script: &Path, task: Option<usize>, record: &Path) -> Vec<Vec<String>> {
        let _ = std::fs::remove_file(record);
        let mut cmd = Command::new("bash");
        cmd.arg(script).env_remove("SLURM_ARRAY_TASK_ID").env("SLURM_CPUS_PER_TASK", "3");
        if let Some(t) = task {
            cmd.env("SLURM_ARRAY_TASK_ID", t.to_string());
        }
        let out = cmd.output().unwrap();
        assert!(out.status.success(), "{}: {}", script.display(), String::from_utf8_lossy(&out.stderr));
        let text = std::fs::read_to_string(record).unwrap();
        text.split('\x1e')
            .filter(|c| !c.is_empty())
            .map(|c| c.split('\x1f').filter(|w| !w.is_empty()).map(str::to_owned).collect())
            .collect()
    }

    fn flag<'a>(args: &'a [String], name: &str) -> &'a str {
        let at = args.iter().position(|a| a == name).unwrap_or_else(|| panic!("{name} in {args:?}"));
        &args[at + 1]
    }

    /// bash itself runs every script against a fake `mcctrace` that records its arguments: each
    /// task gets its camera, view number and frames, paths with spaces stay one argument.
    #[test]
    fn scripts_run_each_task_with_its_own_values() {
        let mut f = Fixture::new("slurm-run");
        let record = f.dir.join("calls");
        let fake = f.dir.join("fake mcctrace");
        program(
            &fake,
            &format!(
                "printf '%s\\x1f' \"$@\" >> {}\nprintf '\\x1e' >> {0}\n",
                crate::quote::sh(&record.display().to_string())
            ),
        );
        f.shot.mcctrace = fake;
        let plan = f.shot.plan().unwrap();
        let scripts = write(&plan).unwrap();
        assert!(plan.path("logs").is_dir(), "Slurm does not create the log folder");
        let script = |stage| scripts.stages.iter().find(|(s, _)| *s == stage).unwrap().1.clone();
        let mut views = Vec::new();
        for task in 0..4 {
            let calls = run(&script(Stage::Views), Some(task), &record);
            assert_eq!(calls.len(), 1);
            let a = &calls[0];
            assert_eq!(
                (a[0].as_str(), a[1].as_str()),
                ("render", f.dir.join("scene.gltf").to_str().unwrap())
            );
            assert_eq!(flag(a, "--threads"), "3");
            assert_eq!(flag(a, "--out"), plan.path("views").to_str().unwrap());
            views.push((
                flag(a, "--frame").to_owned(),
                flag(a, "--camera").to_owned(),
                flag(a, "--first-id").to_owned(),
            ));
        }
        let expect =
            [("0", "left", "1"), ("0", "right", "2"), ("11", "wide", "1"), ("11", "by the window", "2")];
        assert_eq!(views, expect.map(|(a, b, c)| (a.to_owned(), b.to_owned(), c.to_owned())));
        let keys = &run(&script(Stage::Keys), None, &record)[0];
        assert!(!keys.contains(&"--threads".to_owned()), "keys takes no --threads: {keys:?}");
        assert_eq!(
            flag(keys, "--key"),
            format!("0={},{}", f.dir.join("collage0.png").display(), f.dir.join("regions0.png").display())
        );
        assert_eq!(flag(keys, "--frames"), "0..=11");
        let chunks: Vec<String> = (0..3)
            .map(|t| flag(&run(&script(Stage::Frames), Some(t), &record)[0], "--frames").to_owned())
            .collect();
        assert_eq!(chunks, ["0..=4", "5..=9", "10..=11"]);
        let check = &run(&script(Stage::Check), None, &record)[0];
        assert_eq!(flag(check, "--frames"), "0..=11");
        // An array script run outside an array says how to run it, and runs nothing.
        let out = Command::new("bash")
            .arg(script(Stage::Frames))
            .env_remove("SLURM_ARRAY_TASK_ID")
            .output()
            .unwrap();
        assert!(!out.status.success());
        assert!(String::from_utf8_lossy(&out.stderr).contains("run this as an array task"));
    }

    #[test]
    fn scripts_ask_for_the_resources_arrays_and_requeue() {
        let mut f = Fixture::new("slurm-directives");
        f.shot.resources.partition = Some("render".into());
        f.shot.resources.mem_mib = Some(2048);
        let plan = f.shot.plan().unwrap();
        let views = script(&plan, Stage::Views);
        let frames = script(&plan, Stage::Frames);
        assert!(views.contains("#SBATCH --array=0-3\n") && frames.contains("#SBATCH --array=0-2\n"));
        assert!(!script(&plan, Stage::Keys).contains("--array"));
        for stage in Stage::ALL {
            let t = script(&plan, stage);
            assert!(t.contains("set -euo pipefail"), "{t}");
            assert!(t.contains("#SBATCH --requeue\n") && t.contains("#SBATCH --partition=render\n"));
            assert!(t.contains("#SBATCH --mem=2048M\n") && t.contains("#SBATCH --cpus-per-task=1\n"));
            // The shot folder has a space: sbatch takes the log path in double quotes.
            assert!(t.contains(&format!("#SBATCH --output=\"{}/logs/", plan.shot.dir.display())), "{t}");
            assert_eq!(t.contains("--kill-on-invalid-dep=yes"), stage != Stage::Views);
        }
    }

    /// `submit` chains the stages by afterok on the ids sbatch printed (`ID;CLUSTER` too).
    #[test]
    fn submission_chains_the_stages() {
        let f = Fixture::new("slurm-submit");
        let plan = f.shot.plan().unwrap();
        let scripts = write(&plan).unwrap();
        let log = f.dir.join("sbatch.log");
        let sbatch = f.dir.join("sbatch");
        let log_q = crate::quote::sh(&log.display().to_string());
        program(
            &sbatch,
            &format!("echo \"$*\" >> {log_q}\nn=$(wc -l < {log_q})\necho \"$((40 + n));cluster\"\n"),
        );
        let done = submit(&scripts, Some(&sbatch)).unwrap();
        let ids: Vec<(Stage, &str)> = done.iter().map(|s| (s.stage, s.job_id.as_str())).collect();
        assert_eq!(
            ids,
            [(Stage::Views, "41"), (Stage::Keys, "42"), (Stage::Frames, "43"), (Stage::Check, "44")]
        );
        let calls = std::fs::read_to_string(&log).unwrap();
        let calls: Vec<&str> = calls.lines().collect();
        assert!(calls[0].starts_with("--parsable ") && !calls[0].contains("--dependency"));
        for (n, line) in calls.iter().enumerate().skip(1) {
            assert!(line.starts_with(&format!("--parsable --dependency=afterok:{} ", 40 + n)), "{line}");
        }
        assert!(calls[2].ends_with("3-frames.sbatch"));
        // A refusal names the script and what sbatch said, and the stages already submitted.
        program(
            &sbatch,
            &format!(
                "if [[ $* == *frames* ]]; then echo 'invalid partition' >&2; exit 1; fi\necho 7 >> {log_q}; echo 7\n"
            ),
        );
        let err = submit(&scripts, Some(&sbatch)).unwrap_err().to_string();
        assert!(err.contains("3-frames.sbatch") && err.contains("invalid partition"), "{err}");
        assert!(err.contains("already submitted: views 7, keys 7"), "{err}");
        program(&sbatch, "echo 'Submitted batch job 5'\n");
        assert!(submit(&scripts, Some(&sbatch)).unwrap_err().to_string().contains("not a job id"));
    }

    /// submit.sh, run by bash against the same fake sbatch, chains the stages the same way.
    #[test]
    fn submit_script_chains_the_stages() {
        let f = Fixture::new("slurm-submit-sh");
        let plan = f.shot.plan().unwrap();
        let scripts = write(&plan).unwrap();
        let bin = f.dir.join("bin");
        std::fs::create_dir_all(&bin).unwrap();
        let log = f.dir.join("sbatch.log");
        let log_q = crate::quote::sh(&log.display().to_string());
        program(
            &bin.join("sbatch"),
            &format!("echo \"$*\" >> {log_q}\nn=$(wc -l < {log_q})\necho \"$((10 + n))\"\n"),
        );
        let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
        let out = Command::new("bash").arg(&scripts.submit).env("PATH", path).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        assert_eq!(
            String::from_utf8_lossy(&out.stdout),
            "views: job 11\nkeys: job 12\nframes: job 13\ncheck: job 14\n"
        );
        let calls = std::fs::read_to_string(&log).unwrap();
        assert_eq!(calls.lines().nth(3), Some("--parsable --dependency=afterok:13 4-check.sbatch"));
    }
}
