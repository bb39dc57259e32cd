//! How a job reports as it goes (docs/design.md §8: long work shows progress; the libraries never
//! print): the stages of the render under way through [`tracer::render::Progress`], and what the
//! job did or found as events of its own type, which the caller words (or ignores).

use tracer::render::{NoProgress, Progress};

/// Where a job reports: its renders' stages, and its events `E`.
pub trait JobProgress<E>: Sync {
    /// The progress of the stages of the render under way (a frame's, a view's).
    fn stages(&self) -> &dyn Progress;
    /// Something the job did or found, for the caller to tell (or not).
    fn event(&self, event: E);
}

/// A sink that draws nothing and ignores every event.
pub struct Silent;

impl<E> JobProgress<E> for Silent {
    fn stages(&self) -> &dyn Progress {
        &NoProgress
    }

    fn event(&self, _event: E) {}
}
