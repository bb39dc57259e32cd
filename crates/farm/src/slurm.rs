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
use crate::shot::{NodeSize, Plan, Stage, StageResources, Word};
use crate::{FarmError, Result, bad, write_file};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The scripts written for a shot (or a still).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Scripts {
    /// Each stage's name and batch script, in order.
    pub stages: Vec<(&'static str, PathBuf)>,
    /// The script that submits them in order.
    pub submit: PathBuf,
}

/// A submitted stage.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Submitted {
    /// The stage's name.
    pub stage: &'static str,
    /// Its Slurm job id (an array's, for the views and frames).
    pub job_id: String,
}

/// The batch script of `stage`, the file name it is written under.
pub fn script_name(stage: Stage) -> String {
    let n = Stage::ALL.iter().position(|&s| s == stage).unwrap_or(0) + 1;
    numbered_script(n, stage.name())
}

/// The batch script of the `n`-th stage (1-based), `name`.
pub(crate) fn numbered_script(n: usize, name: &str) -> String {
    format!("{n}-{name}.sbatch")
}

/// A job name: the job folder's name (letters, digits, `-`, `_`) and the stage.
fn job_name(dir: &Path, stage: &str) -> String {
    let shot = dir.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let shot: String =
        shot.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '_' }).collect();
    if shot.is_empty() { format!("mcc-{stage}") } else { format!("mcc-{shot}-{stage}") }
}

/// A `#SBATCH` value: sbatch reads these lines itself and takes double quotes around a value.
fn directive_value(v: &str) -> String {
    if v.contains([' ', '\t']) { format!("\"{v}\"") } else { v.to_owned() }
}

/// `command` as a bash line running `$MCCTRACE`; per-task values come from the script's
/// variables (the shot's frames are `shot_frames`); with `threads`, the render takes the CPUs
/// Slurm gave the task.
pub(crate) fn command_line(command: Vec<Word>, shot_frames: &str, threads: bool) -> String {
    let mut words = vec![r#""$MCCTRACE""#.to_owned()];
    for w in command {
        words.push(match w {
            Word::Text(t) => sh(&t),
            Word::KeyFrame => r#""${frames[i]}""#.into(),
            Word::Camera => r#""${cameras[i]}""#.into(),
            Word::ViewId => r#""${ids[i]}""#.into(),
            Word::Frames => r#""$first..=$last""#.into(),
            Word::ShotFrames => sh(shot_frames),
            Word::Tile(n) => format!(r#""$i/{n}""#),
        });
    }
    // Slurm tells the task how many CPUs it has; without it, the renders take all of a shared
    // node's.
    if threads {
        words.push(r#"--threads "${SLURM_CPUS_PER_TASK:-1}""#.into());
    }
    wrap(&words)
}

/// The first lines of a stage's batch script: what it does, its `#SBATCH` directives, strict
/// bash and the program every task runs.
pub(crate) struct Header<'a> {
    /// What is farmed: `shot` or `still`.
    pub kind: &'a str,
    /// The job folder (its name names the jobs; logs go to its `logs/`).
    pub dir: &'a Path,
    /// The stage's name.
    pub stage: &'a str,
    /// What the stage does, for the comment.
    pub what: &'a str,
    /// The array's task ids (`0-3`, `1-8`), if the stage is an array.
    pub array: Option<String>,
    /// What each task asks for.
    pub resources: StageResources,
    /// The partition, if any.
    pub partition: Option<&'a str>,
    /// Whether a stage runs before this one (a failure there cancels this one).
    pub after: bool,
    /// The `mcctrace` program.
    pub mcctrace: &'a Path,
}

impl Header<'_> {
    pub(crate) fn write(&self, t: &mut String) {
        let r = &self.resources;
        let _ = writeln!(t, "#!/usr/bin/env bash");
        let _ = writeln!(t, "# mcctrace farm, {} {}: {}.", self.kind, self.dir.display(), self.what);
        let _ = writeln!(
            t,
            "# Written by `mcctrace farm slurm`; edit freely. submit.sh submits the stages in order."
        );
        let _ = writeln!(t, "# Resources: {}.", r.note());
        let _ = writeln!(t, "#SBATCH --job-name={}", job_name(self.dir, self.stage));
        if let Some(array) = &self.array {
            let _ = writeln!(t, "#SBATCH --array={array}");
        }
        let _ = writeln!(t, "#SBATCH --cpus-per-task={}", r.cpus);
        let _ = writeln!(t, "#SBATCH --mem={}M", r.mem_mib);
        let _ = writeln!(t, "#SBATCH --time={}", r.time_minutes);
        if let Some(p) = self.partition {
            let _ = writeln!(t, "#SBATCH --partition={p}");
        }
        let log = self.dir.join("logs").join(if self.array.is_some() { "%x-%A_%a.out" } else { "%x-%j.out" });
        let _ = writeln!(t, "#SBATCH --output={}", directive_value(&log.display().to_string()));
        let _ = writeln!(t, "#SBATCH --requeue");
        if self.after {
            let _ = writeln!(t, "#SBATCH --kill-on-invalid-dep=yes");
        }
        let _ = writeln!(t, "set -euo pipefail\n");
        let _ = writeln!(t, "MCCTRACE={}", sh(&self.mcctrace.display().to_string()));
    }
}

/// The line that takes array task `i`'s id (refusing to run outside an array of `ids`).
pub(crate) fn array_task(ids: &str) -> String {
    format!("i=${{SLURM_ARRAY_TASK_ID:?run this as an array task: sbatch --array={ids}}}")
}

/// The batch script of `stage`.
pub fn script(plan: &Plan, stage: Stage) -> String {
    let s = &plan.shot;
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
    let array =
        matches!(stage, Stage::Views | Stage::Frames).then(|| format!("0-{}", tasks.saturating_sub(1)));
    let mut t = String::new();
    Header {
        kind: "shot",
        dir: &s.dir,
        stage: stage.name(),
        what,
        array: array.clone(),
        resources: plan.resources(stage),
        partition: s.resources.partition.as_deref(),
        after: stage != Stage::Views,
        mcctrace: &s.mcctrace,
    }
    .write(&mut t);
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
            let _ = writeln!(t, "{}", array_task(array.as_deref().unwrap_or_default()));
        }
        Stage::Frames => {
            let _ = writeln!(t, "# Task i renders CHUNK frames from FIRST + i * CHUNK, up to LAST.");
            let _ = writeln!(t, "FIRST={} LAST={} CHUNK={}", s.frames.first, s.frames.last, s.chunk);
            let _ = writeln!(t, "{}", array_task(array.as_deref().unwrap_or_default()));
            let _ = writeln!(t, "first=$((FIRST + i * CHUNK))");
            let _ = writeln!(t, "last=$((first + CHUNK - 1))");
            let _ = writeln!(t, "if ((last > LAST)); then last=$LAST; fi");
        }
        Stage::Keys | Stage::Check => {}
    }
    // `keys` has no --threads flag.
    let command = command_line(plan.command(stage), &s.frames.to_string(), stage != Stage::Keys);
    let _ = writeln!(t, "\n{command}");
    t
}

/// `submit.sh`: submits the stages in order, each after the one before, and prints their ids.
pub fn submit_script(plan: &Plan) -> String {
    let stages: Vec<(&str, String)> = Stage::ALL.iter().map(|&s| (s.name(), script_name(s))).collect();
    chain_script(&plan.path("slurm"), &stages, "Re-run it to resume: finished frames are skipped.")
}

/// A `submit.sh` submitting `stages` (name, script file in `dir`) in order, each after the one
/// before succeeded; `resume` says what re-running it does.
pub(crate) fn chain_script(dir: &Path, stages: &[(&str, String)], resume: &str) -> String {
    let mut t = String::new();
    let _ = writeln!(t, "#!/usr/bin/env bash");
    let _ =
        writeln!(t, "# Submits the shot's stages in order, each after the one before succeeded (afterok).");
    let _ = writeln!(t, "# Written by `mcctrace farm slurm`. {resume}");
    let _ = writeln!(t, "set -euo pipefail");
    let _ = writeln!(t, "cd {}", sh(&dir.display().to_string()));
    let _ = writeln!(t, "after=()");
    for (n, (name, script)) in stages.iter().enumerate() {
        let _ = writeln!(t, "{name}=$(sbatch --parsable \"${{after[@]}}\" {script})");
        let _ = writeln!(t, "{name}=${{{name}%%;*}}");
        let _ = writeln!(t, "echo \"{name}: job ${name}\"");
        if n + 1 < stages.len() {
            let _ = writeln!(t, "after=(--dependency=afterok:${name})");
        }
    }
    let logs = dir.parent().unwrap_or(dir).join("logs");
    let _ = writeln!(t, "logs={}", sh(&logs.display().to_string()));
    let ids: Vec<String> = stages.iter().map(|(name, _)| format!("${name}")).collect();
    for line in follow_up("$logs", &ids.join(",")).lines() {
        let _ = writeln!(t, "echo \"{line}\"");
    }
    t
}

/// How to see what happened to submitted jobs `ids` (comma-separated) whose logs go to `logs`:
/// printed by `submit.sh` and `farm slurm --submit` (no `"`, `$` or backquote but in the
/// arguments: `submit.sh` echoes it in double quotes).
pub fn follow_up(logs: &str, ids: &str) -> String {
    format!(
        "logs: {logs}/ (one file per task, named after its job: JOBNAME-JOBID_TASK.out or JOBNAME-JOBID.out)\n\
         A stage that fails cancels the stages after it: they never start, leave squeue and write no log.\n\
         What happened to each job, and why it waits or ended: scontrol show job JOBID (for MinJobAge, \
         300 s by default, after it ends)\n\
         All their tasks: squeue --states=all --jobs={ids}"
    )
}

/// Writes the stage scripts and `submit.sh` into `DIR/slurm/` (and makes `DIR/logs/`, where the
/// tasks' output goes: Slurm does not create it).
pub fn write(plan: &Plan) -> Result<Scripts> {
    let stages: Vec<_> = Stage::ALL.iter().map(|&s| (s.name(), script_name(s), script(plan, s))).collect();
    write_scripts(&plan.shot.dir, &stages, &submit_script(plan))
}

/// Writes `stages` (name, file name, text) and `submit` into `dir/slurm/`, and makes `dir/logs/`
/// (Slurm does not create it).
pub(crate) fn write_scripts(
    dir: &Path,
    stages: &[(&'static str, String, String)],
    submit: &str,
) -> Result<Scripts> {
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs)
        .map_err(|e| FarmError::Write { path: logs.clone(), message: e.to_string() })?;
    let dir = dir.join("slurm");
    let mut written = Vec::new();
    for (name, file, text) in stages {
        let path = dir.join(file);
        write_file(&path, text, true)?;
        written.push((*name, path));
    }
    let path = dir.join("submit.sh");
    write_file(&path, submit, true)?;
    Ok(Scripts { stages: written, submit: path })
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
            output(cmd.arg(script)).map_err(|e| fail(format!("cannot run {}: {e}", sbatch.display())))?;
        let stdout = String::from_utf8_lossy(&out.stdout);
        if !out.status.success() {
            let said = String::from_utf8_lossy(&out.stderr);
            let earlier = done.iter().map(|s| format!("{} {}", s.stage, s.job_id)).collect::<Vec<_>>();
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
        done.push(Submitted { stage, job_id: id });
    }
    Ok(done)
}

/// `cmd`'s output, retried while the program is "text file busy" (ETXTBSY): a program written
/// just before it runs (a wrapper script, a test's stand-in) stays busy for as long as any
/// process forked meanwhile by another thread still holds its write descriptor, until that
/// child's exec closes it; Cargo retries its build scripts the same way.
fn output(cmd: &mut Command) -> std::io::Result<std::process::Output> {
    const ETXTBSY: i32 = 26;
    let mut tries = 0;
    loop {
        match cmd.output() {
            Err(e) if e.raw_os_error() == Some(ETXTBSY) && tries < 50 => {
                tries += 1;
                std::thread::sleep(std::time::Duration::from_millis(10));
            }
            result => return result,
        }
    }
}

/// The largest node of the cluster (or of `partition`) as `sinfo` (on PATH, or the program
/// given) lists its nodes: the most CPUs and the most memory any node has.
pub fn largest_node(partition: Option<&str>, sinfo: Option<&Path>) -> Result<NodeSize> {
    let sinfo = sinfo.unwrap_or(Path::new("sinfo"));
    let fail = |message: String| {
        bad("--submit", format!("reading the cluster's nodes with {}: {message}", sinfo.display()))
    };
    let mut cmd = Command::new(sinfo);
    cmd.args(["--noheader", "--Node", "--format=%c %m"]);
    if let Some(p) = partition {
        cmd.arg(format!("--partition={p}"));
    }
    let out = output(&mut cmd).map_err(|e| fail(format!("cannot run it: {e}")))?;
    if !out.status.success() {
        return Err(fail(format!(
            "it exited with {}: {}",
            out.status,
            String::from_utf8_lossy(&out.stderr).trim()
        )));
    }
    let mut most: Option<NodeSize> = None;
    for line in String::from_utf8_lossy(&out.stdout).lines().filter(|l| !l.trim().is_empty()) {
        let mut words = line.split_whitespace().map(|w| w.trim_end_matches('+').parse::<u64>());
        let (Some(Ok(cpus)), Some(Ok(mem))) = (words.next(), words.next()) else {
            return Err(fail(format!("{line:?} is not `CPUS MEMORY`")));
        };
        let cpus = u32::try_from(cpus).unwrap_or(u32::MAX);
        let m = most.get_or_insert(NodeSize { cpus, mem_mib: mem });
        *m = NodeSize { cpus: m.cpus.max(cpus), mem_mib: m.mem_mib.max(mem) };
    }
    most.ok_or_else(|| {
        fail(match partition {
            Some(p) => format!("partition {p} has no node"),
            None => "the cluster has no node".to_owned(),
        })
    })
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
        let script =
            |stage: Stage| scripts.stages.iter().find(|(s, _)| *s == stage.name()).unwrap().1.clone();
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
        let ids: Vec<(&str, &str)> = done.iter().map(|s| (s.stage, s.job_id.as_str())).collect();
        assert_eq!(ids, [("views", "41"), ("keys", "42"), ("frames", "43"), ("check", "44")]);
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
        let said = String::from_utf8_lossy(&out.stdout);
        assert!(said.starts_with("views: job 11\nkeys: job 12\nframes: job 13\ncheck: job 14\n"), "{said}");
        // And how to see what happened, with the real ids and the log folder (issue 41, item 7).
        assert!(said.contains(&format!("logs: {}/ ", plan.path("logs").display())), "{said}");
        assert!(said.contains("scontrol show job JOBID") && said.contains("--jobs=11,12,13,14\n"), "{said}");
        let calls = std::fs::read_to_string(&log).unwrap();
        assert_eq!(calls.lines().nth(3), Some("--parsable --dependency=afterok:13 4-check.sbatch"));
    }
}
