//! Denoising with Intel Open Image Denoise (docs/design.md §3.11): OIDN 2.x's `RT` filter on the
//! HDR beauty, guided by the film's first-hit albedo and normal, through a small binding of our
//! own to OIDN's C API that opens the library at run time ([`loader`]), so nothing of it is
//! needed to build, start or render without denoising.
//!
//! Two ways to call it ([`Mode`]): a final picture prefilters the auxiliaries with the same filter
//! before the beauty is filtered with `cleanAux` (OIDN's advice for auxiliaries that carry noise:
//! ours are averages of jittered, motion-blurred, depth-of-field first hits, noisy at edges at low
//! sample counts), at the highest quality; a preview passes them as they are at the fast
//! quality (half the balanced one's time on this machine's CPU), for speed. Inputs are made finite and in range first (NaN or infinite samples never
//! reach the filter), and the output is finite.

mod filter;
mod loader;

pub use filter::Aux;
use filter::FilterCache;
pub use loader::{ENV_VAR, INSTALL_COMMAND, Location, find_library};

use crate::image::RgbImage;
use loader::Api;
use std::ffi::{CStr, c_char, c_void};
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
    /// The images handed to the denoiser do not fit together.
    #[error("denoising: {0}")]
    Input(String),
}

/// How a picture is denoised.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// A final picture: auxiliaries prefiltered, then `cleanAux`; highest quality.
    Final,
    /// The studio's live preview: auxiliaries as they are; OIDN's fast quality.
    Preview,
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

    /// What a picture denoised in `mode` was denoised with, for an EXR header.
    pub fn describe(&self, mode: Mode, aux: bool) -> String {
        let aux = match (aux, mode) {
            (false, _) => "no auxiliaries",
            (true, Mode::Final) => "albedo+normal prefiltered, cleanAux",
            (true, Mode::Preview) => "albedo+normal",
        };
        let quality = if mode == Mode::Final { "high" } else { "fast" };
        format!("Intel Open Image Denoise {} RT hdr, {aux}, quality {quality}", self.version)
    }

    /// `color` (linear HDR radiance) denoised in `mode`, guided by `aux` when given. Non-finite
    /// and negative inputs are zeroed, auxiliaries clamped to their ranges; the result is finite.
    pub fn denoise(
        &self,
        color: &RgbImage,
        aux: Option<Aux<'_>>,
        mode: Mode,
    ) -> Result<RgbImage, DenoiseError> {
        filter::run(self, color, aux, mode)
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
        if code == 0 {
            return Ok(());
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
