//! 8-bit PNG input and output for the MCC's images (SPEC §4: tagged views, collages, region
//! images; §5.6 debug pictures), through the `image` crate. Reads decode by content (a mislabelled JPEG still
//! decodes); writes go through the tracer's atomic writer, so no run leaves half a PNG behind.

use crate::error::{MccError, Result};
use image::DynamicImage;
use image::codecs::png::PngEncoder;
use std::path::Path;

/// Decodes the image at `path`; errors name the file.
pub fn read_image(path: &Path) -> Result<DynamicImage> {
    let reader = image::ImageReader::open(path)
        .map_err(|e| MccError::io(path, e))?
        .with_guessed_format()
        .map_err(|e| MccError::io(path, e))?;
    reader.decode().map_err(|e| match e {
        image::ImageError::IoError(e) => MccError::io(path, e),
        other => MccError::image(path, format!("cannot decode the image: {other}")),
    })
}

/// Writes `image` as a PNG at `path`, atomically.
pub fn write_png(path: &Path, image: &DynamicImage) -> Result<()> {
    tracer::atomic::write_atomically(path, |w| {
        image.write_with_encoder(PngEncoder::new(w)).map_err(|e| match e {
            image::ImageError::IoError(e) => e,
            other => std::io::Error::other(other),
        })
    })?;
    Ok(())
}
