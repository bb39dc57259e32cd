//! What each message does (docs/studio.md, "Protocol"): edits go through the session under its
//! lock, each one checked whole first (a malformed message changes nothing); the changed state
//! goes to every tab and wakes the engine.

use crate::engine::Shared;
use crate::error::Result;
use crate::protocol::{Envelope, Layer, Outbound, Request};
use serde_json::json;
use std::sync::Arc;

/// Runs one message; returns the replies for the tab that sent it (changes are broadcast).
pub fn handle(shared: &Arc<Shared>, envelope: Envelope) -> Vec<Outbound> {
    let id = envelope.id;
    match run(shared, id, envelope.request) {
        Ok(replies) => replies,
        Err(e) => vec![Outbound::error(id, e.to_string())],
    }
}

/// The whole current state, as `hello` answers it (reply id `id`): the state, both maps and the
/// latest picture of each kind.
pub fn current(shared: &Shared, id: Option<u64>) -> Vec<Outbound> {
    let session = shared.session();
    let mut all = vec![session.state(id), session.labels(Layer::Labels), session.labels(Layer::Regions)];
    drop(session);
    all.extend(shared.latest());
    if shared.autosave_offered().is_some() {
        all.push(crate::project::autosave::message(shared));
    }
    all
}

fn run(shared: &Arc<Shared>, id: Option<u64>, request: Request) -> Result<Vec<Outbound>> {
    let mut session = shared.session();
    let mut layers: Vec<Layer> = Vec::new();
    match request {
        Request::Hello => {
            drop(session);
            return Ok(current(shared, id));
        }
        Request::Paint { layer, rect, data } => {
            if session.paint(layer, rect, &data)? {
                // Every tab sees the stroke (docs/studio.md, "Protocol").
                layers.push(layer);
            }
        }
        Request::Undo | Request::Redo => {
            let redo = matches!(request, Request::Redo);
            layers.extend(session.undo(redo).flatten());
        }
        Request::CameraEdit(edit) => session.edit_camera(&edit)?,
        Request::CameraDuplicate { index } => {
            session.duplicate_camera(index)?;
        }
        Request::View { mode, camera } => session.set_view(mode, camera)?,
        Request::Settings { seamless } => session.set_seamless(seamless),
        Request::Denoise { on } => session.set_denoise(on),
        Request::Frame { frame } => {
            session.switch_frame(frame, || shared.source.cameras(frame))?;
            layers.extend([Layer::Labels, Layer::Regions]);
        }
        Request::Save => {
            drop(session);
            let dir = crate::project::save(shared)?;
            return Ok(vec![Outbound::json(json!({"type": "saved", "id": id, "dir": dir}))]);
        }
        Request::RenderFinal { res, spp, shutter } => {
            drop(session);
            let shutter = shutter.map_or((0.0, 0.0), |[open, close]| (open, close));
            crate::project::start_final(shared, id, res, spp, shutter)?;
            return Ok(Vec::new());
        }
        Request::CancelFinal => {
            shared.final_cancel.store(true, std::sync::atomic::Ordering::SeqCst);
            return Ok(Vec::new());
        }
        Request::Autosave { restore } => {
            drop(session);
            crate::project::autosave::answer(shared, restore)?;
            return Ok(Vec::new());
        }
    }
    shared.changed(&session);
    for layer in layers {
        shared.broadcast(session.labels(layer));
    }
    shared.broadcast(session.state(id));
    Ok(Vec::new())
}
