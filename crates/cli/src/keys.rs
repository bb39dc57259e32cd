//! `mcctrace keys`: the column's keyframe workflow in one go (docs/design.md §5, §7, §8) with the
//! library's [`KeyFrames`] job: one collage per key frame, each remapped against that frame's
//! source views (`frameFFFFcameraCC.mcr`, docs/design.md §4.3), then in-betweened into one ray
//! file per frame; skipped when those files are finished for the same keys, views and settings
//! (`mcc::job::KeysRecord`, docs/farm.md).

use crate::args::KeyArg;
use crate::inbetween::{InbetweenOutputArgs, summary};
use crate::progress::Bars;
use crate::setup::collage::{RemapSettingsArgs, tell_remapped};
use anyhow::bail;
use clap::Args;
use mcc::job::{Inbetween, JobProgress, Key, KeyFrames, KeysEvent};
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

/// The job `a` asks for: each key's collage and regions, the remapper's and the in-betweener's
/// settings.
fn job(a: &KeysArgs) -> anyhow::Result<KeyFrames> {
    let keys = a
        .keys
        .iter()
        .map(|k| {
            let (collage, regions) = split_key(k)?;
            Ok(Key { frame: k.frame, collage, regions, given: k.value.clone() })
        })
        .collect::<anyhow::Result<_>>()?;
    Ok(KeyFrames {
        keys,
        rays: a.rays.clone(),
        options: a.settings.collage_options()?,
        config: a.settings.config(),
        output: a.output.inbetween(),
    })
}

/// `keys`' progress on the terminal: the in-betweener's bar, what each remap made, and why the
/// files are made again or skipped.
pub(crate) struct KeysTerminal {
    quiet: bool,
    bars: Bars,
    output: Inbetween,
}

impl KeysTerminal {
    /// Progress of a job writing `output`; bars and lines unless `quiet`.
    pub(crate) fn new(output: Inbetween, quiet: bool) -> Self {
        Self { quiet, bars: Bars::new(quiet), output }
    }
}

impl JobProgress<KeysEvent<'_>> for KeysTerminal {
    fn stages(&self) -> &dyn tracer::render::Progress {
        &self.bars
    }

    fn event(&self, event: KeysEvent) {
        match event {
            KeysEvent::Finished => {
                if !self.quiet {
                    eprintln!(
                        "keys: the ray files in {} are finished with these keys, views and settings, skipped",
                        self.output.out.display()
                    );
                }
            }
            KeysEvent::Stale(why) => eprintln!("keys: {why}, making them again"),
            KeysEvent::Remapped { job, done, seconds } => tell_remapped(job, done, seconds, self.quiet),
            KeysEvent::Inbetweened { keys, frames, written, seconds } => {
                if !self.quiet {
                    eprintln!("{}", summary(keys, &self.output, frames, written, seconds));
                }
            }
        }
    }
}

pub fn run(a: KeysArgs) -> anyhow::Result<()> {
    let job = job(&a)?;
    let mut seen = std::collections::BTreeSet::new();
    for k in &a.keys {
        if !seen.insert(k.frame) {
            bail!("frame {} has two --key entries; each frame takes one key", k.frame);
        }
    }
    job.run(&KeysTerminal::new(job.output.clone(), a.output.quiet))?;
    Ok(())
}
