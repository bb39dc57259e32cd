//! The `mcctrace` command line (docs/design/workflow.md §8): parses arguments, builds the libraries' jobs
//! (`tracer::job`, `mcc::job`), runs them and reports progress, results and errors. Nothing here
//! renders or remaps by itself.

mod animate;
mod args;
mod collage;
mod demo;
mod farm;
mod inbetween;
mod info;
mod keys;
mod merge;
mod preview;
mod progress;
mod remap;
mod render;
mod rerender;
mod setup;
mod studio;
mod tag;

use clap::{Parser, Subcommand};
use std::ffi::OsString;
use std::process::ExitCode;

/// mcctrace: a CPU path tracer with a multicamera collage built into its camera.
#[derive(Parser, Debug)]
#[command(name = "mcctrace", version, about, long_about = None, propagate_version = true)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene from one or more cameras to OpenEXR (+ an sRGB PNG preview).
    Render(render::RenderArgs),
    /// Show what a scene holds: cameras, triangles, materials, lights, warnings.
    Info(info::InfoArgs),
    /// Stamp a camera number into the low bits of an image (the standalone camera tagger).
    Tag(tag::TagArgs),
    /// Compose a collage from a label image and the tagged views (the editor step, scripted).
    Collage(collage::CollageArgs),
    /// Turn a collage and the views' ray files into one ray per pixel (the lens remapper).
    Remap(remap::RemapArgs),
    /// Render a scene through a collage's rays (remaps first unless given --lens FILE).
    Rerender(rerender::RerenderArgs),
    /// Interpolate key ray files into one ray file per frame (the in-betweener).
    Inbetween(inbetween::InbetweenArgs),
    /// Remap one collage per key frame against that frame's views, then in-between them.
    Keys(keys::KeysArgs),
    /// Render a range of frames through per-frame ray files (resumable; farm-splittable).
    Animate(animate::AnimateArgs),
    /// Write (and with `slurm --submit`, submit) a whole shot's render-farm jobs: source views,
    /// keys, the frames in chunks, and a check of every frame.
    Farm(farm::FarmArgs),
    /// Assemble the bands of `render --tile` / `rerender --tile` into the whole EXR and PNG.
    Merge(merge::MergeArgs),
    /// Run the main job on the bundled scene and write every picture to one folder
    /// (--animation: the keyframe workflow, a short animated shot).
    Demo(demo::DemoArgs),
    /// Paint a collage in a local web page and watch its rerender refine (prints the URL).
    Studio(studio::StudioArgs),
}

/// Runs the command line `args` (program name first); errors are printed, not panicked.
pub fn main_with_args<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            // --help and --version are "errors" that print to stdout and succeed.
            let _ = e.print();
            return if e.use_stderr() { ExitCode::from(2) } else { ExitCode::SUCCESS };
        }
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Parses and runs `args` (program name first), returning the error instead of printing it:
/// the entry point for tests and scripts that drive `mcctrace` in-process.
pub fn try_run<I, T>(args: I) -> anyhow::Result<()>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    run(Cli::try_parse_from(args)?)
}

/// Runs a parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Render(a) => render::run(a),
        Command::Info(a) => info::run(a),
        Command::Tag(a) => tag::run(a),
        Command::Collage(a) => collage::run(a),
        Command::Remap(a) => remap::run(a),
        Command::Rerender(a) => rerender::run(a),
        Command::Inbetween(a) => inbetween::run(a),
        Command::Keys(a) => keys::run(a),
        Command::Animate(a) => animate::run(a),
        Command::Farm(a) => farm::run(a),
        Command::Merge(a) => merge::run(a),
        Command::Demo(a) => demo::run(a),
        Command::Studio(a) => studio::run(a),
    }
}

/// Runs `work` on a rayon pool of `threads` threads (all cores when `None`).
pub(crate) fn with_threads<R: Send>(
    threads: Option<usize>,
    work: impl FnOnce() -> R + Send,
) -> anyhow::Result<R> {
    let mut builder = rayon::ThreadPoolBuilder::new();
    if let Some(n) = threads {
        anyhow::ensure!(n > 0, "--threads must be at least 1");
        builder = builder.num_threads(n);
    }
    let pool = builder.build()?;
    Ok(pool.install(work))
}
