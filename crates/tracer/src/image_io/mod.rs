//! Image files: linear float OpenEXR for renders and references, 8-bit sRGB PNG for previews and
//! for already-8-bit images (the collage's camera-id stamps).
//!
//! Every writer is atomic ([`crate::atomic`]): the file appears complete or not at all, even when
//! encoding fails half-way. Every reader refuses absurd sizes from the header before it
//! allocates (see [`MAX_PIXELS`]) and reports a malformed file as
//! [`TracerError::Image`](crate::TracerError::Image) naming the file and the problem, never by
//! panicking (the tests feed truncated and byte-damaged files; the exr crate did not panic on
//! thousands of them, so there is no `catch_unwind`).
//!
//! - [`write_exr`] / [`read_exr`] / [`read_exr_rgb`]: one single-part scan-line file holding the
//!   beauty image in channels `R`, `G`, `B`, each AOV as a channel-name layer (`albedo.R`,
//!   `depth.Y` …, the OpenEXR 1 layer convention every compositor reads) and string metadata as
//!   header attributes.
//! - [`write_png_srgb`], [`write_png_rgb8`], [`write_png_rgba8`], [`read_png8`], and the sRGB
//!   transfer functions [`linear_to_srgb8`] / [`srgb8_to_linear`].

mod exr_file;
mod png_file;

pub use exr_file::{Aov, ExrImage, ExrLayer, read_exr, read_exr_rgb, write_exr};
pub use png_file::{
    Png8, linear_to_srgb8, read_png8, srgb8_to_linear, write_png_rgb8, write_png_rgba8, write_png_srgb,
};

/// The most pixels (width × height) a reader accepts from a file's header: 2^28 (e.g.
/// 16384 × 16384), 3 GiB as linear RGB f32. Larger claims are refused before anything is
/// allocated, so a corrupt or hostile header cannot exhaust memory.
pub const MAX_PIXELS: u64 = 1 << 28;

/// The most channel samples (pixels × channels, summed over all layers) [`read_exr`] accepts:
/// 2^30, 4 GiB as f32.
pub const MAX_SAMPLES: u64 = 1 << 30;

/// The width and height a PNG's IHDR chunk claims, if `bytes` start like a PNG (signature, then
/// IHDR). Read by hand because the image crate only reports a PNG's size after it has found the
/// first IDAT chunk, so a header-only file with an absurd size would fail with a misleading
/// message instead of being refused for its size.
fn png_header_size(bytes: &[u8]) -> Option<(u32, u32)> {
    const SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";
    if bytes.len() < 24 || &bytes[..8] != SIGNATURE || &bytes[12..16] != b"IHDR" {
        return None;
    }
    let be32 = |at: usize| u32::from_be_bytes([bytes[at], bytes[at + 1], bytes[at + 2], bytes[at + 3]]);
    Some((be32(16), be32(20)))
}

/// Refuses a PNG whose IHDR claims a size no reader allocates for ([`check_claimed_size`]) or
/// more pixel data than the file can hold ([`check_png_data_size`]), before any decoder sees
/// it. Not a PNG: `Ok`, other checks apply. The message says what the file claims (callers
/// name the file).
pub fn check_png_header(bytes: &[u8]) -> Result<(), String> {
    let Some((width, height)) = png_header_size(bytes) else { return Ok(()) };
    check_claimed_size(width, height)?;
    check_png_data_size(bytes)
}

/// The most bytes of output one byte of a deflate stream can decode to, with margin: a 258-byte
/// match coded in 2 bits (1-bit length and distance codes) is deflate's best case, 1032:1.
const DEFLATE_MAX_EXPANSION: u128 = 1100;
/// Bytes allowed on top of [`DEFLATE_MAX_EXPANSION`] × file length, so a tiny file's bound is
/// never below a few rows of a legitimate image.
const DEFLATE_SLACK: u128 = 1024;

/// Refuses a PNG whose IHDR claims more pixel data than a file of `bytes.len()` bytes can hold
/// (a truncated or damaged file): the image crate's decoder reserves the whole claimed image as
/// soon as it finds an IDAT chunk, before it reads the data, so 50 bytes claiming 16384 × 16384
/// RGBA would cost 1 GiB. The
/// bound is the least the decompressed image data can be (`height` rows of
/// ⌈`width` × bits per pixel / 8⌉ bytes plus a filter byte each; interlaced images need at
/// least as much) against the most deflate can expand the whole file to, so no PNG that would
/// decode is refused. Not a PNG (no signature and IHDR): `Ok`, other checks apply. The message
/// says what the file claims (callers name the file).
pub fn check_png_data_size(bytes: &[u8]) -> Result<(), String> {
    let Some((width, height)) = png_header_size(bytes) else { return Ok(()) };
    let (depth, color_type) = match (bytes.get(24), bytes.get(25)) {
        (Some(&depth), Some(&color_type)) => (depth, color_type),
        _ => return Ok(()), // No depth or colour type: the decoder refuses the header itself.
    };
    let channels: u128 = match color_type {
        2 => 3,
        4 => 2,
        6 => 4,
        _ => 1, // Grey and palette; an unknown type has at least one channel too.
    };
    let bits_per_pixel = channels * u128::from(depth.max(1));
    let row_bytes = (u128::from(width) * bits_per_pixel).div_ceil(8) + 1;
    let least_data = u128::from(height) * row_bytes;
    let most_data = DEFLATE_MAX_EXPANSION * bytes.len() as u128 + DEFLATE_SLACK;
    if least_data > most_data {
        return Err(format!(
            "header claims {width} × {height} pixels but the file is only {} bytes, too short to hold \
             their {least_data} bytes of pixel data even at deflate's best compression (truncated or \
             damaged)",
            bytes.len()
        ));
    }
    Ok(())
}

/// Refuses an image size a reader will not allocate for: no pixel, or more than [`MAX_PIXELS`].
/// The message says what the file claims (callers name the file).
pub fn check_claimed_size(width: u32, height: u32) -> Result<(), String> {
    if width == 0 || height == 0 || width as u64 * height as u64 > MAX_PIXELS {
        return Err(format!("the image claims {width} × {height} pixels; 1 to {MAX_PIXELS} are accepted"));
    }
    Ok(())
}

/// Checks that an in-memory image of `width × height` holding `len` values, `per_pixel` to a
/// pixel, is consistent and writable; returns the pixel count. `what` names it in the message.
fn check_dimensions(
    width: u32,
    height: u32,
    len: usize,
    per_pixel: usize,
    what: &str,
) -> Result<usize, String> {
    if width == 0 || height == 0 {
        return Err(format!("{what} is {width} × {height}: an image file needs at least one pixel"));
    }
    let pixels = width as u64 * height as u64;
    if pixels > MAX_PIXELS {
        return Err(format!("{what} is {width} × {height}, more than the {MAX_PIXELS} pixels allowed"));
    }
    let expected = pixels as usize * per_pixel;
    if len != expected {
        return Err(format!("{what} is {width} × {height} but holds {len} values instead of {expected}"));
    }
    Ok(pixels as usize)
}
