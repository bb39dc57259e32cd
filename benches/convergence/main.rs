//! Error against time (`docs/performance.md` §1.5, "Peers"): the Cornell box against Mitsuba 3
//! and Cycles (`cornell.rs`), the café against Cycles (`cafe.rs`).
//!
//! `cargo bench -p mcctrace-suite --bench convergence` runs both series;
//! `CONVERGENCE=cornell` or `CONVERGENCE=cafe` runs one. Each writes its CSVs and a log–log
//! plot under `target/convergence/` (paths relative to the repository root).

mod cafe;
mod cornell;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::ops::Range;
use std::path::{Path, PathBuf};

/// One point of a series: samples per pixel, seconds, relMSE.
struct Row {
    spp: u32,
    seconds: f64,
    rel_mse: f64,
}

fn main() {
    // `cargo bench` passes `--bench` (and filters); this plain main takes no options.
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let which = std::env::var("CONVERGENCE").unwrap_or_default();
    match which.as_str() {
        "" => {
            cornell::run(&root);
            cafe::run(&root);
        }
        "cornell" => cornell::run(&root),
        "cafe" => cafe::run(&root),
        other => panic!("CONVERGENCE={other}: expected cornell or cafe"),
    }
}

/// Seconds (and spp) at which relMSE first falls to `target`: log–log interpolation between the
/// last row above it and the first row at or below it.
fn time_to(rows: &[Row], target: f64) -> Option<(f64, f64)> {
    let i = rows.iter().position(|r| r.rel_mse <= target)?;
    if i == 0 {
        return Some((rows[0].seconds, rows[0].spp as f64));
    }
    let (a, b) = (&rows[i - 1], &rows[i]);
    let f = (target.ln() - a.rel_mse.ln()) / (b.rel_mse.ln() - a.rel_mse.ln());
    let lerp = |x: f64, y: f64| (x.ln() + f * (y.ln() - x.ln())).exp();
    Some((lerp(a.seconds, b.seconds), lerp(a.spp as f64, b.spp as f64)))
}

/// Plots draw text with the bundled DejaVu Sans, not the system's fonts.
fn register_font() -> Result<(), Box<dyn std::error::Error>> {
    plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
        .map_err(|_| "the bundled DejaVu Sans font did not load".into())
}

/// The plots' size in pixels.
const PLOT_SIZE: (u32, u32) = (1000, 700);

/// The result of drawing a plot.
type Drawn = Result<(), Box<dyn std::error::Error>>;

/// Draws a plot with `draw` on a white RGB buffer and writes it to `path` as PNG, encoded by the
/// workspace's `image` (plotters' own encoder would build a second, older `image`).
fn write_png(path: &Path, draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Drawn) -> Drawn {
    register_font()?;
    let (w, h) = PLOT_SIZE;
    let mut rgb = vec![0u8; w as usize * h as usize * 3];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, PLOT_SIZE).into_drawing_area();
        root.fill(&WHITE)?;
        draw(&root)?;
    }
    image::save_buffer(path, &rgb, w, h, image::ExtendedColorType::Rgb8)?;
    Ok(())
}

/// A log–log chart on `root` over seconds `t` and relMSE `e`, with its caption and axis names.
type LogChart<'a, 'b> = ChartContext<'a, BitMapBackend<'b>, Cartesian2d<LogCoord<f64>, LogCoord<f64>>>;

/// Draws a captioned log–log chart's frame and grid; the series go on the returned chart.
fn log_log_chart<'a, 'b>(
    root: &'a DrawingArea<BitMapBackend<'b>, Shift>,
    caption: &str,
    (x_desc, y_desc): (&str, &str),
    t: Range<f64>,
    e: Range<f64>,
) -> Result<LogChart<'a, 'b>, Box<dyn std::error::Error>> {
    let mut chart = ChartBuilder::on(root)
        .caption(caption, ("sans-serif", 26))
        .margin(20)
        .x_label_area_size(55)
        .y_label_area_size(85)
        .build_cartesian_2d(t.log_scale(), e.log_scale())?;
    chart
        .configure_mesh()
        .x_desc(x_desc)
        .y_desc(y_desc)
        .x_label_formatter(&|v| format!("{}", (v * 1e3).round() / 1e3))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .label_style(("sans-serif", 17))
        .axis_desc_style(("sans-serif", 19))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()?;
    Ok(chart)
}

/// Draws the legend in the upper right and writes the picture.
fn finish_chart<'b: 'a, 'a>(
    chart: &mut LogChart<'a, 'b>,
    root: &DrawingArea<BitMapBackend<'b>, Shift>,
) -> Result<(), Box<dyn std::error::Error>> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 17))
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
