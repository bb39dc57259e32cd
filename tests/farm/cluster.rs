//! The Slurm cluster the farm test submits to: found through `MCCTRACE_SLURM_CONF`, or the
//! config `.ci/slurm.sh` writes (`/tmp/mcctrace-slurm/slurm.conf`); its commands run with
//! `SLURM_CONF` pointing there.

use crate::common::external::{external, under_ci};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, Instant};

/// How long a stage may take on the loaded 2-core machine before the test gives up.
const PATIENCE: Duration = Duration::from_secs(900);

/// A running one-node cluster.
pub struct Cluster {
    conf: PathBuf,
}

impl Cluster {
    /// The cluster, or `None` (with a note) on a machine without one; under CI a missing or
    /// silent cluster fails.
    pub fn find() -> Option<Self> {
        for tool in ["sbatch", "squeue", "scancel", "sinfo"] {
            external(tool)?;
        }
        let conf = std::env::var_os("MCCTRACE_SLURM_CONF")
            .map_or_else(|| PathBuf::from("/tmp/mcctrace-slurm/slurm.conf"), PathBuf::from);
        let cluster = Self { conf };
        let up = cluster.conf.is_file()
            && cluster.run("sinfo", &["--noheader", "--format=%a"]).is_some_and(|s| s.contains("up"));
        if up {
            return Some(cluster);
        }
        let why =
            format!("no Slurm cluster answers at {} (bash .ci/slurm.sh starts one)", cluster.conf.display());
        assert!(!under_ci(), "{why}");
        eprintln!("skipping: {why}");
        None
    }

    fn command(&self, program: impl AsRef<std::ffi::OsStr>) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", &self.conf);
        c
    }

    /// `program ARGS`' standard output, or `None` if it failed.
    fn run(&self, program: &str, args: &[&str]) -> Option<String> {
        let out = self.command(program).args(args).output().ok()?;
        out.status.success().then(|| String::from_utf8_lossy(&out.stdout).into_owned())
    }

    /// Runs `mcctrace farm slurm … --submit` (through `program`, the wrapper); returns the
    /// (stage, job id) pairs it printed.
    pub fn submit(&self, program: &Path, args: &[String]) -> Vec<(String, String)> {
        self.submit_in(Path::new("."), program, args)
    }

    /// [`Self::submit`] run in the folder `cwd`; `--submit` goes before any `--` in `args`.
    pub fn submit_in(&self, cwd: &Path, program: &Path, args: &[String]) -> Vec<(String, String)> {
        let at = args.iter().position(|a| a == "--").unwrap_or(args.len());
        let out = self
            .command(program)
            .current_dir(cwd)
            .args(&args[..at])
            .arg("--submit")
            .args(&args[at..])
            .output()
            .expect("run mcctrace farm slurm");
        let said = String::from_utf8_lossy(&out.stdout).into_owned();
        assert!(
            out.status.success(),
            "farm slurm --submit failed:\n{said}\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        said.lines()
            .filter_map(|l| l.split_once(": job "))
            .map(|(stage, id)| (stage.to_owned(), id.trim().to_owned()))
            .collect()
    }

    /// Runs `program ARGS` (the wrapper running `mcctrace`) against this cluster; its output.
    pub fn output(&self, program: &Path, args: &[String]) -> std::process::Output {
        self.command(program).args(args).output().expect("run mcctrace")
    }

    /// `scontrol show job ID`'s output (empty once Slurm has forgotten the job).
    pub fn show_job(&self, id: &str) -> String {
        self.run("scontrol", &["show", "job", id]).unwrap_or_default()
    }

    /// Cancels the jobs (a test that needed only their submission).
    pub fn cancel(&self, jobs: &[(String, String)]) {
        let ids: Vec<&str> = jobs.iter().map(|(_, id)| id.as_str()).collect();
        let out = self.command("scancel").args(&ids).output().expect("run scancel");
        assert!(out.status.success(), "scancel {ids:?}: {}", String::from_utf8_lossy(&out.stderr));
    }

    fn ids(jobs: &[(String, String)]) -> String {
        jobs.iter().map(|(_, id)| id.as_str()).collect::<Vec<_>>().join(",")
    }

    /// Lines `ID STATE` of the jobs' tasks (finished ones included).
    fn states(&self, jobs: &[(String, String)], all: bool) -> Vec<String> {
        let ids = Self::ids(jobs);
        let mut args = vec!["--noheader", "--jobs", &ids, "--format=%i %T"];
        if all {
            args.extend(["--states", "all"]);
        }
        self.run("squeue", &args).unwrap_or_default().lines().map(str::to_owned).collect()
    }

    #[track_caller]
    fn give_up(&self, what: &str, jobs: &[(String, String)], dir: &Path) -> ! {
        super::print_logs(dir);
        panic!("{what}; jobs: {:?}", self.states(jobs, true));
    }

    /// Waits until none of the jobs is pending or running.
    #[track_caller]
    pub fn wait(&self, jobs: &[(String, String)], dir: &Path) {
        let start = Instant::now();
        while !self.states(jobs, false).is_empty() {
            if start.elapsed() > PATIENCE {
                self.give_up(&format!("the jobs did not finish within {PATIENCE:?}"), jobs, dir);
            }
            std::thread::sleep(Duration::from_millis(200));
        }
    }

    /// Every task of the jobs completed.
    #[track_caller]
    pub fn assert_completed(&self, jobs: &[(String, String)], dir: &Path) {
        let states = self.states(jobs, true);
        if states.len() < jobs.len() || !states.iter().all(|s| s.ends_with(" COMPLETED")) {
            self.give_up("not every task completed", jobs, dir);
        }
    }

    /// Cancels `task` (`JOB_INDEX`) as soon as `ready` holds.
    #[track_caller]
    pub fn cancel_when(&self, task: &str, jobs: &[(String, String)], dir: &Path, ready: impl Fn() -> bool) {
        let start = Instant::now();
        while !ready() {
            if start.elapsed() > PATIENCE || self.states(jobs, false).is_empty() {
                self.give_up(&format!("never ready to cancel {task}"), jobs, dir);
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        let out = self.command("scancel").arg(task).output().expect("run scancel");
        assert!(out.status.success(), "scancel {task}: {}", String::from_utf8_lossy(&out.stderr));
    }
}
