//! The studio's engine (docs/studio.md, "Engine"): the session shared by every tab, and the
//! preview worker that, after each change, recomputes what changed and streams pictures — the
//! changed cameras' thumbnails, a coarse full-frame preview, the view picture, then full
//! resolution with more samples while idle. A newer change cancels stale work between tiles.

pub mod pictures;
pub mod priority;
pub mod worker;

use crate::error::Result;
use crate::protocol::{ImageKind, Outbound};
use crate::session::Session;
use crate::source::SceneSource;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, MutexGuard};
use tokio::sync::broadcast;
use tracer::render::Progress;

pub use worker::Worker;

/// How much the engine renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EngineSettings {
    /// The idle preview's last sample count (it doubles from 1 up to this; the coarse first
    /// preview takes 1).
    pub preview_spp: u32,
    /// Samples of a source view at the collage resolution (saved views too).
    pub view_spp: u32,
    /// The coarse preview and thumbnails are the collage resolution divided by this.
    pub coarse_divisor: u32,
    /// The nice value the render threads run at, at least (`priority`; `None`: as started).
    pub render_nice: Option<i32>,
}

impl Default for EngineSettings {
    fn default() -> Self {
        Self { preview_spp: 16, view_spp: 4, coarse_divisor: 4, render_nice: Some(priority::RENDER_NICE) }
    }
}

/// What every connection and the worker share.
pub struct Shared {
    /// The editable state.
    session: Mutex<Session>,
    /// The session's `seq`, readable without the lock (for cancellation).
    seq: AtomicU64,
    wake: Condvar,
    /// Messages to every connected page.
    pub out: broadcast::Sender<Outbound>,
    /// The scene.
    pub source: SceneSource,
    /// Rendering settings.
    pub settings: EngineSettings,
    /// The project folder saves go to.
    pub project: PathBuf,
    /// The latest picture of each (kind, camera), for a page that says hello later.
    latest: Mutex<BTreeMap<(u8, u32), Outbound>>,
    stop: AtomicBool,
    /// A final render is running.
    pub final_running: AtomicBool,
    /// Asks the final render to stop.
    pub final_cancel: AtomicBool,
    /// Serialises saves (several tabs: the last save wins, whole).
    pub save_lock: Mutex<()>,
    /// The session's `edits` when it was last saved (or opened): fewer than now means unsaved
    /// changes, which stopping the studio keeps in the autosave.
    pub saved_edits: AtomicU64,
    /// An autosave an earlier session left beside the project, offered to the page until it is
    /// restored or discarded.
    pub autosave: Mutex<Option<PathBuf>>,
    /// The threads every preview, save and final render runs on, below the page's priority.
    pub pool: rayon::ThreadPool,
}

impl Shared {
    /// Shared state around `session`.
    pub fn new(
        session: Session,
        source: SceneSource,
        settings: EngineSettings,
        project: PathBuf,
    ) -> Result<Self> {
        let (out, _) = broadcast::channel(256);
        let nice = settings.render_nice;
        let pool = rayon::ThreadPoolBuilder::new()
            .thread_name(|i| format!("studio-render-{i}"))
            .start_handler(move |_| nice.into_iter().for_each(priority::lower_current_thread))
            .build()
            .map_err(|e| crate::error::StudioError::Server(format!("starting the render threads: {e}")))?;
        Ok(Self {
            seq: AtomicU64::new(session.seq),
            saved_edits: AtomicU64::new(session.edits),
            autosave: Mutex::new(None),
            session: Mutex::new(session),
            wake: Condvar::new(),
            out,
            source,
            settings,
            project,
            latest: Mutex::new(BTreeMap::new()),
            stop: AtomicBool::new(false),
            final_running: AtomicBool::new(false),
            final_cancel: AtomicBool::new(false),
            save_lock: Mutex::new(()),
            pool,
        })
    }

    /// The autosave offered to the page, if any.
    pub fn autosave_offered(&self) -> Option<PathBuf> {
        self.autosave.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// The session, locked (a panic elsewhere does not lock it forever).
    pub fn session(&self) -> MutexGuard<'_, Session> {
        self.session.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Call after editing `session` (still locked): publishes its seq, which cancels stale
    /// work, and wakes the worker.
    pub fn changed(&self, session: &Session) {
        self.seq.store(session.seq, Ordering::SeqCst);
        self.wake.notify_all();
    }

    /// The current seq.
    pub fn seq(&self) -> u64 {
        self.seq.load(Ordering::SeqCst)
    }

    /// Sends `message` to every page.
    pub fn broadcast(&self, message: Outbound) {
        let _ = self.out.send(message);
    }

    /// Sends a picture to every page and keeps it for pages that join later.
    pub fn picture(&self, kind: ImageKind, camera: Option<u32>, message: Outbound) {
        let slot = (kind as u8, camera.unwrap_or(0));
        self.latest.lock().unwrap_or_else(|e| e.into_inner()).insert(slot, message.clone());
        self.broadcast(message);
    }

    /// The latest pictures.
    pub fn latest(&self) -> Vec<Outbound> {
        self.latest.lock().unwrap_or_else(|e| e.into_inner()).values().cloned().collect()
    }

    /// Stops the worker.
    pub fn stop(&self) {
        self.stop.store(true, Ordering::SeqCst);
        let _guard = self.session();
        self.seq.fetch_add(1, Ordering::SeqCst);
        self.wake.notify_all();
    }

    /// Waits until the session's seq differs from `done` (or the engine stops); returns the
    /// session, locked, or `None` when stopping.
    fn wait_for_change(&self, done: u64) -> Option<MutexGuard<'_, Session>> {
        let mut session = self.session();
        while session.seq == done && !self.stop.load(Ordering::SeqCst) {
            session = self.wake.wait(session).unwrap_or_else(|e| e.into_inner());
        }
        (!self.stop.load(Ordering::SeqCst)).then_some(session)
    }
}

/// Progress of the preview: cancelled as soon as the state moves past `seq`.
pub struct Stale<'a> {
    shared: &'a Shared,
    seq: u64,
}

impl<'a> Stale<'a> {
    /// Work for state `seq`.
    pub fn new(shared: &'a Shared, seq: u64) -> Self {
        Self { shared, seq }
    }

    /// Whether newer state exists.
    pub fn is_stale(&self) -> bool {
        self.shared.seq() != self.seq || self.shared.stop.load(Ordering::SeqCst)
    }

    /// `Err(Cancelled)` when stale.
    pub fn check(&self) -> Result<()> {
        if self.is_stale() { Err(crate::error::StudioError::Cancelled) } else { Ok(()) }
    }
}

impl Progress for Stale<'_> {
    fn advance(&self, _samples: u64) {}

    fn cancelled(&self) -> bool {
        self.is_stale()
    }
}

/// Opens the denoiser (when it is installed) on a render thread, before any page can ask for it.
/// OIDN's CPU device filters on threads of its own, which whichever thread opens the device
/// starts and which keep that thread's priority: opened by a socket handler (the `state` message
/// names the denoiser's version), the preview's denoise ran at the page's nice 0, above the
/// renders (docs/performance.md §1.7).
pub fn open_denoiser(shared: &Shared) {
    shared.pool.install(|| {
        let _ = tracer::denoise::Denoiser::shared();
    });
}

/// Starts the preview worker on its own thread.
pub fn start_worker(shared: Arc<Shared>) -> std::thread::JoinHandle<()> {
    std::thread::Builder::new()
        .name("studio-preview".into())
        .spawn(move || {
            shared.settings.render_nice.into_iter().for_each(priority::lower_current_thread);
            Worker::new(shared).run()
        })
        .expect("a thread starts")
}

#[cfg(all(test, target_os = "linux"))]
mod tests;
