//! The café series: error against time on a real scene, beside Cycles (issue 25's target: the
//! same relMSE in at most half Cycles' time; `docs/performance.md` §1.5).
//!
//! `CONVERGENCE=cafe cargo bench -p mcctrace-suite --bench convergence` renders
//! `scenes/cafe/cafe.gltf`, camera `wide`, 240×135, the default integrator (8 vertices, box
//! filter), Blender's spot falloff (as `cafe.sh` passes `--spot-falloff blender`), at 1, 2, 4, … 256 spp with seeds 1 and 2 on the default rayon pool. A point's time
//! is the wall time of preparing the scene (BVH, light tree) and rendering, the mean of its two
//! seeds — what Cycles' render call covers; its error is the variance part of relMSE from the
//! two seeds (`tracer::test_support::compare::two_seed_rel_mse`), denominators from the mean of the two
//! 256-spp renders. Cycles is drawn as its line of constant time × relMSE, measured on this
//! machine by `benches/peers/cycles/cafe.sh` (`CYCLES_PRODUCT` below), and the target as half of
//! it. Writes `target/convergence/cafe.csv` (`spp,seconds,rel_mse`) and `cafe.png`.

use crate::Row;
use glam::UVec2;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;
use tracer::image::RgbImage;
use tracer::integrator::{IntegratorConfig, PathTracer};
use tracer::job::SceneSetup;
use tracer::lens::LensChain;
use tracer::render::{NoProgress, RenderSettings, render};
use tracer::scene::{CameraSelector, SpotFalloff};
use tracer::test_support::compare::two_seed_rel_mse;

const SIZE: UVec2 = UVec2::new(240, 135);
const LAST_SPP: u32 = 256;
/// Cycles' seconds × relMSE on this view (`cafe.sh`, 256 spp, 2 threads; docs/performance.md
/// §1.5 gives the run).
const CYCLES_PRODUCT: f64 = 0.2542;

/// Renders the series, prints it with its ratio to Cycles and writes its CSV and plot.
pub fn run(root: &Path) {
    // The café is not from Blender, so it would get glTF's spot falloff; Cycles can only render
    // Blender's (docs/design/tracer.md §3.10), and the comparison must render one scene.
    let setup = SceneSetup { spot_falloff: Some(SpotFalloff::Blender), ..SceneSetup::default() };
    let scene = setup.load(&root.join("scenes/cafe/cafe.gltf")).expect("load the café");
    let camera = scene.camera(&CameraSelector::Name("wide".into())).expect("camera 'wide'");
    let camera = camera.build(SIZE).expect("build the camera");
    let config = IntegratorConfig::DEFAULT;
    println!(
        "\nCafé `wide` {}×{}, max depth {}, {} threads, seeds 1 and 2",
        SIZE.x,
        SIZE.y,
        config.max_depth,
        rayon::current_num_threads()
    );
    let render_one = |spp: u32, seed: u32| -> (RgbImage, f64) {
        let start = Instant::now();
        let tracer = PathTracer::new(&scene, config).expect("prepare the scene");
        let settings = RenderSettings { seed, ..RenderSettings::still(spp) };
        let r =
            render(&tracer, camera.as_ref(), &mut LensChain::new(), &settings, &NoProgress).expect("render");
        assert_eq!(r.stats.nonfinite_samples, 0, "{spp} spp: NaN/Inf samples");
        (r.images.image, start.elapsed().as_secs_f64())
    };
    // Warm up (page in, spin up the pool) so the 1-spp timing is not a cold start.
    let _ = render_one(1, 3);
    let pairs: Vec<(u32, [(RgbImage, f64); 2])> = (0..=LAST_SPP.ilog2())
        .map(|k| 1u32 << k)
        .map(|spp| (spp, [render_one(spp, 1), render_one(spp, 2)]))
        .collect();
    let last = &pairs.last().expect("a series").1;
    let mut r = last[0].0.clone();
    for (p, q) in r.pixels.iter_mut().zip(&last[1].0.pixels) {
        *p = (*p + *q) * 0.5;
    }
    println!(
        "{:>5} {:>9} {:>11} {:>11} {:>12} {:>10}",
        "spp", "seconds", "relMSE", "relMSE·spp", "s × relMSE", "/ Cycles"
    );
    let rows: Vec<Row> = pairs
        .iter()
        .map(|(spp, [(a, ta), (b, tb)])| {
            let row = Row { spp: *spp, seconds: (ta + tb) / 2.0, rel_mse: two_seed_rel_mse(a, b, &r) };
            let product = row.seconds * row.rel_mse;
            println!(
                "{:>5} {:>9.3} {:>11.3e} {:>11.4} {:>12.4e} {:>10.3}",
                row.spp,
                row.seconds,
                row.rel_mse,
                row.rel_mse * row.spp as f64,
                product,
                product / CYCLES_PRODUCT
            );
            row
        })
        .collect();

    let dir = root.join("target/convergence");
    std::fs::create_dir_all(&dir).expect("create target/convergence");
    let mut csv = String::from("spp,seconds,rel_mse\n");
    for r in &rows {
        writeln!(csv, "{},{:.6},{:.6e}", r.spp, r.seconds, r.rel_mse).unwrap();
    }
    std::fs::write(dir.join("cafe.csv"), csv).expect("write the CSV");
    plot(&dir.join("cafe.png"), &rows).expect("draw the plot");
    println!("wrote {}/cafe.csv and cafe.png", dir.display());
}

fn plot(path: &Path, rows: &[Row]) -> crate::Drawn {
    crate::write_png(path, |root| {
        let (t_lo, t_hi) = (rows[0].seconds / 1.5, rows[rows.len() - 1].seconds * 1.5);
        let e_hi = rows[0].rel_mse.max(CYCLES_PRODUCT / t_lo) * 1.5;
        let e_lo = rows[rows.len() - 1].rel_mse.min(0.5 * CYCLES_PRODUCT / t_hi) / 1.5;
        let caption = format!("Café `wide` {}×{}, 8 vertices: relMSE vs time, 2 seeds", SIZE.x, SIZE.y);
        let axes =
            ("time: scene preparation + render [s] (log)", "relMSE, variance part from two seeds (log)");
        let mut chart = crate::log_log_chart(root, &caption, axes, t_lo..t_hi, e_lo..e_hi)?;
        // Lines of constant time × relMSE: Cycles', and the target at half of it.
        let orange = RGBColor(230, 130, 0);
        let line = |k: f64| [(t_lo, k / t_lo), (t_hi, k / t_hi)];
        chart
            .draw_series(LineSeries::new(line(CYCLES_PRODUCT), orange.stroke_width(3)))?
            .label(format!("Blender Cycles (time × relMSE = {CYCLES_PRODUCT:.3})"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], orange.stroke_width(3)));
        let grey = RGBColor(120, 120, 120);
        chart
            .draw_series(LineSeries::new(line(0.5 * CYCLES_PRODUCT), grey.stroke_width(2)))?
            .label("target: Cycles' relMSE in half its time")
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], grey.stroke_width(2)));
        let red = RGBColor(200, 40, 40);
        let points: Vec<(f64, f64)> = rows.iter().map(|r| (r.seconds, r.rel_mse)).collect();
        chart
            .draw_series(LineSeries::new(points.clone(), red.stroke_width(3)))?
            .label(format!("mcctrace (1 … {LAST_SPP} spp)"))
            .legend(move |(x, y)| PathElement::new([(x, y), (x + 24, y)], red.stroke_width(3)));
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 5, red.filled())))?;
        chart.draw_series(rows.iter().map(|r| {
            let label = ("sans-serif", 15).into_font().color(&red);
            EmptyElement::at((r.seconds, r.rel_mse)) + Text::new(format!("{} spp", r.spp), (-62, -22), label)
        }))?;
        crate::finish_chart(&mut chart, root)
    })
}
