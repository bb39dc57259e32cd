//! 8-bit PNG input and output for the MCC's images (docs/design/mcc.md §4: tagged views, collages,
//! region images; §5.6 debug pictures), through the `image` crate. Reads decode by content (a
//! mislabelled JPEG still decodes); writes go through the tracer's atomic writer, so no run leaves
//! half a PNG behind.

use crate::error::{MccError, Result};
use image::DynamicImage;
use image::codecs::png::PngEncoder;
use std::path::Path;

/// Decodes the image at `path`; errors name the file. PNG sizes past the tracer's
/// [`MAX_PIXELS`](tracer::image_io::MAX_PIXELS), or more than the file could hold, are refused
/// from the header before decoding ([`check_png_header`](tracer::image_io::check_png_header)).
pub fn read_image(path: &Path) -> Result<DynamicImage> {
    let bytes = std::fs::read(path).map_err(|e| MccError::io(path, e))?;
    let undecodable = |why: String| MccError::image(path, format!("cannot decode the image: {why}"));
    if bytes.is_empty() {
        return Err(undecodable("the file is empty (0 bytes)".to_owned()));
    }
    tracer::image_io::check_png_header(&bytes).map_err(undecodable)?;
    let reader = image::ImageReader::new(std::io::Cursor::new(&bytes))
        .with_guessed_format()
        .map_err(|e| undecodable(e.to_string()))?;
    // Every decoding failure is the file's fault here (it was read into memory already): a
    // truncated file surfaces as the decoder's I/O error "unexpected end of file".
    reader.decode().map_err(|e| undecodable(e.to_string()))
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
