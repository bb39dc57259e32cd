//! `mcctrace collage`: compose a collage from a label image (docs/design/workflow.md §8's image-editor step
//! done from a file, for scripts and tests): each labelled pixel copies the tagged view of its
//! camera; black stays background.

use anyhow::bail;
use clap::Args;
use std::collections::HashMap;
use std::path::PathBuf;

/// Arguments of `mcctrace collage`.
#[derive(Args, Debug)]
pub struct CollageArgs {
    /// Label image: each exact colour picks a camera (see --label); black is background.
    #[arg(long)]
    mask: PathBuf,
    /// Directory holding the tagged views (frameFFFFcameraCC.png).
    #[arg(long)]
    views: PathBuf,
    /// Frame of the views.
    #[arg(long, default_value_t = 0)]
    frame: u32,
    /// Colour-to-camera labels as RRGGBB=ID (hex colour), repeatable. Default: red (ff0000) = 1,
    /// green (00ff00) = 2, blue (0000ff) = 3, yellow (ffff00) = 4, magenta (ff00ff) = 5,
    /// cyan (00ffff) = 6, white (ffffff) = 7.
    #[arg(long = "label", value_name = "RRGGBB=ID")]
    labels: Vec<String>,
    /// Read each label colour's own tag bits as the camera (the mask was drawn in tag colours).
    #[arg(long, conflicts_with = "labels")]
    tag_labels: bool,
    /// Bits per channel of the tag code.
    #[arg(long, default_value_t = 2, value_parser = crate::args::tag_bits)]
    tag_bits: u8,
    /// The collage PNG to write.
    #[arg(long)]
    out: PathBuf,
}

/// The default colour labels (primaries and secondaries, then white).
pub fn default_labels() -> HashMap<[u8; 3], u32> {
    HashMap::from([
        ([255, 0, 0], 1),
        ([0, 255, 0], 2),
        ([0, 0, 255], 3),
        ([255, 255, 0], 4),
        ([255, 0, 255], 5),
        ([0, 255, 255], 6),
        ([255, 255, 255], 7),
    ])
}

fn parse_label(s: &str) -> anyhow::Result<([u8; 3], u32)> {
    let Some((colour, id)) = s.split_once('=') else {
        bail!("--label {s}: expected RRGGBB=ID, like ff0000=1")
    };
    let colour = colour.trim_start_matches('#');
    if colour.len() != 6 {
        bail!("--label {s}: the colour must be six hex digits");
    }
    let byte = |i: usize| u8::from_str_radix(&colour[i..i + 2], 16);
    let rgb = [byte(0), byte(2), byte(4)];
    let [Ok(r), Ok(g), Ok(b)] = rgb else { bail!("--label {s}: '{colour}' is not a hex colour") };
    let id: u32 =
        id.trim().parse().map_err(|_| anyhow::anyhow!("--label {s}: '{id}' is not a camera number"))?;
    if [r, g, b] == [0, 0, 0] {
        bail!("--label {s}: black is the background");
    }
    Ok(([r, g, b], id))
}

/// The label map the arguments ask for.
pub fn label_map(
    labels: &[String],
    tag_labels: bool,
    tag_bits: u8,
) -> anyhow::Result<mcc::compose::LabelMap> {
    Ok(if tag_labels {
        mcc::compose::LabelMap::TagBits(mcc::TagCode::new(tag_bits)?)
    } else if labels.is_empty() {
        mcc::compose::LabelMap::Colours(default_labels())
    } else {
        mcc::compose::LabelMap::Colours(labels.iter().map(|l| parse_label(l)).collect::<Result<_, _>>()?)
    })
}

pub fn run(a: CollageArgs) -> anyhow::Result<()> {
    let map = label_map(&a.labels, a.tag_labels, a.tag_bits)?;
    mcc::compose::compose_files(&a.mask, &map, &a.views, a.frame, &a.out)?;
    println!("collage -> {}", a.out.display());
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_parse() {
        assert_eq!(parse_label("ff0000=1").unwrap(), ([255, 0, 0], 1));
        assert_eq!(parse_label("#00Ff80=12").unwrap(), ([0, 255, 128], 12));
        assert!(parse_label("ff0000").is_err());
        assert!(parse_label("ff00=1").is_err());
        assert!(parse_label("gg0000=1").is_err());
        assert!(parse_label("000000=1").is_err());
        assert!(parse_label("ff0000=x").is_err());
    }
}
