//! Collage decoding (docs/design/mcc.md §4.5): an 8-bit RGB or RGBA image at the views' resolution. A
//! pixel whose alpha is 0, or whose RGB is exactly (0, 0, 0), is background (id 0); every other
//! pixel carries its camera id in the tag bits ([`crate::tag`]).
//!
//! Bad collages get a report, never a silent guess: a non-background pixel whose id is 0 or names a
//! camera without a ray file is a *stray* — almost always an antialiased selection edge, whose
//! blended colours lost the tag bits. Strays are counted and the first few located; the default
//! policy refuses the collage, [`StrayPolicy::Background`] treats strays as background.
//!
//! Pixel formats: 8-bit RGB/RGBA as they are; palette PNGs arrive expanded to exact RGB(A) by the
//! decoder; 16-bit RGB(A) only when every colour value is an exact up-conversion of an 8-bit value
//! (v = 257·k, what editors write when they widen an 8-bit image), else refused; greyscale and
//! floating-point images cannot hold three independent tag fields and are refused.

use crate::error::{MccError, Result};
use crate::tag::TagCode;
use image::DynamicImage;
use std::collections::BTreeSet;
use std::path::Path;

// The stray report is the collage reader's, kept in a leaf the error type can hold; named here
// too, where callers met it first.
pub use crate::stray::{LISTED_IDS, SOLID_BLOCK, STRAY_LOCATIONS, StrayHints, StrayPolicy, StrayReport};

/// How to decode a collage.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CollageOptions {
    /// The tag code the views were tagged with.
    pub tag: TagCode,
    /// What to do with stray pixels.
    pub strays: StrayPolicy,
    /// How the caller names the settings a stray report suggests.
    pub hints: StrayHints,
}

/// A decoded collage: one camera id per pixel (0 = background), row-major.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Collage {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Camera id per pixel, `y · width + x`; 0 is background.
    pub ids: Vec<u32>,
}

impl Collage {
    /// A collage from its ids; `ids` must hold `width × height` entries.
    pub fn new(width: u32, height: u32, ids: Vec<u32>) -> Result<Self> {
        if width == 0 || height == 0 || ids.len() as u64 != width as u64 * height as u64 {
            return Err(MccError::input(
                "collage",
                format!("{} ids for a {width}x{height} image", ids.len()),
            ));
        }
        Ok(Self { width, height, ids })
    }

    /// The id at (x, y).
    #[inline]
    pub fn id(&self, x: u32, y: u32) -> u32 {
        self.ids[y as usize * self.width as usize + x as usize]
    }

    /// The camera ids present, ascending.
    pub fn cameras(&self) -> BTreeSet<u32> {
        let mut seen = BTreeSet::new();
        let mut last = 0;
        for &id in &self.ids {
            // Runs of one id are the rule: skip the set look-up while the id repeats.
            if id != last && id != 0 {
                seen.insert(id);
            }
            last = id;
        }
        seen
    }

    /// Refuses a collage whose size differs from `(width, height)` (the views'), naming `path`.
    pub fn check_size(&self, path: &Path, width: u32, height: u32, expected_from: &str) -> Result<()> {
        if (self.width, self.height) != (width, height) {
            return Err(MccError::SizeMismatch {
                path: path.into(),
                what: "the collage".into(),
                found: (self.width, self.height),
                expected_from: expected_from.into(),
                expected: (width, height),
            });
        }
        Ok(())
    }

    /// Reads and decodes the collage at `path`. `known` lists the cameras that have ray files
    /// (`None`: accept any id). Returns the collage and the strays it had (empty unless the policy
    /// treats them as background; with [`StrayPolicy::Refuse`] strays are an error).
    pub fn load(
        path: &Path,
        known: Option<&BTreeSet<u32>>,
        options: CollageOptions,
    ) -> Result<(Self, StrayReport)> {
        let image = crate::png::read_image(path)?;
        Self::decode(&image, path, known, options).map_err(|e| match e {
            MccError::StrayPixels { path, mut report } => {
                // A JPEG never keeps tags: say so rather than list what its noise decodes to.
                let mut head = [0u8; 3];
                let read =
                    std::fs::File::open(&path).and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head));
                report.jpeg = read.is_ok() && head == [0xFF, 0xD8, 0xFF];
                MccError::StrayPixels { path, report }
            }
            other => other,
        })
    }

    /// Decodes an image already in memory; `path` names it in errors.
    pub fn decode(
        image: &DynamicImage,
        path: &Path,
        known: Option<&BTreeSet<u32>>,
        options: CollageOptions,
    ) -> Result<(Self, StrayReport)> {
        let (width, height) = (image.width(), image.height());
        let n = width as usize * height as usize;
        if n == 0 {
            return Err(MccError::image(path, "the collage is empty (0 pixels)"));
        }
        let mut ids = Vec::with_capacity(n);
        let mut strays = StrayReport::new(options.strays, options.hints);
        let code = options.tag;
        // (colour, alpha is 0) → (id, stray): colours come in runs, so remember the last answer
        // instead of looking the id up in `known` for every pixel.
        let mut last: Option<([u8; 3], bool, u32, bool)> = None;
        let mut push = |rgb: [u8; 3], alpha_zero: bool| {
            let (id, stray) = match last {
                Some((c, a, id, stray)) if c == rgb && a == alpha_zero => (id, stray),
                _ => {
                    let background = alpha_zero || rgb == [0, 0, 0];
                    let id = if background { 0 } else { code.decode(rgb) };
                    let usable = id != 0 && known.is_none_or(|set| set.contains(&id));
                    let stray = !background && !usable;
                    last = Some((rgb, alpha_zero, id, stray));
                    (id, stray)
                }
            };
            if id != 0 || stray {
                strays.foreground += 1;
            }
            if stray {
                let k = ids.len() as u32;
                strays.add(k % width, k / width, id);
                ids.push(0);
            } else {
                ids.push(id);
            }
        };
        match image {
            DynamicImage::ImageRgb8(img) => img.pixels().for_each(|p| push(p.0, false)),
            DynamicImage::ImageRgba8(img) => {
                img.pixels().for_each(|p| push([p.0[0], p.0[1], p.0[2]], p.0[3] == 0))
            }
            DynamicImage::ImageRgb16(_) | DynamicImage::ImageRgba16(_) => {
                let alpha = image.color().has_alpha();
                let rgba = image.to_rgba16();
                for (k, p) in rgba.pixels().enumerate() {
                    let [r, g, b, a] = p.0;
                    if let Some(v) = [r, g, b].into_iter().find(|v| v % 257 != 0) {
                        let (x, y) = (k as u32 % width, k as u32 / width);
                        return Err(MccError::image(
                            path,
                            format!(
                                "16-bit collage: pixel ({x}, {y}) has the value {v}, which is no 8-bit \
                                 value widened (257·k), so its tag bits are lost; save the collage as \
                                 8-bit RGB or RGBA"
                            ),
                        ));
                    }
                    push([(r / 257) as u8, (g / 257) as u8, (b / 257) as u8], alpha && a == 0);
                }
            }
            DynamicImage::ImageLuma8(_)
            | DynamicImage::ImageLumaA8(_)
            | DynamicImage::ImageLuma16(_)
            | DynamicImage::ImageLumaA16(_) => {
                return Err(MccError::image(
                    path,
                    "a greyscale image cannot carry camera tags (they need separate red, green and \
                     blue bits); save the collage as 8-bit RGB or RGBA",
                ));
            }
            other => {
                return Err(MccError::image(
                    path,
                    format!(
                        "pixel format {:?} cannot carry exact tag bits; save the collage as 8-bit RGB or RGBA",
                        other.color()
                    ),
                ));
            }
        }
        if let Some(known) = known.filter(|_| strays.nearly_all()) {
            strays.fitting_bits = fitting_bits(image, known, code);
        }
        if !strays.is_empty() && options.strays == StrayPolicy::Refuse {
            return Err(MccError::StrayPixels { path: path.into(), report: Box::new(strays) });
        }
        Ok((Self { width, height, ids }, strays))
    }
}

/// Another tag width than `given`'s at which at least 90 % of `image`'s non-background pixels
/// name a camera in `known`, if any: the width the views were tagged with. (Only asked when
/// nearly every pixel is a stray, so the extra passes cost only a refused collage.)
fn fitting_bits(image: &DynamicImage, known: &BTreeSet<u32>, given: TagCode) -> Option<u8> {
    let rgba = image.to_rgba8();
    let foreground: Vec<[u8; 3]> = rgba
        .pixels()
        .filter(|p| p.0[3] != 0 && p.0[..3] != [0, 0, 0])
        .map(|p| [p.0[0], p.0[1], p.0[2]])
        .collect();
    (1..=8u8).filter(|&b| b != given.bits()).find(|&b| {
        let code = TagCode::new(b).expect("1 ..= 8 bits");
        let named = foreground.iter().filter(|&&rgb| known.contains(&code.decode(rgb))).count();
        !foreground.is_empty() && named * 10 >= foreground.len() * 9
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{ImageBuffer, Rgb, RgbImage, Rgba, RgbaImage};
    use std::collections::BTreeMap;
    type Rgb16Image = ImageBuffer<Rgb<u16>, Vec<u16>>;

    fn known(ids: &[u32]) -> BTreeSet<u32> {
        ids.iter().copied().collect()
    }

    /// 6 × 3: camera 1 on the left, camera 2 on the right, background in the middle column pair.
    fn tagged() -> RgbImage {
        let code = TagCode::default();
        RgbImage::from_fn(6, 3, |x, _| match x {
            0 | 1 => Rgb(code.encode([200, 100, 0], 1).unwrap()),
            4 | 5 => Rgb(code.encode([0, 0, 0], 2).unwrap()),
            _ => Rgb([0, 0, 0]),
        })
    }

    #[test]
    fn decodes_ids_and_background() {
        let img = DynamicImage::ImageRgb8(tagged());
        let (c, strays) =
            Collage::decode(&img, Path::new("c.png"), Some(&known(&[1, 2])), Default::default()).unwrap();
        assert!(strays.is_empty());
        assert_eq!(&c.ids[..6], &[1, 1, 0, 0, 2, 2]);
        assert_eq!(c.cameras(), known(&[1, 2]));
        // Alpha 0 is background whatever the colour.
        let mut rgba = DynamicImage::ImageRgb8(tagged()).to_rgba8();
        rgba.put_pixel(0, 0, Rgba([201, 101, 1, 0]));
        let (c, _) =
            Collage::decode(&DynamicImage::ImageRgba8(rgba), Path::new("c.png"), None, Default::default())
                .unwrap();
        assert_eq!(c.id(0, 0), 0);
        assert_eq!(c.id(1, 0), 1);
    }

    #[test]
    fn strays_are_counted_located_and_refused_by_default() {
        let mut img = tagged();
        img.put_pixel(2, 1, Rgb([100, 100, 100])); // id 0: a blended edge
        img.put_pixel(3, 2, Rgb(TagCode::default().encode([9, 9, 9], 7).unwrap())); // no ray file
        img.put_pixel(3, 0, Rgb([4, 8, 12])); // id 0 again
        let img = DynamicImage::ImageRgb8(img);
        let err = Collage::decode(&img, Path::new("cut.png"), Some(&known(&[1, 2])), Default::default())
            .unwrap_err();
        let MccError::StrayPixels { report, .. } = &err else { panic!("{err}") };
        assert_eq!(report.count, 3);
        assert_eq!(report.zero_id, 2);
        assert_eq!(report.unknown_ids, BTreeMap::from([(7, 1)]));
        assert_eq!(report.first, vec![(3, 0), (2, 1), (3, 2)]);
        let msg = err.to_string();
        for want in
            ["cut.png", "3 non-background", "(3, 0), (2, 1), (3, 2)", "antialiased selection edge", "7 ×1"]
        {
            assert!(msg.contains(want), "{msg:?} lacks {want:?}");
        }
        let options = CollageOptions { strays: StrayPolicy::Background, ..Default::default() };
        let (c, report) =
            Collage::decode(&img, Path::new("cut.png"), Some(&known(&[1, 2])), options).unwrap();
        assert_eq!(report.count, 3);
        assert_eq!((c.id(2, 1), c.id(3, 2), c.id(3, 0)), (0, 0, 0));
        // Many strays (beside tagged pixels: a collage of nothing but strays is untagged, and
        // told so without locations): only the first few are located.
        let one = TagCode::default().encode([90, 90, 90], 1).unwrap();
        let grey = DynamicImage::ImageRgb8(RgbImage::from_fn(30, 10, |x, _| {
            Rgb(if x < 10 { [4, 4, 4] } else { one })
        }));
        let err = Collage::decode(&grey, Path::new("g.png"), None, Default::default()).unwrap_err();
        let MccError::StrayPixels { report, .. } = &err else { panic!("{err}") };
        assert_eq!((report.count, report.first.len()), (100, STRAY_LOCATIONS));
        assert!(err.to_string().contains(", …"));
    }

    #[test]
    fn stray_messages_name_the_likely_cause_and_the_remedy() {
        let code = TagCode::default();
        let hints = StrayHints {
            ignore: "--ignore-strays",
            tag_bits: "--tag-bits",
            tagged_views: "`render --tag`",
            layered_views: "`render --layers`",
        };
        let refuse = CollageOptions { hints, ..Default::default() };
        let ignore = CollageOptions { strays: StrayPolicy::Background, ..refuse };
        let decode = |img: RgbImage, options| {
            let img = DynamicImage::ImageRgb8(img);
            Collage::decode(&img, Path::new("c.png"), Some(&known(&[1])), options)
        };
        // A few blended pixels at a cut: the edge is blamed, the flag named.
        let mut edge = RgbImage::from_pixel(20, 20, Rgb(code.encode([90, 90, 90], 1).unwrap()));
        edge.put_pixel(3, 3, Rgb([100, 100, 100]));
        let msg = decode(edge.clone(), refuse).unwrap_err().to_string();
        assert!(
            msg.contains("antialiased selection edge")
                && msg.ends_with("give --ignore-strays to treat such pixels as background"),
            "{msg}"
        );
        // Once the strays are ignored, the warning suggests nothing.
        let (_, report) = decode(edge, ignore).unwrap();
        assert!(!report.to_string().contains("--ignore-strays"), "{report}");
        // A solid block of a camera without a ray file is that, not an edge.
        let block = RgbImage::from_fn(20, 20, |x, _| {
            Rgb(code.encode([90, 90, 90], if x < 10 { 1 } else { 5 }).unwrap())
        });
        let msg = decode(block, refuse).unwrap_err().to_string();
        assert!(
            msg.contains("camera(s) 5 cover whole areas but have no ray file")
                && !msg.contains("antialiased"),
            "{msg}"
        );
        // Nearly every pixel a stray, but read at 3 bits they name camera 9: the views were
        // tagged with 3 bits, and the message says so.
        let wide = TagCode::new(3).unwrap();
        let other =
            DynamicImage::ImageRgb8(RgbImage::from_pixel(20, 20, Rgb(wide.encode([90, 90, 90], 9).unwrap())));
        let msg =
            Collage::decode(&other, Path::new("c.png"), Some(&known(&[9])), refuse).unwrap_err().to_string();
        assert!(
            msg.contains("at 3 bits per channel they name cameras with ray files")
                && msg.contains("give --tag-bits 3"),
            "{msg}"
        );
        // Noise (an untagged picture): two lines saying so and what works, a few ids at most,
        // no advice about tag widths or views to render.
        let mut state = 12345u32;
        let noise = RgbImage::from_fn(32, 32, |_, _| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let [a, b, c, _] = state.to_le_bytes();
            Rgb([a | 1, b, c])
        });
        let msg = decode(noise, refuse).unwrap_err().to_string();
        let lines: Vec<&str> = msg.lines().collect();
        assert_eq!(lines.len(), 2, "{msg}");
        assert!(lines[0].contains("its pixels carry no camera tags") && lines[0].contains("more)"), "{msg}");
        assert!(lines[1].contains("`render --tag`") && lines[1].contains("`render --layers`"), "{msg}");
        assert!(msg.matches('×').count() <= LISTED_IDS, "{msg}");
        assert!(!msg.contains("--tag-bits") && !msg.contains("cover whole areas"), "{msg}");
    }

    #[test]
    fn sixteen_bit_only_when_exactly_widened() {
        let eight = tagged();
        let wide = Rgb16Image::from_fn(6, 3, |x, y| {
            let p = eight.get_pixel(x, y).0;
            Rgb([p[0] as u16 * 257, p[1] as u16 * 257, p[2] as u16 * 257])
        });
        let (c, _) = Collage::decode(
            &DynamicImage::ImageRgb16(wide.clone()),
            Path::new("w.png"),
            None,
            Default::default(),
        )
        .unwrap();
        let (c8, _) =
            Collage::decode(&DynamicImage::ImageRgb8(eight), Path::new("e.png"), None, Default::default())
                .unwrap();
        assert_eq!(c, c8);
        let mut off = wide;
        off.put_pixel(4, 2, Rgb([257 * 3 + 1, 0, 0]));
        let err =
            Collage::decode(&DynamicImage::ImageRgb16(off), Path::new("w.png"), None, Default::default())
                .unwrap_err();
        let msg = err.to_string();
        assert!(msg.contains("w.png") && msg.contains("(4, 2)") && msg.contains("8-bit"), "{msg}");
    }

    #[test]
    fn grey_and_float_images_are_refused_and_palettes_decode() {
        let grey = DynamicImage::ImageLuma8(image::GrayImage::new(4, 4));
        assert!(
            Collage::decode(&grey, Path::new("g.png"), None, Default::default())
                .unwrap_err()
                .to_string()
                .contains("greyscale")
        );
        let float = DynamicImage::ImageRgb32F(image::Rgb32FImage::new(4, 4));
        assert!(Collage::decode(&float, Path::new("f.exr"), None, Default::default()).is_err());
        // An indexed PNG decodes to exact RGB: write one by hand with the png crate's encoder path.
        let dir = crate::test_util::scratch_dir("collage-palette");
        let path = dir.join("palette.png");
        let code = TagCode::default();
        let palette = [[0u8, 0, 0], code.encode([120, 40, 200], 5).unwrap()];
        write_indexed_png(&path, 3, 2, &palette, &[0, 1, 1, 1, 0, 0]);
        let (c, _) = Collage::load(&path, None, Default::default()).unwrap();
        assert_eq!(c.ids, vec![0, 5, 5, 5, 0, 0]);
        let empty = RgbaImage::new(0, 0);
        assert!(
            Collage::decode(&DynamicImage::ImageRgba8(empty), Path::new("e.png"), None, Default::default())
                .is_err()
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// A minimal 8-bit indexed PNG (so the palette path is tested without a png dev-dependency).
    fn write_indexed_png(path: &Path, w: u32, h: u32, palette: &[[u8; 3]], indices: &[u8]) {
        fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
            out.extend_from_slice(&(data.len() as u32).to_be_bytes());
            let start = out.len();
            out.extend_from_slice(kind);
            out.extend_from_slice(data);
            let crc = crc32(&out[start..]);
            out.extend_from_slice(&crc.to_be_bytes());
        }
        fn crc32(bytes: &[u8]) -> u32 {
            let mut c = !0u32;
            for &b in bytes {
                c ^= b as u32;
                for _ in 0..8 {
                    c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
                }
            }
            !c
        }
        fn adler32(bytes: &[u8]) -> u32 {
            let (mut a, mut b) = (1u32, 0u32);
            for &x in bytes {
                a = (a + x as u32) % 65521;
                b = (b + a) % 65521;
            }
            (b << 16) | a
        }
        let mut raw = Vec::new();
        for row in indices.chunks(w as usize) {
            raw.push(0); // filter: none
            raw.extend_from_slice(row);
        }
        // zlib stream with one stored (uncompressed) block.
        let mut z = vec![0x78, 0x01, 0x01];
        z.extend_from_slice(&(raw.len() as u16).to_le_bytes());
        z.extend_from_slice(&(!(raw.len() as u16)).to_le_bytes());
        z.extend_from_slice(&raw);
        z.extend_from_slice(&adler32(&raw).to_be_bytes());
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = Vec::new();
        ihdr.extend_from_slice(&w.to_be_bytes());
        ihdr.extend_from_slice(&h.to_be_bytes());
        ihdr.extend_from_slice(&[8, 3, 0, 0, 0]);
        chunk(&mut png, b"IHDR", &ihdr);
        chunk(&mut png, b"PLTE", &palette.concat());
        chunk(&mut png, b"IDAT", &z);
        chunk(&mut png, b"IEND", &[]);
        std::fs::write(path, png).unwrap();
    }
}
