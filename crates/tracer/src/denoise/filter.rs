//! One picture through OIDN's `RT` filter: inputs made finite and in range, the auxiliaries
//! prefiltered when the settings say so, the beauty filtered, the output made finite.

use super::{DenoiseError, Denoiser, Guide, Settings};
use crate::image::RgbImage;
use crate::render::Progress;
use glam::Vec3;
use std::ffi::{CStr, c_int, c_void};

/// The auxiliary images that guide the filter: first-hit albedo (0..1) and shading normal
/// (−1..1), the same size as the beauty.
#[derive(Clone, Copy, Debug)]
pub struct Aux<'a> {
    /// Mean first-hit base colour.
    pub albedo: &'a RgbImage,
    /// Mean first-hit shading normal.
    pub normal: &'a RgbImage,
}

/// `OIDN_FORMAT_FLOAT3`: three packed f32 per pixel, glam's `Vec3` layout.
const FORMAT_FLOAT3: c_int = 3;

/// Denoises `color` (see [`Denoiser::denoise`]).
pub(super) fn run(
    denoiser: &Denoiser,
    color: &RgbImage,
    aux: Option<Aux<'_>>,
    settings: Settings,
    progress: &dyn Progress,
) -> Result<RgbImage, DenoiseError> {
    let (w, h) = (color.width, color.height);
    if color.pixels.len() != w as usize * h as usize {
        return Err(DenoiseError::Input(format!("a {w}×{h} image holds {} pixels", color.pixels.len())));
    }
    if let Some(a) = aux {
        for (name, image) in [("albedo", a.albedo), ("normal", a.normal)] {
            if (image.width, image.height, image.pixels.len()) != (w, h, color.pixels.len()) {
                return Err(DenoiseError::Input(format!(
                    "the {name} image is {}×{}, the picture {w}×{h}",
                    image.width, image.height
                )));
            }
        }
    }
    if color.pixels.is_empty() {
        return Ok(color.clone());
    }
    let mut input = sanitized(&color.pixels, 0.0, f32::MAX);
    let quality = settings.quality.oidn();
    let mut output = vec![Vec3::ZERO; input.len()];
    match aux {
        None => execute(
            denoiser,
            &[(c"color", input.as_mut_ptr()), (c"output", output.as_mut_ptr())],
            (w, h),
            (false, quality),
            progress,
        )?,
        Some(a) => {
            let mut albedo = sanitized(&a.albedo.pixels, 0.0, 1.0);
            let mut normal = sanitized(&a.normal.pixels, -1.0, 1.0);
            let clean = settings.guide != Guide::AsRendered;
            if settings.guide == Guide::Prefiltered {
                // OIDN's advice for noisy auxiliaries: each filtered in place by the same filter
                // type alone, then the beauty filtered with `cleanAux`.
                for (name, aux) in [(c"albedo", albedo.as_mut_ptr()), (c"normal", normal.as_mut_ptr())] {
                    execute(denoiser, &[(name, aux), (c"output", aux)], (w, h), (false, quality), progress)?;
                }
            }
            let images = [
                (c"color", input.as_mut_ptr()),
                (c"albedo", albedo.as_mut_ptr()),
                (c"normal", normal.as_mut_ptr()),
                (c"output", output.as_mut_ptr()),
            ];
            execute(denoiser, &images, (w, h), (clean, quality), progress)?;
        }
    }
    // The filter's output is finite for finite input; should a pixel not be, it keeps its
    // (finite) input rather than carry NaN into a file.
    for (out, raw) in output.iter_mut().zip(&input) {
        if !out.is_finite() {
            *out = *raw;
        }
        *out = out.max(Vec3::ZERO);
    }
    Ok(RgbImage { width: w, height: h, pixels: output })
}

/// `pixels` with every channel clamped to `lo..=hi` and NaN made 0 (infinities clamp).
fn sanitized(pixels: &[Vec3], lo: f32, hi: f32) -> Vec<Vec3> {
    let fix = |c: f32| if c.is_nan() { 0.0 } else { c.clamp(lo, hi) };
    pixels.iter().map(|p| Vec3::new(fix(p.x), fix(p.y), fix(p.z))).collect()
}

/// What makes two filter runs able to share one OIDN filter: which images it takes, their size,
/// `cleanAux` and the quality. A filter's creation and first commit build its network and load
/// its weights (OIDN: "an expensive operation"); re-pointing its images and committing again is
/// cheap, so the device keeps its filters ([`FilterCache`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct FilterKey {
    names: u64,
    size: (u32, u32),
    clean_aux: bool,
    quality: c_int,
}

/// A device's filters by [`FilterKey`], the most recently used last; at most [`FilterCache::MAX`].
#[derive(Default)]
pub(super) struct FilterCache(Vec<(FilterKey, usize)>);

impl FilterCache {
    /// Filters kept: a final's three and a preview's, at two sizes.
    const MAX: usize = 8;

    /// Releases every filter (the device is going).
    pub(super) fn release_all(&mut self, d: &Denoiser) {
        for (_, filter) in self.0.drain(..) {
            // SAFETY: a filter this cache created and owns, released once.
            unsafe { (d.api.release_filter)(filter as *mut c_void) };
        }
    }
}

/// Runs an `RT` filter over the shared `images` (name, `w × h` float3 pixels) with `hdr` on for
/// a beauty, `cleanAux` as given, at `quality`: the device's cached filter for these settings,
/// or a new one; `progress` can cancel it.
fn execute(
    d: &Denoiser,
    images: &[(&CStr, *mut Vec3)],
    (w, h): (u32, u32),
    (clean_aux, quality): (bool, c_int),
    progress: &dyn Progress,
) -> Result<(), DenoiseError> {
    if progress.cancelled() {
        return Err(DenoiseError::Cancelled);
    }
    let api = &d.api;
    let names = images
        .iter()
        .fold(0u64, |acc, (name, _)| acc.wrapping_mul(31).wrapping_add(name.to_bytes()[0] as u64));
    let key = FilterKey { names, size: (w, h), clean_aux, quality };
    // One filter run at a time per device (OIDN serialises them anyway); the lock also guards
    // the cache.
    let mut cache = d.filters.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    let cached = cache.0.iter().position(|(k, _)| *k == key).map(|i| cache.0.remove(i).1);
    let filter = match cached {
        Some(f) => f as *mut c_void,
        None => {
            // SAFETY: a live device; the type is a NUL-terminated C string.
            let filter = unsafe { (api.new_filter)(d.device, c"RT".as_ptr()) };
            if filter.is_null() {
                d.check()?;
                return Err(DenoiseError::Oidn {
                    origin: api.origin.clone(),
                    message: "no RT filter".into(),
                });
            }
            let is_beauty = images.iter().any(|(name, _)| *name == c"color");
            // SAFETY: a live filter; the names are NUL-terminated C strings.
            unsafe {
                if is_beauty {
                    (api.set_filter_bool)(filter, c"hdr".as_ptr(), true);
                    (api.set_filter_bool)(filter, c"cleanAux".as_ptr(), clean_aux);
                }
                (api.set_filter_int)(filter, c"quality".as_ptr(), quality);
            }
            filter
        }
    };
    cache.0.push((key, filter as usize));
    if cache.0.len() > FilterCache::MAX {
        let (_, oldest) = cache.0.remove(0);
        // SAFETY: a filter the cache owned, now dropped from it, released once.
        unsafe { (api.release_filter)(oldest as *mut c_void) };
    }
    let stride = std::mem::size_of::<Vec3>();
    // SAFETY: every pointer is the start of a live `w × h` Vec3 buffer (12 bytes a pixel, packed,
    // the layout of OIDN_FORMAT_FLOAT3) that outlives the filter's execution below (the filter
    // keeps the pointers, but only reads them when executed, and every run sets them afresh);
    // the names are NUL-terminated C strings.
    unsafe {
        for (name, pixels) in images {
            (api.set_shared_filter_image)(
                filter,
                name.as_ptr(),
                pixels.cast::<c_void>(),
                FORMAT_FLOAT3,
                w as usize,
                h as usize,
                0,
                stride,
                stride * w as usize,
            );
        }
        (api.commit_filter)(filter);
    }
    d.check()?;
    // The monitor's user pointer is `&progress` (a pointer to the fat `&dyn` pointer), live for
    // the execution; it is cleared afterwards, so a cached filter never keeps a stale one.
    let user = std::ptr::from_ref(&progress).cast_mut().cast::<c_void>();
    // SAFETY: a committed filter whose images are live (see above); `monitor` matches
    // `OIDNProgressMonitorFunction` and reads `user` only during this execution.
    unsafe {
        (api.set_filter_progress_monitor_function)(filter, Some(monitor), user);
        (api.execute_filter)(filter);
        (api.set_filter_progress_monitor_function)(filter, None, std::ptr::null_mut());
    }
    d.check()
}

/// OIDN's progress callback: `false` (cancel) once the caller's progress is cancelled.
unsafe extern "C" fn monitor(user: *mut c_void, _done: f64) -> bool {
    // SAFETY: `user` is the `&&dyn Progress` that `execute` passes, live while it executes.
    let progress = unsafe { *user.cast::<&dyn Progress>() };
    !progress.cancelled()
}
