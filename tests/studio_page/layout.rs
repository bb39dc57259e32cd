//! The browser test's geometry at one collage size: the size (160×90 by default, for a quick run;
//! another one by `STUDIO_PAGE_RES=WxH`, as CI runs it at the 480×270, docs/performance.md
//! §1.6), and the
//! brush, strokes, camera drag, browser window and waits, laid out at 160×90 and scaled with it,
//! so every check of the test means the same at any size.

use std::time::Duration;

/// The environment variable that picks the collage size, `WxH`; unset, the default size.
pub const RES_VAR: &str = "STUDIO_PAGE_RES";
/// The default collage size: small, so the preview converges quickly on two loaded cores.
const DEFAULT_RES: (u32, u32) = (160, 90);
/// The largest size the test lays out: the page at 2× must fit a 1920×1080-class window.
const MAX_RES: (u32, u32) = (1920, 1080);
/// The brush diameter at 160×90, in collage pixels.
const BRUSH: f64 = 9.0;
/// Two horizontal strokes at 160×90, camera 1 on the left, camera 2 on the right.
const STROKES: [Stroke; 2] = [(1, (16.0, 30.0), (56.0, 30.0)), (2, (104.0, 60.0), (144.0, 60.0))];
/// Waits for the server's work (previews, save, final render) at 160×90 on a loaded machine.
const PATIENCE: Duration = Duration::from_secs(180);

/// A stroke: the camera it paints, and its start and end (collage pixels).
pub type Stroke = (u32, (f64, f64), (f64, f64));

/// The test's geometry at one collage size.
pub struct Layout {
    /// The collage size.
    pub res: (u32, u32),
    /// The brush diameter in collage pixels.
    pub brush: f64,
    /// The two strokes, in collage pixels.
    pub strokes: [Stroke; 2],
    /// The source-view drag that orbits a camera, in collage pixels.
    pub orbit: Vec<(f64, f64)>,
    /// The browser window: room for the canvas at 2× beside the page's side panels.
    pub window: (u32, u32),
    /// How long to wait for the server's work: [`PATIENCE`] per 160×90 worth of pixels.
    pub patience: Duration,
}

impl Layout {
    /// The layout at the size [`RES_VAR`] names, or at the default size when it is unset.
    pub fn from_env() -> Result<Self, String> {
        match std::env::var(RES_VAR) {
            Ok(text) => Ok(Self::at(parse_res(&text)?)),
            Err(std::env::VarError::NotPresent) => Ok(Self::at(DEFAULT_RES)),
            Err(e) => Err(format!("{RES_VAR}: {e}")),
        }
    }

    /// The 160×90 layout scaled to `res` (x and y each by their own factor, the brush by the
    /// smaller one, so it stays round).
    fn at(res: (u32, u32)) -> Self {
        let (sx, sy) = (res.0 as f64 / DEFAULT_RES.0 as f64, res.1 as f64 / DEFAULT_RES.1 as f64);
        let at = |(x, y): (f64, f64)| (x * sx, y * sy);
        let strokes = STROKES.map(|(camera, a, b)| (camera, at(a), at(b)));
        let orbit = (0..=6).map(|i| at((60.0 + 6.0 * i as f64, 45.0))).collect();
        let pixels = (res.0 * res.1) as f64 / (DEFAULT_RES.0 * DEFAULT_RES.1) as f64;
        Self {
            res,
            brush: BRUSH * sx.min(sy),
            strokes,
            orbit,
            window: ((2 * res.0 + 600).max(1100), (2 * res.1 + 300).max(650)),
            patience: PATIENCE.mul_f64(pixels.max(1.0)),
        }
    }

    /// The pixels whose centres lie within `radius` of stroke `s`'s path.
    pub fn near_stroke(&self, s: usize, radius: f64) -> Vec<(u32, u32)> {
        let (_, a, b) = self.strokes[s];
        self.pixels().filter(|&(x, y)| distance_to_segment(x, y, a, b) <= radius).collect()
    }

    /// Every pixel of the collage, row by row.
    pub fn pixels(&self) -> impl Iterator<Item = (u32, u32)> + use<> {
        let (w, h) = self.res;
        (0..h).flat_map(move |y| (0..w).map(move |x| (x, y)))
    }

    /// The RGB of pixel (x, y) in an RGBA buffer of the collage size.
    pub fn rgb_at(&self, rgba: &[u8], (x, y): (u32, u32)) -> [u8; 3] {
        let i = ((y * self.res.0 + x) * 4) as usize;
        [rgba[i], rgba[i + 1], rgba[i + 2]]
    }
}

/// `WxH` (e.g. `480x270`) as a collage size the test can lay out, or what is wrong with it.
pub fn parse_res(text: &str) -> Result<(u32, u32), String> {
    let bad = |why: &str| format!("{RES_VAR}={text:?}: {why} (expected WxH, e.g. 480x270)");
    let (w, h) = text.trim().split_once(['x', 'X']).ok_or_else(|| bad("no `x` between width and height"))?;
    let (w, h): (u32, u32) = match (w.parse(), h.parse()) {
        (Ok(w), Ok(h)) => (w, h),
        _ => return Err(bad("width and height must be whole numbers")),
    };
    if w < DEFAULT_RES.0 || h < DEFAULT_RES.1 || w > MAX_RES.0 || h > MAX_RES.1 {
        return Err(bad(&format!(
            "the test lays out sizes from {}x{} to {}x{}",
            DEFAULT_RES.0, DEFAULT_RES.1, MAX_RES.0, MAX_RES.1
        )));
    }
    Ok((w, h))
}

/// Distance from the pixel centre (x + ½, y + ½) to the segment a–b.
pub fn distance_to_segment(x: u32, y: u32, a: (f64, f64), b: (f64, f64)) -> f64 {
    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((px - a.0) * dx + (py - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    ((px - a.0 - t * dx).powi(2) + (py - a.1 - t * dy).powi(2)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_malformed_ones_are_refused() {
        assert_eq!(parse_res("480x270"), Ok((480, 270)));
        assert_eq!(parse_res(" 160X90 "), Ok((160, 90)));
        for bad in
            ["", "480", "480x", "x270", "480*270", "480x270x1", "-480x270", "4.5x270", "80x45", "4000x2000"]
        {
            let e = parse_res(bad).expect_err(bad);
            assert!(e.starts_with(RES_VAR) && e.contains("expected WxH"), "{bad}: {e}");
        }
    }

    #[test]
    fn the_default_layout_is_the_one_the_test_was_written_at() {
        let l = Layout::at(DEFAULT_RES);
        assert_eq!((l.brush, l.strokes, l.window, l.patience), (BRUSH, STROKES, (1100, 650), PATIENCE));
        assert_eq!(l.orbit.first(), Some(&(60.0, 45.0)));
        let big = Layout::at((480, 270));
        assert_eq!((big.brush, big.strokes[1].2, big.window), (27.0, (432.0, 180.0), (1560, 840)));
    }
}
