//! Outside programs the end-to-end tests drive for real (a scheduler, a browser, a job runner):
//! found on PATH or in the checkout's `.venv/bin`. On a developer's machine a missing program
//! skips its test with a note; under CI (`MCCTRACE_CI=1`, set by `.ci/run`, which installs them)
//! a missing program fails the test, so a forgotten install step cannot hide as a skip.

use std::path::PathBuf;

/// Whether the tests run under CI, where every outside program must be present.
pub fn under_ci() -> bool {
    std::env::var_os("MCCTRACE_CI").is_some_and(|v| v == "1")
}

/// The path of `program` (on PATH or in `.venv/bin`), or `None` after printing why the calling
/// test skips. Panics under CI, where `.ci/run` must have installed it.
pub fn external(program: &str) -> Option<PathBuf> {
    let venv = super::repo_root().join(".venv/bin");
    let path = std::env::var_os("PATH").unwrap_or_default();
    let found = std::iter::once(venv)
        .chain(std::env::split_paths(&path))
        .map(|dir| dir.join(program))
        .find(|candidate| candidate.is_file());
    match found {
        Some(p) => Some(p),
        None if under_ci() => {
            panic!("`{program}` is not installed, but MCCTRACE_CI=1 requires it (.ci/run installs it)")
        }
        None => {
            eprintln!(
                "skipping: `{program}` is not installed (.ci/run installs it; MCCTRACE_CI=1 makes its absence a failure)"
            );
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_program_every_machine_has() {
        assert!(external("sh").is_some_and(|p| p.ends_with("sh")));
    }

    #[test]
    fn a_missing_program_is_none_outside_ci() {
        if !under_ci() {
            assert!(external("mcctrace-no-such-program").is_none());
        }
    }
}
