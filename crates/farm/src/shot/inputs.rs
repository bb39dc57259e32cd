//! What a shot's inputs already say before any job is written (docs/farm.md, "Checked before
//! writing"): a mistake the farm would only meet after rendering every view — a camera the
//! scene lacks, a collage that is not the views' size, a layer that names no camera of its key —
//! is refused here, naming the flag, instead of failing `keys` on the farm.

use super::{Key, Plan};
use crate::{Result, bad};
use mcc::layers::{CameraNames, open_collage};
use tracer::scene::{CameraSelector, Scene};

impl Plan {
    /// Checks the shot's inputs against each other: every key's cameras are the scene's, and
    /// every collage (and region image) reads as `keys` will read it, at `--view-res`, its
    /// layers naming the key's cameras. Reads the scene and the collages (not the views, which
    /// the farm renders).
    pub fn check_inputs(&self) -> Result<()> {
        let s = &self.shot;
        let scene = tracer::job::SceneSetup::default()
            .load(&s.scene)
            .map_err(|e| bad("SCENE", format!("{}: {e}", s.scene.display())))?;
        for key in &s.keys {
            let names = camera_names(&scene, key)?;
            let ids = (1..=names.len() as u32).collect();
            let cameras = CameraNames::with_names(Some(ids), names.into_iter().zip(1..));
            let opened =
                open_collage(&key.collage, key.regions.as_deref(), &cameras, mcc::CollageOptions::default())
                    .map_err(|e| bad("--key", format!("key at frame {}: {e}", key.frame)))?;
            let found = (opened.collage.width, opened.collage.height);
            if found != s.views.res {
                let (w, h) = s.views.res;
                return Err(bad(
                    "--view-res",
                    format!(
                        "the views are rendered at {w}x{h}, but the collage of the key at frame {} ({}) is \
                         {}x{}: `keys` remaps a collage only over views of its own size; give --view-res \
                         {}x{} (or cut the collage from {w}x{h} views)",
                        key.frame,
                        key.collage.display(),
                        found.0,
                        found.1,
                        found.0,
                        found.1
                    ),
                ));
            }
        }
        Ok(())
    }
}

/// The scene names of `key`'s cameras (as `render --camera` picks them), in view order.
fn camera_names(scene: &Scene, key: &Key) -> Result<Vec<String>> {
    key.cameras
        .iter()
        .map(|c| {
            scene
                .camera(&CameraSelector::parse(c))
                .map(|d| d.name.clone())
                .map_err(|e| bad("--cameras", format!("key at frame {}: camera {c:?}: {e}", key.frame)))
        })
        .collect()
}
