//! Denoising with Intel Open Image Denoise (docs/design/tracer.md §3.11): OIDN 2.x's `RT` filter on the
//! HDR beauty, guided by the film's first-hit albedo and normal, through a small binding of our
//! own to OIDN's C API that opens the library at run time ([`loader`]), so nothing of it is
//! needed to build, start or render without denoising.
//!
//! A run is described by [`Settings`]: OIDN's [`Quality`] (its network: fast, balanced, high)
//! and how the auxiliaries guide it ([`Guide`]). A final picture's auxiliaries are means over
//! every sample's first hit, clean enough for `cleanAux` unless the camera has depth of field or
//! motion blur or the samples are few; [`Settings::for_final`] picks the use that measured best
//! for each quality (docs/performance.md §1.7), prefiltering them only at high quality when they
//! carry noise, as OIDN advises. The studio's preview passes them as they are
//! ([`Settings::PREVIEW`]). Inputs are made finite and in range
//! first (NaN or infinite samples never reach the filter), and the output is finite.

mod filter;
mod loader;

pub use filter::Aux;
use filter::FilterCache;
pub use loader::{ENV_VAR, INSTALL_COMMAND, Location, find_library};

use crate::image::RgbImage;
use loader::Api;
use std::ffi::{CStr, c_char, c_int, c_void};
use std::path::PathBuf;
use std::sync::{Mutex, OnceLock};

/// What can go wrong finding, opening or running the denoiser.
#[derive(Clone, Debug, thiserror::Error)]
pub enum DenoiseError {
    /// The library is not where [`find_library`] looks.
    #[error(
        "denoising needs Intel Open Image Denoise 2.x, which is not installed (looked at: {looked}). \
         Install it with this one command, run in the folder mcctrace runs from: {INSTALL_COMMAND}"
    )]
    NotFound {
        /// Where it was looked for.
        looked: String,
    },
    /// The library was found but does not open, or lacks OIDN 2.x's functions.
    #[error(
        "{}: cannot open Intel Open Image Denoise: {message}. Reinstall it with: {INSTALL_COMMAND}",
        path.display()
    )]
    Load {
        /// The library file.
        path: PathBuf,
        /// What the loader said.
        message: String,
    },
    /// OIDN reported an error (no CPU device, out of memory …).
    #[error("Intel Open Image Denoise ({origin}): {message}")]
    Oidn {
        /// Where the library was opened from.
        origin: String,
        /// OIDN's message.
        message: String,
    },
    /// The caller's progress asked for the run to stop (newer work supersedes it).
    #[error("denoising cancelled")]
    Cancelled,
    /// The images handed to the denoiser do not fit together.
    #[error("denoising: {0}")]
    Input(String),
}

/// OIDN's `quality`: which network filters the picture. On this machine's 2 cores a 1920×1080
/// beauty with auxiliaries takes about 1.6 s fast, 3.1 s balanced, 7.8 s high (with `cleanAux`;
/// docs/performance.md §1.7).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Quality {
    /// The small network: the quickest, a little blurrier.
    Fast,
    /// The default network.
    Balanced,
    /// The large network (with clean auxiliaries): the best, about 2.5× balanced's time.
    High,
}

impl Quality {
    /// What a plain `--denoise` gives, as Cycles' final renders: the best. Fast meets the 2 s
    /// of a 1920×1080 final on 2 cores but leaves 1.2–1.55× high's relMSE, worth 1.4–2.4× the
    /// samples, which costs more than high's few extra seconds (docs/performance.md §1.7).
    pub const DEFAULT: Self = Self::High;

    /// Every quality, quickest first.
    pub const ALL: [Self; 3] = [Self::Fast, Self::Balanced, Self::High];

    /// The name the command line and the EXR header use.
    pub const fn name(self) -> &'static str {
        match self {
            Self::Fast => "fast",
            Self::Balanced => "balanced",
            Self::High => "high",
        }
    }

    /// The quality called `name` ([`Quality::name`]), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|q| q.name() == name)
    }

    /// OIDN's `OIDN_QUALITY_*` value.
    pub(crate) const fn oidn(self) -> std::ffi::c_int {
        match self {
            Self::Fast => 4,
            Self::Balanced => 5,
            Self::High => 6,
        }
    }
}

/// How the albedo and normal guide the filter.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Guide {
    /// Passed as they are, `cleanAux` off: the network expects some noise in them (the studio's
    /// few-sample preview).
    AsRendered,
    /// Passed as they are with `cleanAux`: they are noise-free, and the filter trusts their edges.
    Clean,
    /// Each first filtered alone by the same filter, then the beauty with `cleanAux` (OIDN's
    /// advice for noisy auxiliaries): three filter runs.
    Prefiltered,
}

impl Guide {
    /// From this many samples per pixel (and without depth of field or motion blur) a final's
    /// auxiliaries count as clean: their edge pixels average enough first hits.
    pub const CLEAN_FROM_SPP: u32 = 16;

    /// The name the EXR header uses.
    pub const fn name(self) -> &'static str {
        match self {
            Self::AsRendered => "as-rendered",
            Self::Clean => "clean",
            Self::Prefiltered => "prefiltered",
        }
    }

    /// The guide called `name` ([`Guide::name`]), if any.
    pub fn from_name(name: &str) -> Option<Self> {
        [Self::AsRendered, Self::Clean, Self::Prefiltered].into_iter().find(|g| g.name() == name)
    }
}

/// How a picture is denoised: the network and the auxiliaries' part.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Settings {
    /// OIDN's quality.
    pub quality: Quality,
    /// How albedo and normal guide it (ignored without auxiliaries).
    pub guide: Guide,
}

impl Settings {
    /// The studio's live preview: fast, auxiliaries as rendered (few samples, noisy edges).
    pub const PREVIEW: Self = Self { quality: Quality::Fast, guide: Guide::AsRendered };

    /// How a final picture of `spp` samples per pixel is denoised at `quality`. Its auxiliaries
    /// carry noise with depth of field (`lens`), motion blur (`motion`: the shutter open) or
    /// fewer than [`Guide::CLEAN_FROM_SPP`] samples. Measured against 1024-spp references
    /// (docs/performance.md §1.7): high quality's large network needs `cleanAux`, and gains
    /// 10–13 % from prefiltering noisy auxiliaries (4 spp), nothing from it on clean ones;
    /// balanced gains up to 10 % from `cleanAux` on clean ones and nothing from prefiltering;
    /// fast does best with them as rendered (its `cleanAux` network is up to 20 % worse).
    pub const fn for_final(quality: Quality, spp: u32, lens: bool, motion: bool) -> Self {
        let noisy = lens || motion || spp < Guide::CLEAN_FROM_SPP;
        let guide = match (quality, noisy) {
            (Quality::Fast, _) | (Quality::Balanced, true) => Guide::AsRendered,
            (Quality::Balanced, false) | (Quality::High, false) => Guide::Clean,
            (Quality::High, true) => Guide::Prefiltered,
        };
        Self { quality, guide }
    }
}

/// An OIDN CPU device, ready to filter images. OIDN's API is thread-safe (calls on one device
/// are serialised by OIDN), so one device serves every thread.
pub struct Denoiser {
    api: Api,
    device: *mut c_void,
    version: String,
    /// Filters kept for reuse (creating one builds its network), behind the lock every run takes.
    filters: Mutex<FilterCache>,
}

// SAFETY: OIDN documents every API call as thread-safe; the device handle is only passed to it.
unsafe impl Send for Denoiser {}
// SAFETY: as above.
unsafe impl Sync for Denoiser {}

impl Denoiser {
    /// Opens the library ([`loader`]'s rules) and starts a CPU device.
    pub fn new() -> Result<Self, DenoiseError> {
        let api = Api::open()?;
        const DEVICE_TYPE_CPU: i32 = 1;
        // SAFETY: OIDN's C API, called as `oidn.h` declares; a null device is checked below.
        let device = unsafe { (api.new_device)(DEVICE_TYPE_CPU) };
        let mut denoiser = Self { api, device, version: String::new(), filters: Mutex::default() };
        if device.is_null() {
            return Err(denoiser.error(std::ptr::null_mut()).unwrap_err());
        }
        // SAFETY: a live device.
        unsafe { (denoiser.api.commit_device)(device) };
        denoiser.check()?;
        // SAFETY: a live, committed device; the name is a NUL-terminated C string.
        let v = unsafe { (denoiser.api.get_device_int)(device, c"version".as_ptr()) };
        denoiser.version = format!("{}.{}.{}", v / 10000, v / 100 % 100, v % 100);
        Ok(denoiser)
    }

    /// The process's one denoiser, started on first use (a device costs a fraction of a second
    /// to start, too much per frame or per preview); the error, if it could not start, is kept
    /// and returned again.
    pub fn shared() -> Result<&'static Self, DenoiseError> {
        static SHARED: OnceLock<Result<Denoiser, DenoiseError>> = OnceLock::new();
        SHARED.get_or_init(Self::new).as_ref().map_err(Clone::clone)
    }

    /// OIDN's version, `MAJOR.MINOR.PATCH`.
    pub fn version(&self) -> &str {
        &self.version
    }

    /// Where the library was opened from.
    pub fn origin(&self) -> &str {
        &self.api.origin
    }

    /// What a picture denoised with `settings` was denoised with, for an EXR header.
    pub fn describe(&self, settings: Settings, aux: bool) -> String {
        let aux = match (aux, settings.guide) {
            (false, _) => "no auxiliaries",
            (true, Guide::AsRendered) => "albedo+normal as rendered",
            (true, Guide::Clean) => "albedo+normal clean, cleanAux",
            (true, Guide::Prefiltered) => "albedo+normal prefiltered, cleanAux",
        };
        format!(
            "Intel Open Image Denoise {} RT hdr, {aux}, quality {}",
            self.version,
            settings.quality.name()
        )
    }

    /// `color` (linear HDR radiance) denoised with `settings`, guided by `aux` when given.
    /// Non-finite and negative inputs are zeroed, auxiliaries clamped to their ranges; the
    /// result is finite.
    pub fn denoise(
        &self,
        color: &RgbImage,
        aux: Option<Aux<'_>>,
        settings: Settings,
    ) -> Result<RgbImage, DenoiseError> {
        filter::run(self, color, aux, settings, &crate::render::NoProgress)
    }

    /// [`Denoiser::denoise`], stopped with [`DenoiseError::Cancelled`] as soon as
    /// `progress.cancelled()` says so: OIDN asks between its tiles of work, so a run that newer
    /// work supersedes (the studio's preview after a stroke) ends within a few milliseconds.
    pub fn denoise_cancellable(
        &self,
        color: &RgbImage,
        aux: Option<Aux<'_>>,
        settings: Settings,
        progress: &dyn crate::render::Progress,
    ) -> Result<RgbImage, DenoiseError> {
        filter::run(self, color, aux, settings, progress)
    }

    /// `Err` with OIDN's message if the device has an error pending.
    fn check(&self) -> Result<(), DenoiseError> {
        self.error(self.device)
    }

    fn error(&self, device: *mut c_void) -> Result<(), DenoiseError> {
        let mut message: *const c_char = std::ptr::null();
        // SAFETY: a live device or null (OIDN then reports its global error); `message` is an
        // out-pointer OIDN fills with a string it owns until the next call.
        let code = unsafe { (self.api.get_device_error)(device, &mut message) };
        /// `OIDN_ERROR_CANCELLED`: the progress monitor stopped the execution.
        const ERROR_CANCELLED: c_int = 6;
        match code {
            0 => return Ok(()),
            ERROR_CANCELLED => return Err(DenoiseError::Cancelled),
            _ => {}
        }
        let text = if message.is_null() {
            format!("error {code}")
        } else {
            // SAFETY: OIDN returns a NUL-terminated string valid until its next call on the device.
            unsafe { CStr::from_ptr(message) }.to_string_lossy().into_owned()
        };
        Err(DenoiseError::Oidn { origin: self.api.origin.clone(), message: text })
    }
}

impl Drop for Denoiser {
    fn drop(&mut self) {
        let mut filters =
            std::mem::take(self.filters.get_mut().unwrap_or_else(std::sync::PoisonError::into_inner));
        filters.release_all(self);
        if !self.device.is_null() {
            // SAFETY: the device this value owns, released once.
            unsafe { (self.api.release_device)(self.device) };
        }
    }
}

#[cfg(test)]
mod tests;
