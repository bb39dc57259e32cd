//! The camera tag code (docs/design/mcc.md §4.4): a camera id 1 … 2^(3b) − 1 lives in the b low-order
//! bits of each 8-bit channel. Red holds the lowest b bits of the id, green the middle b, blue the
//! highest b: camera 9 with b = 2 is 00 10 01 → blue …00, green …10, red …01. Id 0 means *no
//! camera*, so a tagged pixel is never (0, 0, 0), the collage's background.

use crate::error::{MccError, Result};
use image::{DynamicImage, RgbImage, RgbaImage};
use std::path::Path;

/// A tag code with `bits` low-order bits per channel (1 ..= 8; the column's default is 2).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct TagCode {
    bits: u8,
}

impl Default for TagCode {
    fn default() -> Self {
        Self { bits: Self::DEFAULT_BITS }
    }
}

impl TagCode {
    /// The column's width: 2 bits per channel, ids 1 … 63.
    pub const DEFAULT_BITS: u8 = 2;

    /// A tag code with `bits` bits per channel; refuses widths outside 1 ..= 8.
    pub fn new(bits: u8) -> Result<Self> {
        if (1..=8).contains(&bits) {
            Ok(Self { bits })
        } else {
            Err(MccError::Tag(format!("{bits} bits per channel: must be 1 to 8")))
        }
    }

    /// Bits per channel.
    pub fn bits(self) -> u8 {
        self.bits
    }

    /// The largest camera id the code can hold, 2^(3b) − 1.
    pub fn max_id(self) -> u32 {
        (1u32 << (3 * self.bits as u32)) - 1
    }

    /// Refuses id 0 (no camera) and ids beyond [`TagCode::max_id`].
    pub fn check_id(self, id: u32) -> Result<()> {
        if id == 0 {
            return Err(MccError::Tag("camera id 0 is reserved for 'no camera'; ids start at 1".into()));
        }
        if id > self.max_id() {
            return Err(MccError::Tag(format!(
                "camera id {id} does not fit in {} bits per channel (ids 1 … {}); use more bits",
                self.bits,
                self.max_id()
            )));
        }
        Ok(())
    }

    fn mask(self) -> u8 {
        ((1u16 << self.bits) - 1) as u8
    }

    /// Writes `id` (already checked) into the low bits of `rgb`.
    #[inline]
    fn put(self, rgb: [u8; 3], id: u32) -> [u8; 3] {
        let (b, m) = (self.bits as u32, self.mask());
        let part = |k: u32| (id >> (k * b)) as u8 & m;
        [(rgb[0] & !m) | part(0), (rgb[1] & !m) | part(1), (rgb[2] & !m) | part(2)]
    }

    /// `rgb` with `id` written into its low bits.
    pub fn encode(self, rgb: [u8; 3], id: u32) -> Result<[u8; 3]> {
        self.check_id(id)?;
        Ok(self.put(rgb, id))
    }

    /// The id in the low bits of `rgb` (0 when they are all zero).
    #[inline]
    pub fn decode(self, rgb: [u8; 3]) -> u32 {
        let (b, m) = (self.bits as u32, self.mask());
        (rgb[0] & m) as u32 | ((rgb[1] & m) as u32) << b | ((rgb[2] & m) as u32) << (2 * b)
    }

    /// Tags every pixel of an RGB image with camera `id`.
    pub fn tag_rgb(self, image: &mut RgbImage, id: u32) -> Result<()> {
        self.check_id(id)?;
        for p in image.pixels_mut() {
            p.0 = self.put(p.0, id);
        }
        Ok(())
    }

    /// Tags every pixel of an RGBA image with camera `id` (alpha is left alone).
    pub fn tag_rgba(self, image: &mut RgbaImage, id: u32) -> Result<()> {
        self.check_id(id)?;
        for p in image.pixels_mut() {
            let [r, g, b, a] = p.0;
            let [r, g, b] = self.put([r, g, b], id);
            p.0 = [r, g, b, a];
        }
        Ok(())
    }
}

/// The standalone tagger: reads `input` (any image the `image` crate decodes; deeper images are
/// reduced to 8 bits, alpha is kept), tags it with `camera` using `bits` bits per channel and
/// writes an 8-bit PNG to `output` atomically.
pub fn tag_png(input: &Path, camera: u32, bits: u8, output: &Path) -> Result<()> {
    let code = TagCode::new(bits)?;
    code.check_id(camera)?;
    let image = crate::png::read_image(input)?;
    let tagged = if image.color().has_alpha() {
        let mut rgba = image.to_rgba8();
        code.tag_rgba(&mut rgba, camera)?;
        DynamicImage::ImageRgba8(rgba)
    } else {
        let mut rgb = image.to_rgb8();
        code.tag_rgb(&mut rgb, camera)?;
        DynamicImage::ImageRgb8(rgb)
    };
    crate::png::write_png(output, &tagged)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::scratch_dir;

    #[test]
    fn camera_nine_with_two_bits_is_the_spec_example() {
        let code = TagCode::default();
        let [r, g, b] = code.encode([0xFF, 0xFF, 0xFF], 9).unwrap();
        assert_eq!((r & 3, g & 3, b & 3), (0b01, 0b10, 0b00));
        assert_eq!((r >> 2, g >> 2, b >> 2), (0x3F, 0x3F, 0x3F), "high bits kept");
        assert_eq!(code.decode([r, g, b]), 9);
        // The column's pitch-black pixel of camera 6 becomes (2, 1, 0).
        assert_eq!(code.encode([0, 0, 0], 6).unwrap(), [2, 1, 0]);
        assert_eq!(code.max_id(), 63);
    }

    #[test]
    fn every_id_round_trips_for_every_width() {
        for bits in 1..=8u8 {
            let code = TagCode::new(bits).unwrap();
            assert_eq!(code.max_id(), (1u32 << (3 * bits)) - 1);
            let step = (code.max_id() / 5000).max(1);
            let ids = (1..=code.max_id()).step_by(step as usize).chain([code.max_id()]);
            for (k, id) in ids.enumerate() {
                let base = [(k * 37) as u8, (k * 101) as u8, (k * 13) as u8];
                let px = code.encode(base, id).unwrap();
                assert_eq!(code.decode(px), id, "bits {bits} id {id}");
                assert_ne!(px, [0, 0, 0], "a tagged pixel is never background");
                let keep = !(((1u16 << bits) - 1) as u8);
                assert_eq!(
                    [px[0] & keep, px[1] & keep, px[2] & keep],
                    [base[0] & keep, base[1] & keep, base[2] & keep]
                );
            }
            assert!(code.encode([0; 3], 0).is_err());
            assert!(code.encode([0; 3], code.max_id() + 1).is_err());
        }
        assert!(TagCode::new(0).is_err());
        assert!(TagCode::new(9).is_err());
    }

    #[test]
    fn tags_a_png_file() {
        let dir = scratch_dir("tag");
        let input = dir.join("in.png");
        let img = RgbImage::from_fn(5, 4, |x, y| image::Rgb([x as u8 * 50, y as u8 * 60, 200]));
        crate::png::write_png(&input, &DynamicImage::ImageRgb8(img)).unwrap();
        let output = dir.join("out.png");
        tag_png(&input, 9, 2, &output).unwrap();
        let out = crate::png::read_image(&output).unwrap().to_rgb8();
        assert!(out.pixels().all(|p| TagCode::default().decode(p.0) == 9));
        let err = tag_png(&input, 64, 2, &output).unwrap_err().to_string();
        assert!(err.contains("64") && err.contains("1 … 63"), "{err}");
        assert!(tag_png(&input, 0, 2, &output).unwrap_err().to_string().contains("reserved"));
        assert!(tag_png(&input, 1, 9, &output).is_err());
        std::fs::write(dir.join("junk.png"), b"not a png").unwrap();
        let err = tag_png(&dir.join("junk.png"), 1, 2, &output).unwrap_err().to_string();
        assert!(err.contains("junk.png"), "{err}");
        let err = tag_png(&dir.join("missing.png"), 1, 2, &output).unwrap_err().to_string();
        assert!(err.contains("missing.png"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
