//! `mcctrace inbetween`: the in-betweener (docs/design.md §7, §8): key ray files in, one
//! `rerender-frameFFFF` ray file per frame out, each written atomically.

use crate::args::{FrameRange, KeyArg, RayFormatArg, Resolution};
use crate::progress::Bars;
use clap::{Args, ValueEnum};
use mcc::inbetween::{InbetweenMode, Keys};
use mcc::job::Inbetween;
use std::ops::RangeInclusive;
use std::path::{Path, PathBuf};

/// In-betweening modes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// C1 across interior keys (Catmull–Rom origins, its spherical counterpart on directions);
    /// eases in and out of the first and last key.
    Smooth,
    /// Origins lerp, directions slerp between the two surrounding keys.
    Linear,
}

impl From<ModeArg> for InbetweenMode {
    fn from(m: ModeArg) -> Self {
        match m {
            ModeArg::Smooth => InbetweenMode::Smooth,
            ModeArg::Linear => InbetweenMode::Linear,
        }
    }
}

/// Output settings shared by `inbetween` and `keys`.
#[derive(Args, Debug, Clone)]
pub struct InbetweenOutputArgs {
    /// Frames to write, FIRST..=LAST (both included) or one frame F (default: the first key's
    /// frame to the last key's). Frames before the first key or after the last hold that key.
    #[arg(long, value_name = "A..=B")]
    pub frames: Option<FrameRange>,
    /// Directory that receives rerender-frameFFFF.mcr (or .txt) per frame.
    #[arg(long)]
    pub out: PathBuf,
    /// Interpolation between keys.
    #[arg(long, value_enum, default_value = "smooth")]
    pub mode: ModeArg,
    /// Resolution of every frame (default: the earliest key's); keys of another size are
    /// resampled with the lens reader's rule.
    #[arg(long, value_name = "WxH")]
    pub res: Option<Resolution>,
    /// Encoding of the ray files.
    #[arg(long, value_enum, default_value = "binary")]
    pub ray_format: RayFormatArg,
    /// Drop an N-pixel border from every key (in its own pixels) rendered with `render
    /// --overscan N`: the frames hold the picture only; --res is then the size of what is left.
    #[arg(long, default_value_t = 0, value_name = "N")]
    pub crop: u32,
    /// No progress bar or summary.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Arguments of `mcctrace inbetween`.
#[derive(Args, Debug)]
pub struct InbetweenArgs {
    /// A key: its frame and ray file, FRAME=FILE (like 150=lens/rerender-frame0150.mcr);
    /// repeat for each key, in any order. Keys need share no cameras or resolution.
    #[arg(long = "key", value_name = "FRAME=FILE", required = true)]
    pub keys: Vec<KeyArg>,
    #[command(flatten)]
    pub output: InbetweenOutputArgs,
}

impl InbetweenOutputArgs {
    /// The library's settings these arguments make.
    pub fn inbetween(&self) -> Inbetween {
        Inbetween {
            frames: self.frames.map(FrameRange::range),
            out: self.out.clone(),
            mode: self.mode.into(),
            res: self.res.map(|r| r.0),
            format: self.ray_format.into(),
            crop: self.crop,
        }
    }
}

/// Writes the frames `o` asks for from `keys`, with a bar and a summary unless `quiet`; returns
/// the paths written, in frame order.
pub fn write_inbetweens(keys: &Keys, o: &Inbetween, quiet: bool) -> anyhow::Result<Vec<PathBuf>> {
    let start = std::time::Instant::now();
    let written = o.write(keys, &Bars::new(quiet))?;
    if !quiet {
        let frames = o.frames_for(&keys.frames());
        eprintln!("{}", summary(keys, o, frames, &written, start.elapsed().as_secs_f64()));
    }
    Ok(written)
}

/// The line saying `written` frames `frames` were in-betweened from `keys` as `o` says, in
/// `seconds`.
pub fn summary(
    keys: &Keys,
    o: &Inbetween,
    frames: RangeInclusive<u32>,
    written: &[PathBuf],
    seconds: f64,
) -> String {
    let res = keys.resolution();
    format!(
        "in-between: {} frames ({}..={}) at {}x{} from keys at {:?} ({:?}) in {seconds:.2} s -> {}",
        written.len(),
        frames.start(),
        frames.end(),
        res.x,
        res.y,
        keys.frames(),
        o.mode,
        o.out.display()
    )
}

/// Loads the key files, refusing a missing one by name before anything is written.
fn load_keys(keys: &[KeyArg], crop: u32, res: Option<Resolution>) -> anyhow::Result<Keys> {
    let pairs: Vec<(u32, PathBuf)> = keys.iter().map(|k| (k.frame, k.path())).collect();
    for (frame, path) in &pairs {
        if !Path::new(path).is_file() {
            anyhow::bail!("key at frame {frame}: {} is not a file (or cannot be reached)", path.display());
        }
    }
    Ok(Keys::load_cropped(&pairs, crop, res.map(|r| r.0))?)
}

pub fn run(a: InbetweenArgs) -> anyhow::Result<()> {
    let keys = load_keys(&a.keys, a.output.crop, a.output.res)?;
    write_inbetweens(&keys, &a.output.inbetween(), a.output.quiet)?;
    Ok(())
}
