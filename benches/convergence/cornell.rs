//! The Cornell series: error against time on the Cornell box, compared with the peers measured
//! on this kind of machine (`docs/performance.md`, "Peers"; `tests/data/cornell/README.md`).
//!
//! `CONVERGENCE=cornell cargo bench -p mcctrace-suite --bench convergence` renders `scenes/cornell/cornell.gltf`
//! (camera `cornell`, 256², at most 4 scattering vertices, default roulette depth) at 1, 2, 4,
//! … 256 spp on the default rayon pool, with samples spread evenly and (from 4 spp) with
//! adaptive sampling (`tracer::adaptive`, spp then being the average), then both again with
//! first-vertex splitting into 2 paths (`--split 2`, up to 128 spp), times each by the
//! render's own `stats.seconds` (tracing only; best of a few runs — the image is the same each
//! run, the seed being fixed), measures relMSE against the Mitsuba 3 reference with
//! `tracer::test_support::compare::rel_mse` (mean over pixels and channels of (x − r)² / (r² + 0.01)), and
//! writes
//!
//! - `target/convergence/cornell.csv`, `cornell-adaptive.csv`, `cornell-split2.csv` and
//!   `cornell-adaptive-split2.csv`: rows `spp,seconds,rel_mse`;
//! - `target/convergence/cornell.png`: relMSE against seconds on log–log axes, all series,
//!   with the peers' points and the relMSE = 1e-3 line;
//!
//! and prints the tables and the time at which relMSE first reaches 1e-3 (log–log interpolation
//! between the bracketing spp). Paths are relative to the repository root.

use crate::{Row, time_to};
use glam::UVec2;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, Scene};
use tracer::test_support::compare::rel_mse;

const SIZE: u32 = 256;
const SEED: u32 = 7;
const TARGET: f64 = 1e-3;
/// The first-vertex split of the third and fourth series.
const SPLIT: u32 = 2;

/// Peers (`docs/performance.md`, "Peers"): (label, [(seconds, relMSE)]).
const MITSUBA_LLVM: [(f64, f64); 3] = [(0.231, 0.00919), (0.906, 0.00234), (3.60, 0.000584)];
const MITSUBA_SCALAR: [(f64, f64); 1] = [(2.84, 0.00229)];
/// Cycles reaches relMSE 1e-3 after ≈ 3.8 s (`docs/performance.md`, "Peers").
const CYCLES_AT_TARGET: (f64, f64) = (3.8, 1e-3);

/// Renders the four series, prints them and writes their CSVs and plot under `root`.
pub fn run(root: &Path) {
    let scene = Scene::load(&root.join("scenes/cornell/cornell.gltf")).expect("load the Cornell glTF");
    let camera = scene.camera(&CameraSelector::Name("cornell".into())).expect("camera 'cornell'");
    let camera = camera.build(UVec2::splat(SIZE)).expect("build the camera");
    let reference =
        tracer::image_io::read_exr_rgb(&root.join("tests/data/cornell/reference-mitsuba3-16384spp.exr"))
            .expect("read the Mitsuba reference");
    let config = IntegratorConfig::DEFAULT.with_max_depth(4);
    let tracer = PathTracer::new(&scene, config).expect("prepare the scene");
    let split_tracer = PathTracer::new(&scene, config.with_split(SPLIT)).expect("prepare the scene");
    println!(
        "Cornell box {SIZE}², max depth {}, roulette from depth {}{}, {} threads, seed {SEED}",
        config.max_depth,
        config.rr_depth,
        if config.rr_depth >= config.max_depth { " (so none)" } else { "" },
        rayon::current_num_threads()
    );

    // Warm up (page in, spin up the pool) so the 1-spp timing is not a cold start.
    let _ = render(&tracer, camera.as_ref(), &mut LensChain::new(), &RenderSettings::still(4), &NoProgress);

    let series = |adaptive: bool, split: u32| {
        let tracer = if split == 1 { &tracer } else { &split_tracer };
        println!(
            "\n{} sampling{}",
            if adaptive { "adaptive" } else { "uniform" },
            if split == 1 { String::new() } else { format!(", {split} paths split from each first hit") }
        );
        println!("{:>5} {:>9} {:>11} {:>11} {:>13}", "spp", "seconds", "relMSE", "relMSE·spp", "M samples/s");
        let mut rows = Vec::new();
        // Adaptive sampling splits from PILOT_SHARE spp on; below that it is uniform.
        let last = if split == 1 { 8 } else { 7 };
        for k in if adaptive { tracer::adaptive::PILOT_SHARE.ilog2()..=last } else { 0..=last } {
            let spp = 1u32 << k;
            let runs = if spp <= 32 {
                5
            } else if spp <= 128 {
                3
            } else {
                2
            };
            let settings = RenderSettings { seed: SEED, adaptive, ..RenderSettings::still(spp) };
            let mut best = f64::INFINITY;
            let mut last = None;
            for _ in 0..runs {
                let r = render(tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress)
                    .expect("render");
                assert_eq!(r.stats.nonfinite_samples, 0, "{spp} spp: NaN/Inf samples");
                best = best.min(r.stats.seconds);
                last = Some(r);
            }
            // Every run gives the same bits: the error and the counts of one will do.
            let r = last.expect("at least one run");
            let (error, samples) = (rel_mse(&r.images.image, &reference), r.stats.samples);
            println!(
                "{spp:>5} {best:>9.4} {error:>11.3e} {:>11.4} {:>13.2}",
                error * spp as f64,
                samples as f64 / best / 1e6
            );
            rows.push(Row { spp, seconds: best, rel_mse: error });
        }
        let crossing = time_to(&rows, TARGET);
        match crossing {
            Some((seconds, spp)) => println!(
                "relMSE {TARGET:e} first reached after {seconds:.3} s (≈ {spp:.0} spp, log–log interpolation)"
            ),
            None => println!("relMSE {TARGET:e} not reached by {} spp", rows.last().unwrap().spp),
        }
        (rows, crossing)
    };
    let all = [series(false, 1), series(true, 1), series(false, SPLIT), series(true, SPLIT)];

    let dir = root.join("target/convergence");
    std::fs::create_dir_all(&dir).expect("create target/convergence");
    let names = ["cornell.csv", "cornell-adaptive.csv", "cornell-split2.csv", "cornell-adaptive-split2.csv"];
    for (name, (rows, _)) in names.into_iter().zip(&all) {
        let mut csv = String::from("spp,seconds,rel_mse\n");
        for r in rows {
            writeln!(csv, "{},{:.6},{:.6e}", r.spp, r.seconds, r.rel_mse).unwrap();
        }
        std::fs::write(dir.join(name), csv).expect("write the CSV");
    }
    let png_path = dir.join("cornell.png");
    plot(&png_path, &all).expect("draw the plot");
    println!("wrote {}/{} and cornell.png", dir.display(), names.join(", "));
}

/// A series of rows and its crossing of the target.
type Series = (Vec<Row>, Option<(f64, f64)>);

fn plot(path: &Path, all: &[Series; 4]) -> crate::Drawn {
    crate::write_png(path, |root| {
        let peers = MITSUBA_LLVM.iter().chain(&MITSUBA_SCALAR).chain(std::iter::once(&CYCLES_AT_TARGET));
        let (mut t_lo, mut t_hi, mut e_lo, mut e_hi) = (f64::INFINITY, 0f64, f64::INFINITY, 0f64);
        let ours: Vec<(f64, f64)> = all.iter().flat_map(|s| &s.0).map(|r| (r.seconds, r.rel_mse)).collect();
        for &(t, e) in ours.iter().chain(peers) {
            (t_lo, t_hi, e_lo, e_hi) = (t_lo.min(t), t_hi.max(t), e_lo.min(e), e_hi.max(e));
        }
        let (t_lo, t_hi) = (t_lo / 1.5, t_hi * 1.5);
        let (e_lo, e_hi) = (e_lo.min(TARGET) / 1.5, e_hi * 1.5);

        let caption = format!(
            "Cornell box {SIZE}², 4 bounces: relMSE vs render time ({} threads)",
            rayon::current_num_threads()
        );
        let axes = ("render time [s] (log)", "relMSE vs Mitsuba 16384 spp (log)");
        let mut chart = crate::log_log_chart(root, &caption, axes, t_lo..t_hi, e_lo..e_hi)?;

        // The target line.
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(LineSeries::new([(t_lo, TARGET), (t_hi, TARGET)], grey.stroke_width(2)))?
            .label(format!("relMSE = {TARGET:.0e}"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], grey.stroke_width(2)));

        // mcctrace: every series; spp labels only on the first two (the others would overlap).
        let [uniform, adaptive, split, adaptive_split] = all;
        for ((rows, crossing), colour, name, dy, labels) in [
            (uniform, RGBColor(200, 40, 40), "mcctrace (1 … 256 spp)", -22, true),
            (adaptive, RGBColor(150, 40, 160), "mcctrace adaptive (4 … 256 spp average)", 14, true),
            (split, RGBColor(230, 120, 110), "mcctrace --split 2 (1 … 128 spp)", -22, false),
            (adaptive_split, RGBColor(200, 140, 210), "mcctrace adaptive --split 2 (4 … 128 spp)", 14, false),
        ] {
            let points: Vec<(f64, f64)> = rows.iter().map(|r| (r.seconds, r.rel_mse)).collect();
            chart
                .draw_series(LineSeries::new(points.clone(), colour.stroke_width(3)))?
                .label(name)
                .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], colour.stroke_width(3)));
            chart.draw_series(points.iter().map(|&p| Circle::new(p, 5, colour.filled())))?;
            // "N spp" beside each point: above left for the uniform series, below for the other.
            chart.draw_series(rows.iter().filter(|_| labels).map(|r| {
                let label = ("sans-serif", 15).into_font().color(&colour);
                EmptyElement::at((r.seconds, r.rel_mse))
                    + Text::new(format!("{} spp", r.spp), (-62, dy), label)
            }))?;
            if let Some((t, _)) = *crossing {
                chart.draw_series(std::iter::once(Cross::new((t, TARGET), 9, colour.stroke_width(3))))?;
                let label = ("sans-serif", 16).into_font().color(&colour);
                chart.draw_series(std::iter::once(
                    EmptyElement::at((t, TARGET))
                        + Text::new(format!("1e-3 at {t:.2} s"), (10, dy.signum() * 20 + 8), label),
                ))?;
            }
        }

        // Peers.
        let blue = RGBColor(30, 90, 200);
        chart
            .draw_series(MITSUBA_LLVM.iter().map(|&p| TriangleMarker::new(p, 9, blue.filled())))?
            .label("Mitsuba 3 llvm_ad_rgb (16, 64, 256 spp)")
            .legend(move |(x, y)| TriangleMarker::new((x + 12, y), 7, blue.filled()));
        let teal = RGBColor(20, 150, 130);
        chart
            .draw_series(
                MITSUBA_SCALAR
                    .iter()
                    .map(|&p| EmptyElement::at(p) + Rectangle::new([(-6, -6), (6, 6)], teal.filled())),
            )?
            .label("Mitsuba 3 scalar_rgb (64 spp)")
            .legend(move |(x, y)| Rectangle::new([(x + 7, y - 5), (x + 17, y + 5)], teal.filled()));
        let orange = RGBColor(230, 130, 0);
        chart
            .draw_series(std::iter::once(
                EmptyElement::at(CYCLES_AT_TARGET) + Circle::new((0, 0), 8, orange.filled()),
            ))?
            .label("Blender Cycles: 1e-3 after ≈ 3.8 s")
            .legend(move |(x, y)| Circle::new((x + 12, y), 6, orange.filled()));

        crate::finish_chart(&mut chart, root)
    })
}
