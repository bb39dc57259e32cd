//! This process's CPU time, for benchmarks that report CPU seconds beside wall time on a
//! shared machine.

/// This process's user + system CPU seconds (from /proc/self/stat, clock ticks of 1/100 s).
pub fn cpu_seconds() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let after = stat.rsplit_once(')').map_or("", |s| s.1);
    let fields: Vec<&str> = after.split_whitespace().collect();
    let tick = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0) / 100.0;
    // Fields 14 and 15 of the stat line (utime, stime) are 12 and 13 after the name.
    tick(11) + tick(12)
}
