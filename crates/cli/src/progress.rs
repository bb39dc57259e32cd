//! Progress on the terminal (docs/design.md §8: long work shows progress): the libraries
//! report stages and their units through [`tracer::render::Progress`]; this draws each stage as
//! an indicatif bar on stderr, or nothing with `--quiet`. The command line never cancels.

use indicatif::{ProgressBar, ProgressStyle};
use std::sync::Mutex;

/// One bar per stage, replaced when the next stage begins.
pub struct Bars {
    quiet: bool,
    current: Mutex<Option<ProgressBar>>,
}

impl Bars {
    /// Bars on stderr; none when `quiet`.
    pub fn new(quiet: bool) -> Self {
        Self { quiet, current: Mutex::new(None) }
    }

    fn current(&self) -> std::sync::MutexGuard<'_, Option<ProgressBar>> {
        // A panic elsewhere cannot leave a bar half-updated: keep drawing.
        self.current.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl tracer::render::Progress for Bars {
    fn begin(&self, label: &str, total: u64) {
        if self.quiet {
            return;
        }
        let bar = ProgressBar::new(total);
        bar.set_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})")
                .expect("the template is valid")
                .progress_chars("=> "),
        );
        bar.set_message(label.to_owned());
        if let Some(old) = self.current().replace(bar) {
            old.finish_and_clear();
        }
    }

    fn advance(&self, units: u64) {
        if let Some(bar) = &*self.current() {
            bar.inc(units);
        }
    }

    fn finish(&self) {
        if let Some(bar) = self.current().take() {
            bar.finish_and_clear();
        }
    }
}
