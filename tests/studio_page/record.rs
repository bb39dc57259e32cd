//! The page's responsiveness over the whole session (issue 24: "no frame of the page blocked by
//! rendering for more than 50 ms"): the long tasks Chromium reports (anything that held the main
//! thread over 50 ms, whoever ran it: the page, the test's own scripts, the browser) and the
//! page's own handlers as the page times them (`performance.measure`), written to
//! `page-record.json` beside the screenshots with the machine's load.

use super::browser::Browser;
use serde_json::{Value, json};

/// One of the page's handlers: its name, calls and longest call in ms.
pub struct Handler {
    /// The name the page times it under (`socket message`, `draw`, `pointermove`, …).
    pub name: String,
    /// How often it ran.
    pub calls: u64,
    /// Its longest run.
    pub max_ms: f64,
}

/// The longest any one of the page's own handlers may run: the 50 ms frame budget.
pub const HANDLER_LIMIT_MS: f64 = 50.0;

/// The load average (1, 5, 15 minutes) as `/proc/loadavg` gives it, or "?" off Linux.
pub fn load_average() -> String {
    std::fs::read_to_string("/proc/loadavg")
        .map(|s| s.split_whitespace().take(3).collect::<Vec<_>>().join(" "))
        .unwrap_or_else(|_| "?".into())
}

/// Reads the page's record, writes it to `path` with the load at the start and now, prints the
/// figures and returns the page's handlers, longest first.
pub async fn collect(b: &Browser, path: &std::path::Path, load_at_start: &str) -> Vec<Handler> {
    let script =
        "const S = window.studio; return { long: S.longTasks, loaded: S.loadedAt, previews: S.previewLog,
        handlers: S.handlers, slow: S.slowHandlers };";
    let mut record = b.js(script, vec![]).await;
    let load_now = load_average();
    record["load"] = json!({ "start": load_at_start, "end": load_now });
    std::fs::write(path, serde_json::to_string_pretty(&record).unwrap()).expect("write the page's record");
    let long_tasks: Vec<(f64, f64)> = record["long"]
        .as_array()
        .expect("the page's long tasks")
        .iter()
        .map(|t| (t["start"].as_f64().unwrap(), t["ms"].as_f64().unwrap()))
        .collect();
    let mut handlers: Vec<Handler> = record["handlers"]
        .as_object()
        .expect("the page's handler times")
        .iter()
        .map(|(name, h): (&String, &Value)| Handler {
            name: name.clone(),
            calls: h["calls"].as_u64().unwrap(),
            max_ms: h["max"].as_f64().unwrap(),
        })
        .collect();
    handlers.sort_by(|a, b| b.max_ms.total_cmp(&a.max_ms));
    let loaded = record["loaded"].as_f64().unwrap_or(0.0);
    let longest = long_tasks.iter().map(|t| t.1).fold(0.0, f64::max);
    let after: Vec<f64> = long_tasks.iter().filter(|t| t.0 >= loaded).map(|t| t.1).collect();
    println!(
        "long tasks on the page: {} (longest {longest:.0} ms); after the first preview: {} (longest {:.0} ms); load average {load_at_start} → {load_now}",
        long_tasks.len(),
        after.len(),
        after.iter().copied().fold(0.0, f64::max)
    );
    let top: Vec<String> = handlers
        .iter()
        .take(6)
        .map(|h| format!("{} {:.1} ms ({} calls)", h.name, h.max_ms, h.calls))
        .collect();
    println!("the page's longest handlers: {}", top.join(", "));
    handlers
}
