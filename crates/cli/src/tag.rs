//! `mcctrace tag`: the standalone camera tagger (docs/design.md §4.4): stamp a camera number into
//! the low bits of an 8-bit image's pixels.

use clap::Args;
use std::path::PathBuf;

/// Arguments of `mcctrace tag`.
#[derive(Args, Debug)]
pub struct TagArgs {
    /// The image to tag (8-bit PNG, RGB or RGBA).
    image: PathBuf,
    /// Camera number to stamp (1 … 2^(3·bits) − 1).
    #[arg(long)]
    camera: u32,
    /// Bits per channel used for the tag.
    #[arg(long, default_value_t = 2)]
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
