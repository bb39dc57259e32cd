//! `mcctrace` run in a child process, to see what it prints: the child is this test binary
//! again, on the ignored test [`cli_child`], which hands its arguments to
//! `mcctrace_cli::main_with_args` (the whole of the binary's `main`) and exits with its status.
//! No prebuilt binary is needed, and what the run prints on stdout and stderr comes back whole.

use std::process::{Command, Stdio};

/// The environment variable carrying the child's arguments, separated by U+001F.
const ARGS_VAR: &str = "MCCTRACE_CLI_CHILD_ARGS";

/// The `mcctrace` run of [`run`], in its own process; ignored in a normal test run.
#[test]
#[ignore = "runs one `mcctrace` command line inside the child process `common::child::run` starts"]
fn cli_child() {
    let Ok(args) = std::env::var(ARGS_VAR) else { return };
    let code = mcctrace_cli::main_with_args(std::iter::once("mcctrace").chain(args.split('\u{1f}')));
    let ok = format!("{code:?}") == format!("{:?}", std::process::ExitCode::SUCCESS);
    // Exit here, before the test harness prints its own result lines.
    std::process::exit(if ok { 0 } else { 1 });
}

/// What a child run of `mcctrace` did.
#[derive(Debug)]
pub struct Run {
    /// True when it exited successfully.
    pub ok: bool,
    /// What it printed on stdout (after the test harness's own `running 1 test` line).
    pub stdout: String,
    /// What it printed on stderr: its warnings and errors.
    pub stderr: String,
}

/// Runs `mcctrace ARGS…` in a child process and returns what it printed.
pub fn run(args: &[&str]) -> Run {
    let exe = std::env::current_exe().expect("the test binary's path");
    let out = Command::new(exe)
        .args(["--ignored", "--exact", "common::child::cli_child", "--nocapture", "--test-threads=1"])
        .env(ARGS_VAR, args.join("\u{1f}"))
        .env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .output()
        .expect("start the child process");
    Run {
        ok: out.status.success(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}
