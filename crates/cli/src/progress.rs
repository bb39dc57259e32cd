//! Progress on the terminal (docs/design/workflow.md §8: long work shows progress): the libraries
//! report stages and their units through [`tracer::render::Progress`]; this draws each stage as
//! an indicatif bar on stderr, or nothing with `--quiet`. The command line never cancels.

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::sync::Mutex;

/// One bar per stage, replaced when the next stage begins.
pub struct Bars {
    quiet: bool,
    current: Mutex<Option<ProgressBar>>,
    /// Drawn below a [`ShotBar`] when set.
    multi: Option<MultiProgress>,
}

impl Bars {
    /// Bars on stderr; none when `quiet`.
    pub fn new(quiet: bool) -> Self {
        Self { quiet, current: Mutex::new(None), multi: None }
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
        let bar = match &self.multi {
            Some(multi) => multi.add(ProgressBar::new(total)),
            None => ProgressBar::new(total),
        };
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

/// A bar for a whole shot (frames done of the frames to render, with an ETA) above the frames'
/// own bars: `animate`'s progress.
pub struct ShotBar {
    multi: MultiProgress,
    bar: ProgressBar,
    quiet: bool,
}

impl ShotBar {
    /// A bar for `frames` frames on stderr; hidden (still counting) when `quiet`.
    pub fn new(frames: u64, quiet: bool) -> Self {
        let target = if quiet { ProgressDrawTarget::hidden() } else { ProgressDrawTarget::stderr() };
        let multi = MultiProgress::with_draw_target(target);
        let bar = multi.add(ProgressBar::new(frames));
        bar.set_style(
            ProgressStyle::with_template(
                "{msg:>12} [{bar:40}] {pos}/{len} frames {elapsed_precise} (eta {eta})",
            )
            .expect("the template is valid")
            .progress_chars("=> "),
        );
        bar.set_message("shot");
        Self { multi, bar, quiet }
    }

    /// The bars of one frame's stages, drawn below the shot's.
    pub fn frame_bars(&self) -> Bars {
        Bars { quiet: self.quiet, current: Mutex::new(None), multi: Some(self.multi.clone()) }
    }

    /// Says a frame is done, printing `line` above the bars.
    pub fn frame_done(&self, line: &str) {
        if !self.quiet {
            self.multi.suspend(|| eprintln!("{line}"));
        }
        self.bar.inc(1);
    }

    /// Removes the bars.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tracer::render::Progress;

    /// The shot's bar counts frames; the frames' bars draw in the same group.
    #[test]
    fn the_shot_bar_counts_frames() {
        let shot = ShotBar::new(3, true);
        let frame = shot.frame_bars();
        assert!(frame.multi.is_some());
        frame.begin("frame 0", 10);
        frame.advance(10);
        frame.finish();
        shot.frame_done("frame 0 done");
        shot.frame_done("frame 1 done");
        assert_eq!((shot.bar.position(), shot.bar.length()), (2, Some(3)));
        shot.finish();
    }
}
