//! Error against time (`docs/performance.md` §1.3, "Peers"): the Cornell box against Mitsuba 3
//! and Cycles (`cornell.rs`), the café against Cycles (`cafe.rs`).
//!
//! `cargo bench -p mcctrace-suite --bench convergence` runs both series;
//! `CONVERGENCE=cornell` or `CONVERGENCE=cafe` runs one. Each writes its CSVs and a log–log
//! plot under `target/convergence/` (paths relative to the repository root).

mod cafe;
mod cornell;

use plotters::style::FontStyle;
use std::path::PathBuf;

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
