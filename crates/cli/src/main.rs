//! The `mcctrace` binary: everything lives in the `mcctrace_cli` library so tests can drive it.

fn main() -> std::process::ExitCode {
    mcctrace_cli::main_with_args(std::env::args_os())
}
