//! The column's keyframe workflow (docs/design.md §5, §7, §8; `keys`, the animation demo): one
//! collage per key frame, each remapped against that frame's source views
//! (`frameFFFFcameraCC.mcr`, docs/design.md §4.3) by [`RemapJob`], then in-betweened into one
//! ray file per frame ([`Inbetween`]). Skipped when those files are finished for the same keys,
//! views and settings ([`KeysRecord`], docs/farm.md).

use super::keys_record::KeysRecord;
use super::progress::JobProgress;
use super::remap::{CollageFiles, RemapJob, Remapped};
use crate::collage::CollageOptions;
use crate::error::{MccError, Result};
use crate::inbetween::{InbetweenMode, Keys, crop_key, write_frames};
use crate::names::rerender_name;
use crate::ray_file::{RayFile, RayFormat};
use crate::remap::RemapConfig;
use glam::UVec2;
use std::ops::RangeInclusive;
use std::path::PathBuf;
use std::time::Instant;
use tracer::job::Stale;
use tracer::render::Progress;

/// Which frames the in-betweener writes, where and how (`inbetween`, `keys`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Inbetween {
    /// The frames to write (both ends included); `None`: the first key's frame to the last's.
    /// Frames before the first key or after the last hold that key.
    pub frames: Option<RangeInclusive<u32>>,
    /// The folder that receives `rerender-frameFFFF.{mcr|txt}` per frame.
    pub out: PathBuf,
    /// The interpolation between keys.
    pub mode: InbetweenMode,
    /// The frames' resolution (`None`: the earliest key's); other keys are resampled.
    pub res: Option<UVec2>,
    /// The ray files' encoding.
    pub format: RayFormat,
    /// The overscan border dropped from every key, in its own pixels.
    pub crop: u32,
}

impl Inbetween {
    /// The frames written from keys at `key_frames` (at least one).
    pub fn frames_for(&self, key_frames: &[u32]) -> RangeInclusive<u32> {
        self.frames.clone().unwrap_or_else(|| {
            let first = key_frames.iter().copied().min().unwrap_or(0);
            first..=key_frames.iter().copied().max().unwrap_or(0)
        })
    }

    /// Writes the frames from `keys`, each atomically, a progress stage `in-between` counting
    /// them; returns the paths written, in frame order.
    pub fn write(&self, keys: &Keys, progress: &dyn Progress) -> Result<Vec<PathBuf>> {
        let frames = self.frames_for(&keys.frames());
        progress.begin("in-between", (frames.end() - frames.start()) as u64 + 1);
        let written =
            write_frames(keys, frames.clone(), self.mode, &self.out, self.format, &|_| progress.advance(1))
                .map_err(|e| {
                let (first, last) = (frames.start(), frames.end());
                e.during(format!("in-betweening frames {first}..={last} into {}", self.out.display()))
            })?;
        progress.finish();
        Ok(written)
    }
}

/// One key of a [`KeyFrames`] job.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Key {
    /// Its frame.
    pub frame: u32,
    /// Its collage (an image or a layered file).
    pub collage: PathBuf,
    /// Its region image; `None`: found as [`CollageFiles::regions`] says.
    pub regions: Option<PathBuf>,
    /// How the user wrote it (`COLLAGE[,REGIONS]`), recorded as given.
    pub given: String,
}

/// Key collages remapped and in-betweened into one ray file per frame.
#[derive(Clone, Debug, PartialEq)]
pub struct KeyFrames {
    /// The keys, one per frame.
    pub keys: Vec<Key>,
    /// The folder holding every key frame's source views' ray files.
    pub rays: PathBuf,
    /// How each collage is decoded.
    pub options: CollageOptions,
    /// The remapper's settings.
    pub config: RemapConfig,
    /// Which frames are written, where and how.
    pub output: Inbetween,
}

/// What a [`KeyFrames`] job tells as it goes.
pub enum KeysEvent<'a> {
    /// The ray files are finished with these keys, views and settings: nothing is made.
    Finished,
    /// The ray files are not finished (made from other inputs or settings, damaged): made again.
    Stale(&'a Stale),
    /// A key's collage is remapped, in `seconds`.
    Remapped {
        /// The remap.
        job: &'a RemapJob,
        /// What it made.
        done: &'a Remapped,
        /// How long it took.
        seconds: f64,
    },
    /// The frames are in-betweened, in `seconds`.
    Inbetweened {
        /// The keys.
        keys: &'a Keys,
        /// The frames written.
        frames: RangeInclusive<u32>,
        /// The files written.
        written: &'a [PathBuf],
        /// How long it took.
        seconds: f64,
    },
}

/// Where a [`KeyFrames`] job reports: the in-betweener's stage and its events.
pub type KeysProgress = dyn for<'e> JobProgress<KeysEvent<'e>>;

impl KeyFrames {
    /// The remap of `key`.
    pub fn remap_job(&self, key: &Key) -> RemapJob {
        let input = CollageFiles {
            regions: key.regions.clone(),
            options: self.options,
            ..CollageFiles::new(key.collage.clone(), self.rays.clone(), key.frame)
        };
        RemapJob { config: self.config, ..RemapJob::new(input) }
    }

    /// The record of what this job's ray files are made from: its settings, and every file the
    /// keys' remaps read (hashed now).
    pub fn record(&self) -> Result<KeysRecord> {
        let o = &self.output;
        let mut inputs = Vec::new();
        let mut settings = Vec::new();
        for k in &self.keys {
            let job = self.remap_job(k);
            inputs.extend(job.input.inputs().map_err(|e| e.during(format!("key at frame {}", k.frame)))?);
            settings.push((format!("key {}", k.frame), k.given.clone()));
            settings
                .push((format!("remap {}", k.frame), format!("{:?} {:?}", job.config, job.input.options)));
        }
        let key_frames: Vec<u32> = self.keys.iter().map(|k| k.frame).collect();
        let frames = o.frames_for(&key_frames);
        settings.extend([
            ("rays".to_owned(), self.rays.display().to_string()),
            ("frames".to_owned(), format!("{}..={}", frames.start(), frames.end())),
            ("mode".to_owned(), format!("{:?}", o.mode)),
            ("res".to_owned(), o.res.map(|r| format!("{}x{}", r.x, r.y)).unwrap_or_default()),
            ("ray_format".to_owned(), format!("{:?}", o.format)),
            ("crop".to_owned(), o.crop.to_string()),
        ]);
        let outputs = frames.map(|f| o.out.join(rerender_name(f, o.format))).collect();
        KeysRecord::new(&o.out, settings, &inputs, outputs)
    }

    /// Makes the ray files unless they are finished for this job (its record there and the
    /// same), then writes the record; returns the files written (none when finished).
    pub fn run(&self, progress: &KeysProgress) -> Result<Vec<PathBuf>> {
        let record = self.record()?;
        match record.check() {
            Ok(()) => {
                progress.event(KeysEvent::Finished);
                return Ok(Vec::new());
            }
            // Never made here: nothing to tell.
            Err(Stale::Missing(path)) if path == record.path => {}
            Err(why) => progress.event(KeysEvent::Stale(&why)),
        }
        let written = self.make(progress)?;
        record.write()?;
        Ok(written)
    }

    /// Remaps every key and in-betweens the frames (no record: [`Self::run`] keeps one).
    pub fn make(&self, progress: &KeysProgress) -> Result<Vec<PathBuf>> {
        let remapped = self.keys.iter().map(|k| self.remap_key(k, progress)).collect::<Result<_>>()?;
        let keys = Keys::new(remapped, self.output.res)?;
        let start = Instant::now();
        let written = self.output.write(&keys, progress.stages())?;
        let frames = self.output.frames_for(&keys.frames());
        let seconds = start.elapsed().as_secs_f64();
        progress.event(KeysEvent::Inbetweened { keys: &keys, frames, written: &written, seconds });
        Ok(written)
    }

    /// Remaps `key`'s collage against its frame's views: (frame, rays without the border).
    fn remap_key(&self, key: &Key, progress: &KeysProgress) -> Result<(u32, RayFile)> {
        let at = || format!("key at frame {} ({})", key.frame, key.collage.display());
        let job = self.remap_job(key);
        let start = Instant::now();
        let done = job.run().map_err(|e| e.during(at()))?;
        progress.event(KeysEvent::Remapped {
            job: &job,
            done: &done,
            seconds: start.elapsed().as_secs_f64(),
        });
        let rays = crop_key(done.output.rays, self.output.crop).map_err(|m| MccError::input(at(), m))?;
        Ok((key.frame, rays))
    }
}
