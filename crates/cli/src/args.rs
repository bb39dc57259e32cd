//! Value parsers for command-line arguments: vectors, resolutions, frame ranges, shutter
//! intervals, keys and ray-file encodings.

use glam::{UVec2, Vec3};
use std::ops::RangeInclusive;
use std::path::PathBuf;
use std::str::FromStr;

/// A 3-vector written `x,y,z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3Arg(pub Vec3);

/// A `--sky` radiance: `grey` (Blender's default world), one number (a grey of that radiance)
/// or `R,G,B`; finite and non-negative.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkyArg(pub Vec3);

impl FromStr for SkyArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let v = match s.trim() {
            "grey" | "gray" => Vec3::splat(tracer::job::SceneSetup::BLENDER_GREY_SKY),
            t if t.contains(',') => t.parse::<Vec3Arg>()?.0,
            t => {
                let x = t.parse::<f32>().map_err(|_| {
                    format!(
                        "'{s}' is not a sky: give grey, a radiance (like 0.5) or R,G,B (like 0.4,0.5,0.6)"
                    )
                })?;
                Vec3::splat(x)
            }
        };
        if !(v.is_finite() && v.min_element() >= 0.0) {
            return Err(format!("'{s}': a sky's radiance must be finite and non-negative"));
        }
        Ok(Self(v))
    }
}

impl FromStr for Vec3Arg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(format!("'{s}' is not three comma-separated numbers (like 1,2.5,-3)"));
        }
        let mut v = [0.0f32; 3];
        for (slot, p) in v.iter_mut().zip(&parts) {
            *slot = p.parse::<f32>().map_err(|_| format!("'{p}' in '{s}' is not a number"))?;
            if !slot.is_finite() {
                return Err(format!("'{p}' in '{s}' is not finite"));
            }
        }
        Ok(Self(Vec3::from_array(v)))
    }
}

/// An image size written `WIDTHxHEIGHT`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution(pub UVec2);

impl FromStr for Resolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (w, h) =
            s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (like 640x360)"))?;
        let parse =
            |v: &str| v.trim().parse::<u32>().map_err(|_| format!("'{v}' in '{s}' is not a whole number"));
        let (w, h) = (parse(w)?, parse(h)?);
        if w == 0 || h == 0 {
            return Err(format!("'{s}' has a zero dimension"));
        }
        Ok(Self(UVec2::new(w, h)))
    }
}

impl std::fmt::Display for Resolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.0.x, self.0.y)
    }
}

/// An inclusive range of frames written `A..=B`, or one frame `A`. `A..B` is refused, naming
/// both readings: a user writing `5..12` may mean frame 12 included or not.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameRange {
    /// The first frame.
    pub first: u32,
    /// The last frame (inclusive).
    pub last: u32,
}

impl FrameRange {
    /// The frames as a range.
    pub fn range(self) -> RangeInclusive<u32> {
        self.first..=self.last
    }

    /// How many frames the range holds.
    pub fn len(self) -> u64 {
        (self.last - self.first) as u64 + 1
    }
}

impl FromStr for FrameRange {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let frame = |v: &str| {
            v.trim().parse::<u32>().map_err(|_| format!("'{v}' in '{s}' is not a frame number (0, 1, 2 …)"))
        };
        let (first, last) = if let Some((a, b)) = s.split_once("..=") {
            (frame(a)?, frame(b)?)
        } else if let Some((a, b)) = s.split_once("..") {
            let (a, b) = (frame(a)?, frame(b)?);
            let without =
                if b > a { format!(" or {a}..={} to stop before it", b - 1) } else { String::new() };
            return Err(format!(
                "'{s}' is ambiguous: write {a}..={b} to include frame {b}{without} (FIRST..=LAST, both \
                 included; or one frame F)"
            ));
        } else {
            let f = frame(s)?;
            (f, f)
        };
        if last < first {
            return Err(format!("'{s}' runs backwards: give FIRST..=LAST with FIRST ≤ LAST"));
        }
        Ok(Self { first, last })
    }
}

impl std::fmt::Display for FrameRange {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}..={}", self.first, self.last)
    }
}

/// A shutter interval `OPEN..CLOSE` in fractions of a frame (like 0..0.5), 0 ≤ OPEN ≤ CLOSE ≤ 1.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shutter {
    /// When the shutter opens, after the frame's start.
    pub open: f32,
    /// When it closes.
    pub close: f32,
}

impl FromStr for Shutter {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (a, b) = s.split_once("..").ok_or_else(|| format!("'{s}' is not OPEN..CLOSE (like 0..0.5)"))?;
        let b = b.strip_prefix('=').unwrap_or(b);
        let num = |v: &str| v.trim().parse::<f32>().map_err(|_| format!("'{v}' in '{s}' is not a number"));
        let (open, close) = (num(a)?, num(b)?);
        // Beyond one frame the lens reader would need frames past f + 1, which it does not read.
        if !(0.0..=1.0).contains(&open) || !(0.0..=1.0).contains(&close) || open > close {
            return Err(format!(
                "shutter '{s}': need 0 ≤ OPEN ≤ CLOSE ≤ 1 (fractions of a frame; the lens reader blends \
                 frames f and f+1 only)"
            ));
        }
        Ok(Self { open, close })
    }
}

/// A key `F=FILE`: a frame number and a file (the rest of the text after `=`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct KeyArg {
    /// The key's frame.
    pub frame: u32,
    /// Everything after `=`.
    pub value: String,
}

impl FromStr for KeyArg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (f, v) =
            s.split_once('=').ok_or_else(|| format!("'{s}' is not FRAME=FILE (like 150=key.mcr)"))?;
        let frame = f.trim().parse::<u32>().map_err(|_| format!("'{f}' in '{s}' is not a frame number"))?;
        if v.is_empty() {
            return Err(format!("'{s}' names no file after '='"));
        }
        Ok(Self { frame, value: v.to_owned() })
    }
}

impl KeyArg {
    /// The value as a path.
    pub fn path(&self) -> PathBuf {
        PathBuf::from(&self.value)
    }
}

/// `--spp`: samples per pixel, 1 ..= 65536 (clap names the flag in the error; with `--split N`
/// the renderer's limit is 65536 / N, checked with both flags known).
pub fn spp(s: &str) -> Result<u32, String> {
    let most = tracer::sampler::MAX_SAMPLES_PER_PIXEL;
    let n = s.trim().parse::<u32>().map_err(|_| format!("'{s}' is not a whole number of samples"))?;
    if n == 0 || n > most {
        return Err(format!("{n} samples per pixel: must be 1 ..= {most}"));
    }
    Ok(n)
}

/// `--denoise=QUALITY`: Intel Open Image Denoise's quality, `fast`, `balanced` or `high`.
pub fn denoise_quality(s: &str) -> Result<tracer::denoise::Quality, String> {
    tracer::denoise::Quality::from_name(s.trim()).ok_or_else(|| {
        let names: Vec<&str> = tracer::denoise::Quality::ALL.iter().map(|q| q.name()).collect();
        format!(
            "'{s}' is not a denoising quality: give one of {} (plain --denoise is {})",
            names.join(", "),
            tracer::denoise::Quality::DEFAULT.name()
        )
    })
}

/// `--ease`: the remapper's ease control, strictly between 0 and 1 (docs/design/mcc.md §5.4).
pub fn ease(s: &str) -> Result<f32, String> {
    let g = s.trim().parse::<f32>().map_err(|_| format!("'{s}' is not a number"))?;
    if !(g.is_finite() && g > 0.0 && g < 1.0) {
        return Err(format!("ease control {g} must be strictly between 0 and 1 (0.5: no easing)"));
    }
    Ok(g)
}

/// `--tag-bits`, `--bits`: bits per channel of the camera tag, 1 to 8 (docs/design/mcc.md §4.4).
pub fn tag_bits(s: &str) -> Result<u8, String> {
    let bits = s.trim().parse::<u8>().map_err(|_| format!("'{s}' is not a whole number of bits"))?;
    if !(1..=8).contains(&bits) {
        return Err(format!("{bits} bits per channel: must be 1 to 8 (the camera tag code's width)"));
    }
    Ok(bits)
}

/// `--tile I/N`: band I of N horizontal bands (docs/farm.md).
pub fn tile(s: &str) -> Result<tracer::job::Band, String> {
    tracer::job::Band::parse(s).map_err(|e| e.to_string())
}

/// Ray-file encodings, for every command that writes ray files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum RayFormatArg {
    /// Binary .mcr (smaller and faster; the default).
    Binary,
    /// The column's text format, .txt.
    Text,
}

impl From<RayFormatArg> for mcc::RayFormat {
    fn from(f: RayFormatArg) -> Self {
        match f {
            RayFormatArg::Binary => mcc::RayFormat::Binary,
            RayFormatArg::Text => mcc::RayFormat::Text,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses() {
        assert_eq!("1, 2.5,-3".parse::<Vec3Arg>().unwrap().0, Vec3::new(1.0, 2.5, -3.0));
        assert!("1,2".parse::<Vec3Arg>().is_err());
        assert!("1,nan,2".parse::<Vec3Arg>().is_err());
        assert_eq!("grey".parse::<SkyArg>().unwrap().0, Vec3::splat(0.050_876));
        assert_eq!("0.5".parse::<SkyArg>().unwrap().0, Vec3::splat(0.5));
        assert_eq!("0.1,0.2,0.3".parse::<SkyArg>().unwrap().0, Vec3::new(0.1, 0.2, 0.3));
        for bad in ["-1", "blue", "inf", "0,-1,0"] {
            assert!(bad.parse::<SkyArg>().is_err(), "{bad}");
        }
        assert_eq!("640x360".parse::<Resolution>().unwrap().0, UVec2::new(640, 360));
        assert!("640".parse::<Resolution>().is_err());
        assert!("0x10".parse::<Resolution>().is_err());
        assert!("-5x10".parse::<Resolution>().is_err());
    }

    #[test]
    fn frames_shutters_and_keys() {
        let r = |s: &str| s.parse::<FrameRange>().map(|r| (r.first, r.last));
        assert_eq!(r("0..=500"), Ok((0, 500)));
        assert_eq!(r("12"), Ok((12, 12)));
        // `A..B` once meant A..=B-1 without a word: now it is refused, naming both readings.
        let e = r("5..12").unwrap_err();
        assert!(e.contains("5..=12 to include frame 12") && e.contains("5..=11 to stop before it"), "{e}");
        assert!(r("5..=2").is_err());
        assert!(r("5..5").is_err());
        assert!(r("a..=2").is_err());
        assert!(r("-1..=2").is_err());
        assert_eq!("0..0.5".parse::<Shutter>(), Ok(Shutter { open: 0.0, close: 0.5 }));
        assert_eq!("0.25..=1".parse::<Shutter>(), Ok(Shutter { open: 0.25, close: 1.0 }));
        assert!("0.5..0.25".parse::<Shutter>().is_err());
        assert!("0..1.5".parse::<Shutter>().is_err());
        assert!("0..nan".parse::<Shutter>().is_err());
        assert!("0.5".parse::<Shutter>().is_err());
        let k = "150=dir/a=b.mcr".parse::<KeyArg>().unwrap();
        assert_eq!((k.frame, k.value.as_str()), (150, "dir/a=b.mcr"));
        assert!("x=a.mcr".parse::<KeyArg>().is_err());
        assert!("5=".parse::<KeyArg>().is_err());
        assert!("a.mcr".parse::<KeyArg>().is_err());
    }

    #[test]
    fn ranges_of_spp_ease_and_tag_bits() {
        assert_eq!(spp("1"), Ok(1));
        assert_eq!(spp("65536"), Ok(65536));
        assert_eq!(spp("0"), Err("0 samples per pixel: must be 1 ..= 65536".into()));
        assert!(spp("65537").unwrap_err().contains("must be 1 ..= 65536"));
        assert!(spp("-1").is_err());
        assert_eq!(ease("0.75"), Ok(0.75));
        assert!(ease("1.5").unwrap_err().contains("ease control 1.5 must be strictly between 0 and 1"));
        assert!(ease("0").is_err() && ease("nan").is_err() && ease("x").is_err());
        assert_eq!(tag_bits("2"), Ok(2));
        assert!(tag_bits("9").unwrap_err().contains("9 bits per channel: must be 1 to 8"));
        assert!(tag_bits("0").is_err());
    }

    /// `--denoise` alone is the default quality, `--denoise=Q` names one; the value needs the
    /// `=`, so a scene after a bare `--denoise` stays the scene; a bad quality is refused with
    /// the flag and the qualities named. On every command that renders.
    #[test]
    fn denoise_takes_an_optional_quality() {
        use clap::Parser;
        use tracer::denoise::Quality;
        let denoise = |line: &str| -> Result<Option<Quality>, String> {
            let cli = crate::Cli::try_parse_from(line.split(' ')).map_err(|e| e.to_string())?;
            Ok(match cli.command {
                crate::Command::Render(a) => a.quality.denoise,
                crate::Command::Rerender(a) => a.quality.denoise,
                crate::Command::Animate(a) => a.quality.denoise,
                crate::Command::Demo(a) => a.denoise,
                _ => unreachable!(),
            })
        };
        assert_eq!(denoise("mcctrace render s.gltf --out o.exr"), Ok(None));
        assert_eq!(denoise("mcctrace render --denoise s.gltf --out o.exr"), Ok(Some(Quality::DEFAULT)));
        assert_eq!(denoise("mcctrace render s.gltf --out o.exr --denoise=high"), Ok(Some(Quality::High)));
        assert_eq!(denoise("mcctrace demo --denoise=balanced"), Ok(Some(Quality::Balanced)));
        assert_eq!(denoise("mcctrace demo --denoise"), Ok(Some(Quality::DEFAULT)));
        assert_eq!(
            denoise("mcctrace rerender s.gltf --lens l.mcr --out o.exr --denoise=fast"),
            Ok(Some(Quality::Fast))
        );
        assert_eq!(
            denoise("mcctrace animate s.gltf --lens-dir d --frames 0..=1 --out o --denoise=high"),
            Ok(Some(Quality::High))
        );
        let err = denoise("mcctrace render s.gltf --out o.exr --denoise=medium").unwrap_err();
        assert!(
            err.contains("--denoise")
                && err.contains("'medium' is not a denoising quality: give one of fast, balanced, high"),
            "{err}"
        );
        assert!(denoise_quality("ultra").unwrap_err().contains("plain --denoise is high"));
    }
}
