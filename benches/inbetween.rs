//! In-betweener speed (docs/design/workflow.md §7): 1920×1080 frames from four synthetic keys.
//!
//! `cargo bench -p mcctrace-suite --bench inbetween` prints one table. The keys are pinhole
//! cameras orbiting the origin at the column's frames 0, 150, 400 and 500; the key at 400 looks
//! back the way the key at 150 came (nearly opposite rays at neighbouring keys, the hard case
//! for the spherical interpolation), and the key at 500 is stored at 1280×720 so building the
//! keys includes a resample. Rows:
//!
//! * building the keys (one resample) and the one-off tangents of the first smooth frame;
//! * frames in memory, smooth and linear, into a reused buffer (`Keys::frame_into`) and freshly
//!   allocated (`Keys::frame`): target ≥ 20 frames/s on a 2-core machine;
//! * `write_frames` to binary ray files in a temporary directory (each file written atomically:
//!   temporary file, fsync, rename), computing frame n + 1 while frame n is written; and
//!   `RayFile::write` alone, the ceiling for writing.
//!
//! `-- NAME` runs only rows whose label contains NAME; `MCC_INBETWEEN_FRAMES=N` sets the
//! frames per row (default 48).

use glam::{UVec2, Vec3};
use mcc::inbetween::{InbetweenMode, Keys, write_frames};
use mcc::ray_file::{RayFile, RayFormat, StoredRay};
use std::time::Instant;

/// CPU time of the whole process so far (all threads), in seconds: on a shared machine wall
/// time also measures the neighbours, CPU time does not.
fn cpu_seconds() -> f64 {
    let Ok(tasks) = std::fs::read_dir("/proc/self/task") else { return 0.0 };
    let ns: u64 = tasks
        .flatten()
        .filter_map(|t| std::fs::read_to_string(t.path().join("schedstat")).ok())
        .filter_map(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .sum();
    ns as f64 / 1e9
}

/// Wall and CPU time of a run of frames: (frames, wall seconds, best frame's wall seconds, CPU
/// seconds).
struct Run {
    frames: u32,
    wall: f64,
    best: f64,
    cpu: f64,
}

fn run(frames: &[u32], mut f: impl FnMut(u32)) -> Run {
    let (start, cpu0) = (Instant::now(), cpu_seconds());
    let mut best = f64::INFINITY;
    for &frame in frames {
        let t = Instant::now();
        f(frame);
        best = best.min(t.elapsed().as_secs_f64());
    }
    Run { frames: frames.len() as u32, wall: start.elapsed().as_secs_f64(), best, cpu: cpu_seconds() - cpu0 }
}

const KEY_FRAMES: [u32; 4] = [0, 150, 400, 500];

/// A pinhole camera's eye rays: eye at `eye`, looking at `target`, vertical half-angle tan 0.4.
fn camera(eye: Vec3, target: Vec3, w: u32, h: u32) -> RayFile {
    let forward = (target - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let tan = 0.4f32;
    let mut rays = Vec::with_capacity((w * h) as usize);
    for y in 0..h {
        for x in 0..w {
            let sx = (2.0 * (x as f32 + 0.5) / w as f32 - 1.0) * tan * w as f32 / h as f32;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / h as f32) * tan;
            rays.push(StoredRay::new(eye, (forward + sx * right + sy * up).normalize()));
        }
    }
    RayFile::new(w, h, 0, 1, rays).expect("camera rays")
}

fn keys() -> Vec<(u32, RayFile)> {
    let orbit = |deg: f32, height: f32| {
        let a = deg.to_radians();
        Vec3::new(5.0 * a.cos(), height, 5.0 * a.sin())
    };
    let (w, h) = (1920, 1080);
    vec![
        (0, camera(orbit(0.0, 1.0), Vec3::ZERO, w, h)),
        (150, camera(orbit(70.0, 1.5), Vec3::ZERO, w, h)),
        // Turned round: looks away from the origin, nearly opposite to the key at 150.
        (400, camera(orbit(80.0, 1.2), orbit(80.0, 1.2) * 2.0, w, h)),
        (500, camera(orbit(200.0, 0.8), Vec3::new(0.0, 0.5, 0.0), 1280, 720)),
    ]
}

fn main() {
    let filter: Vec<String> = std::env::args().skip(1).filter(|a| !a.starts_with('-')).collect();
    let wanted = |label: &str| filter.is_empty() || filter.iter().any(|f| label.contains(f.as_str()));
    let frames_per_row: u32 =
        std::env::var("MCC_INBETWEEN_FRAMES").ok().and_then(|v| v.parse().ok()).unwrap_or(48).max(1);
    let threads = rayon::current_num_threads();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "mcc in-betweener benchmark: 1920x1080, keys at {KEY_FRAMES:?} (the last stored at 1280x720), \
         {threads} threads, load average {}\n",
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    );
    let pixels = 1920.0 * 1080.0;
    println!(
        "{:<50} {:>8} {:>8} {:>8} {:>8} {:>9}",
        "case", "frames/s", "ms/frame", "best ms", "cpu ms", "cpu ns/px"
    );
    let row = |label: &str, r: &Run| {
        let n = r.frames as f64;
        println!(
            "{label:<50} {:>8.1} {:>8.1} {:>8.1} {:>8.1} {:>9.1}",
            n / r.wall,
            r.wall / n * 1e3,
            r.best * 1e3,
            r.cpu / n * 1e3,
            r.cpu / n * 1e9 / pixels
        );
    };

    let (mut input, mut keys) = (Some(self::keys()), None);
    row(
        "build keys (one 720p key resampled to 1080p)",
        &run(&[0], |_| {
            keys = Some(Keys::new(input.take().expect("once"), Some(UVec2::new(1920, 1080))).expect("keys"));
        }),
    );
    let keys = keys.expect("keys");
    let mut out = keys.frame(200, InbetweenMode::Linear);
    row(
        "first smooth frame (+ the 2 interior keys' tangents)",
        &run(&[200], |f| keys.frame_into(f, InbetweenMode::Smooth, &mut out)),
    );

    // Frames spread over the whole animation, never on a key (key frames are plain copies).
    let spread: Vec<u32> = (0..frames_per_row).map(|n| 1 + n * 499 / frames_per_row).collect();
    assert!(spread.iter().all(|f| !KEY_FRAMES.contains(f)));
    for (name, mode) in [("smooth", InbetweenMode::Smooth), ("linear", InbetweenMode::Linear)] {
        let label = format!("{name}, in memory, reused buffer (frame_into)");
        if wanted(&label) {
            keys.frame_into(spread[0], mode, &mut out); // warm
            row(&label, &run(&spread, |f| keys.frame_into(f, mode, &mut out)));
        }
        let label = format!("{name}, in memory, new buffer per frame (frame)");
        if wanted(&label) {
            row(&label, &run(&spread, |f| drop(std::hint::black_box(keys.frame(f, mode)))));
        }
    }
    let label = "hold (a key frame: a copy), in memory, reused buffer";
    if wanted(label) {
        row(label, &run(&spread, |_| keys.frame_into(150, InbetweenMode::Smooth, &mut out)));
    }

    let dir = std::env::temp_dir().join(format!("mcc-inbetween-bench-{}", std::process::id()));
    let first = 101;
    let label = "RayFile::write alone (binary, atomic: fsync + rename)";
    if wanted(label) {
        std::fs::create_dir_all(&dir).expect("bench dir");
        let frames: Vec<u32> = (0..frames_per_row.min(12)).collect();
        row(
            label,
            &run(&frames, |f| out.write(&dir.join(format!("w{f}.mcr")), RayFormat::Binary).expect("write")),
        );
        let _ = std::fs::remove_dir_all(&dir);
    }
    for (name, mode) in [("smooth", InbetweenMode::Smooth), ("linear", InbetweenMode::Linear)] {
        let label = format!("{name}, write_frames, binary .mcr (49.8 MB each)");
        if wanted(&label) {
            let mut r = run(&[0], |_| {
                let frames = first..=first + frames_per_row - 1;
                write_frames(&keys, frames, mode, &dir, RayFormat::Binary, &|_| {}).expect("write frames");
            });
            // The writer thread has ended by now, and with it its schedstat: no CPU figure.
            (r.frames, r.best, r.cpu) = (frames_per_row, f64::NAN, f64::NAN);
            row(&label, &r);
            let _ = std::fs::remove_dir_all(&dir);
        }
    }
    println!(
        "\nTarget: >= 20 frames/s in memory. cpu = all threads' CPU time (rayon's idle spinning \
         included); written to {} (removed).",
        dir.display()
    );
}
