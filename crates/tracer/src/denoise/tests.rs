use super::*;
use crate::lcg::Lcg;
use glam::Vec3;

/// The shared denoiser, or `None` after a note when OIDN is not installed on a developer's
/// machine; under CI (`MCCTRACE_CI=1`, `.ci/run` installs it) its absence fails the test.
pub(crate) fn denoiser_or_skip() -> Option<&'static Denoiser> {
    match Denoiser::shared() {
        Ok(d) => Some(d),
        Err(e @ DenoiseError::NotFound { .. })
            if std::env::var_os("MCCTRACE_CI").is_none_or(|v| v != "1") =>
        {
            eprintln!("skipping: {e} (MCCTRACE_CI=1 makes its absence a failure)");
            None
        }
        Err(e) => panic!("{e}"),
    }
}

/// A clean picture (a bright left half, a dim right half, a gradient down) and the same with
/// heavy zero-mean noise, as a low sample count gives.
fn scene(w: u32, h: u32, rng: &mut Lcg) -> (RgbImage, RgbImage, RgbImage, RgbImage) {
    let mut clean = RgbImage::new(w, h);
    let mut albedo = RgbImage::new(w, h);
    let mut normal = RgbImage::new(w, h);
    for y in 0..h {
        for x in 0..w {
            let a = if x < w / 2 { Vec3::new(0.8, 0.6, 0.4) } else { Vec3::new(0.2, 0.3, 0.5) };
            clean.set(x, y, a * (0.5 + y as f32 / h as f32));
            albedo.set(x, y, a);
            normal.set(x, y, if x < w / 2 { Vec3::Z } else { Vec3::X });
        }
    }
    let mut noisy = clean.clone();
    for p in &mut noisy.pixels {
        let n = rng.vec();
        *p = (*p * (Vec3::ONE + n)).max(Vec3::ZERO);
    }
    (clean, noisy, albedo, normal)
}

fn mse(a: &RgbImage, b: &RgbImage) -> f64 {
    let sum: f64 = a.pixels.iter().zip(&b.pixels).map(|(x, y)| (*x - *y).length_squared() as f64).sum();
    sum / a.pixels.len() as f64
}

/// Both modes, with and without auxiliaries, bring a noisy picture far closer to the clean one
/// (the noise's error falls at least tenfold), and the output is finite.
#[test]
fn denoising_removes_most_of_the_noise() {
    let Some(d) = denoiser_or_skip() else { return };
    assert!(d.version().starts_with("2."), "{}", d.version());
    let (clean, noisy, albedo, normal) = scene(64, 48, &mut Lcg(7));
    let raw = mse(&noisy, &clean);
    for mode in [Mode::Final, Mode::Preview] {
        for aux in [None, Some(Aux { albedo: &albedo, normal: &normal })] {
            let out = d.denoise(&noisy, aux, mode).unwrap();
            assert_eq!((out.width, out.height), (64, 48));
            assert!(out.pixels.iter().all(|p| p.is_finite()));
            let err = mse(&out, &clean);
            assert!(err < raw / 10.0, "{mode:?} aux={}: {err} vs raw {raw}", aux.is_some());
        }
    }
    assert!(d.describe(Mode::Final, true).contains("prefiltered"));
}

/// NaN, infinite and negative samples never reach the filter: the output is finite and the
/// picture around them is denoised as if they were black.
#[test]
fn non_finite_samples_give_a_finite_picture() {
    let Some(d) = denoiser_or_skip() else { return };
    let (_, mut noisy, mut albedo, mut normal) = scene(32, 24, &mut Lcg(3));
    noisy.pixels[5] = Vec3::NAN;
    noisy.pixels[40] = Vec3::INFINITY;
    noisy.pixels[41] = Vec3::NEG_INFINITY;
    noisy.pixels[100] = Vec3::new(f32::NAN, 1.0, -3.0);
    albedo.pixels[7] = Vec3::NAN;
    normal.pixels[9] = Vec3::splat(f32::INFINITY);
    for mode in [Mode::Final, Mode::Preview] {
        let out = d.denoise(&noisy, Some(Aux { albedo: &albedo, normal: &normal }), mode).unwrap();
        assert!(out.pixels.iter().all(|p| p.is_finite() && p.min_element() >= 0.0), "{mode:?}");
    }
}

/// Auxiliaries of another size are refused with both sizes named.
#[test]
fn mismatched_auxiliaries_are_refused() {
    let Some(d) = denoiser_or_skip() else { return };
    let (color, small) = (RgbImage::new(8, 8), RgbImage::new(4, 8));
    let err = d.denoise(&color, Some(Aux { albedo: &small, normal: &color }), Mode::Final).unwrap_err();
    assert!(err.to_string().contains("albedo image is 4×8, the picture 8×8"), "{err}");
}
