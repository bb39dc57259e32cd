//! Progress reporting for long work: an indicatif bar on stderr, or nothing with `--quiet`.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

/// A progress bar over a known amount of work (pixel samples, rays, frames).
pub struct Bar {
    bar: ProgressBar,
}

impl Bar {
    /// A bar for `total` units labelled `what`; hidden when `quiet`.
    pub fn new(total: u64, what: &str, quiet: bool) -> Self {
        let bar = if quiet {
            ProgressBar::with_draw_target(Some(total), ProgressDrawTarget::hidden())
        } else {
            ProgressBar::new(total)
        };
        bar.set_style(
            ProgressStyle::with_template("{msg:>12} [{bar:40}] {percent:>3}% {elapsed_precise} (eta {eta})")
                .expect("the template is valid")
                .progress_chars("=> "),
        );
        bar.set_message(what.to_owned());
        Self { bar }
    }

    /// Finishes and removes the bar.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl tracer::render::Progress for Bar {
    fn advance(&self, samples: u64) {
        self.bar.inc(samples);
    }
}
