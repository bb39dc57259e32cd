//! `mcctrace tag`: the standalone camera tagger (docs/design/mcc.md §4.4): stamp a camera number into
//! the low bits of an 8-bit image's pixels.

use clap::Args;
use std::path::PathBuf;

/// Arguments of `mcctrace tag`.
#[derive(Args, Debug)]
pub struct TagArgs {
    /// The image to tag (8-bit PNG, RGB or RGBA).
    image: PathBuf,
    /// The view's number to stamp, counted from 1 as `render` numbers its views
    /// (1 … 2^(3·B) − 1).
    #[arg(long, value_name = "NUMBER")]
    camera: u32,
    /// Bits per channel of the camera tag, as `render --tag-bits` (and `remap --tag-bits`) take
    /// it; `--bits` is the old spelling.
    #[arg(long = "tag-bits", visible_alias = "bits", value_name = "B",
          default_value_t = mcc::TagCode::DEFAULT_BITS, value_parser = crate::args::tag_bits)]
    bits: u8,
    /// The tagged PNG to write.
    #[arg(long)]
    out: PathBuf,
}

pub fn run(a: TagArgs) -> anyhow::Result<()> {
    mcc::tag::tag_png(&a.image, a.camera, a.bits, &a.out)?;
    println!("tagged {} as camera {} ({} bits) -> {}", a.image.display(), a.camera, a.bits, a.out.display());
    Ok(())
}
