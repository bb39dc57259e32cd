//! `mcctrace keys`: the column's keyframe workflow in one go (docs/design.md §5, §7, §8): one
//! collage per key frame, each remapped against that frame's source views
//! (`frameFFFFcameraCC.mcr`, docs/design.md §4.3) by the remap command's own job, then
//! in-betweened into one ray file per frame.

use crate::args::KeyArg;
use crate::inbetween::{InbetweenOutputArgs, write_inbetweens};
use crate::setup::collage::{RemapSettingsArgs, remap};
use anyhow::{Context, bail};
use clap::Args;
use mcc::inbetween::Keys;
use std::path::PathBuf;

/// Arguments of `mcctrace keys`.
#[derive(Args, Debug)]
pub struct KeysArgs {
    /// A key: FRAME=COLLAGE or FRAME=COLLAGE,REGIONS (the collage an image or a layered .ora or
    /// .psd file; the region image by default the collage's "regions" layer group, else
    /// <collage-stem>-regions.png beside the collage, if present). Repeat for each key; each
    /// key may use its own cameras.
    #[arg(long = "key", value_name = "FRAME=COLLAGE[,REGIONS]", required = true)]
    pub keys: Vec<KeyArg>,
    /// Directory holding the source views' ray files of every key frame
    /// (frameFFFFcameraCC.mcr or .txt, as `render --lens-writer` names them).
    #[arg(long)]
    pub rays: PathBuf,
    /// How each collage is read and remapped.
    #[command(flatten)]
    pub settings: RemapSettingsArgs,
    #[command(flatten)]
    pub output: InbetweenOutputArgs,
}

/// A key's collage and optional region image, from `COLLAGE[,REGIONS]`.
pub(crate) fn split_key(key: &KeyArg) -> anyhow::Result<(PathBuf, Option<PathBuf>)> {
    match key.value.split_once(',') {
        None => Ok((key.path(), None)),
        Some((collage, regions)) if !collage.is_empty() && !regions.is_empty() => {
            Ok((PathBuf::from(collage), Some(PathBuf::from(regions))))
        }
        Some(_) => {
            bail!("--key {}={}: expected FRAME=COLLAGE or FRAME=COLLAGE,REGIONS", key.frame, key.value)
        }
    }
}

/// Remaps every key's collage against its frame's views; returns (frame, rays) per key.
fn remap_keys(a: &KeysArgs) -> anyhow::Result<Vec<(u32, mcc::RayFile)>> {
    let mut seen = std::collections::BTreeSet::new();
    for k in &a.keys {
        if !seen.insert(k.frame) {
            bail!("frame {} has two --key entries; each frame takes one key", k.frame);
        }
    }
    a.keys
        .iter()
        .map(|k| {
            let (collage, regions) = split_key(k)?;
            let out = (a.settings.job(collage.clone(), regions, a.rays.clone(), k.frame))
                .and_then(|job| remap(&job, a.output.quiet))
                .with_context(|| format!("key at frame {} ({})", k.frame, collage.display()))?;
            let rays = mcc::inbetween::crop_key(out.output.rays, a.output.crop)
                .map_err(|m| anyhow::anyhow!("key at frame {} ({}): {m}", k.frame, collage.display()))?;
            Ok((k.frame, rays))
        })
        .collect()
}

pub fn run(a: KeysArgs) -> anyhow::Result<()> {
    let remapped = remap_keys(&a)?;
    let keys = Keys::new(remapped, a.output.res.map(|r| r.0))?;
    write_inbetweens(&keys, &a.output)?;
    Ok(())
}
