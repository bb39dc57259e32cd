//! The autosave (docs/studio.md, "Autosave"): when the studio is stopped (Ctrl-C) with unsaved
//! changes, the session is saved as a project folder beside the project, `PROJECT.autosave/`,
//! never over the project itself, which holds only what the user saved. The next studio on
//! that project offers it on the page: restored, the session becomes it (still saving to the
//! project); discarded, the folder goes. A save of the project makes it obsolete and removes it.

use super::{PROJECT_FILE, open_project, save::save_into};
use crate::engine::Shared;
use crate::error::{Result, StudioError};
use crate::protocol::{Layer, Outbound};
use serde_json::json;
use std::path::{Path, PathBuf};
use std::sync::atomic::Ordering;

/// The autosave folder of `project`: `PROJECT.autosave` beside it.
pub fn autosave_dir(project: &Path) -> PathBuf {
    let mut name = project.file_name().map(|n| n.to_os_string()).unwrap_or_else(|| "studio".into());
    name.push(".autosave");
    project.with_file_name(name)
}

/// Whether the session has edits no save holds.
pub fn unsaved(shared: &Shared) -> bool {
    shared.session().edits > shared.saved_edits.load(Ordering::SeqCst)
}

/// Saves unsaved changes into the autosave folder; returns it, or `None` when there was
/// nothing unsaved (an autosave from before is then left as it is).
pub fn autosave(shared: &Shared) -> Result<Option<PathBuf>> {
    if !unsaved(shared) {
        return Ok(None);
    }
    let dir = autosave_dir(&shared.project);
    save_into(shared, &dir)?;
    Ok(Some(dir))
}

/// Marks an autosave beside the project, if there is one, to be offered to the page.
pub(super) fn offer(shared: &Shared) {
    let dir = autosave_dir(&shared.project);
    if dir.join(PROJECT_FILE).is_file() {
        *shared.autosave.lock().unwrap_or_else(|e| e.into_inner()) = Some(dir);
    }
}

/// The `autosave` message: the folder offered, or `null` once answered.
pub fn message(shared: &Shared) -> Outbound {
    let dir = shared.autosave_offered();
    let modified = dir.as_ref().and_then(|d| std::fs::metadata(d.join(PROJECT_FILE)).ok()?.modified().ok());
    let age = modified.and_then(|m| m.elapsed().ok()).map(|d| d.as_secs());
    Outbound::json(json!({"type": "autosave", "dir": dir, "age_seconds": age}))
}

/// Answers the offer: `restore` makes the session the autosave's (its keys, frame and blend;
/// the project folder stays where saves go), else the autosave folder is removed. Either way
/// every tab is told; after a restore the changes are unsaved until the next save.
pub fn answer(shared: &Shared, restore: bool) -> Result<()> {
    let dir = shared
        .autosave_offered()
        .ok_or_else(|| StudioError::request("no autosave is offered (it was restored or discarded)"))?;
    if restore {
        let (saved, source) = open_project(&dir)?;
        let mut session = shared.session();
        if saved.res != session.res || source.path != shared.source.path {
            return Err(StudioError::Project {
                path: dir.clone(),
                message: format!(
                    "the autosave is of {} at {}x{}, this session of {} at {}x{}: open it on its own with \
                     `mcctrace studio {}`",
                    source.path.display(),
                    saved.res[0],
                    saved.res[1],
                    shared.source.path.display(),
                    session.res[0],
                    session.res[1],
                    dir.display()
                ),
            });
        }
        session.keys = saved.keys;
        session.frame = saved.frame;
        session.seamless = saved.seamless;
        // The view may name a camera the kept keys do not have.
        session.view = saved.view;
        session.seq += 1;
        // Unsaved in the project until the next save (and kept again if stopped before it).
        session.edits = shared.saved_edits.load(Ordering::SeqCst) + 1;
        shared.changed(&session);
        for layer in [Layer::Labels, Layer::Regions] {
            shared.broadcast(session.labels(layer));
        }
        shared.broadcast(session.state(None));
    } else {
        std::fs::remove_dir_all(&dir).map_err(|e| StudioError::io(&dir, e))?;
    }
    *shared.autosave.lock().unwrap_or_else(|e| e.into_inner()) = None;
    shared.broadcast(message(shared));
    Ok(())
}
