//! Numerical stress tests of the tracer (docs/testing.md §4; docs/design/tracer.md §3.4, §3.8): `tests/robustness.rs`
//! proves the ray–surface arithmetic on the Cornell box (Lambert, emissive triangles, a perspective
//! camera); these extend it to every material (Lambert, GGX metal, rough dielectric, glass,
//! textured alpha mask, normal maps through explicit and derived tangents, one- and double-sided
//! emitters), every light type (emissive triangles, point, spot, directional, constant sky,
//! environment image) and every camera model (perspective, orthographic, thin lens, fisheye,
//! equirectangular).
//!
//! * `scale`: the stress scene scaled by 10^k, k ∈ {−4, −2, 2, 4}, or moved 10^4 along every
//!   axis renders the same image as at unit scale (statistical two-estimate test, independent
//!   seeds) — with point and spot intensities scaled by s² (inverse square law), the thin lens's
//!   aperture and focus distance and the orthographic window by s, everything else unchanged.
//!   Refraction and alpha cut-outs are checked exactly: an index-matched glass sphere and a fully
//!   cut-out quad are invisible, at every scale, which fails if a refracted ray re-hits its own
//!   surface.
//! * `nan`: grazing views (cos ≈ 1e-7) of every material under every light, degenerate and
//!   zero-area triangles of every material, degenerate tangent frames, denormal and huge
//!   coordinates: no NaN/Inf sample, ever (`RenderStats::nonfinite_samples`, the film's count).

mod nan;
mod scale;
mod scene;
