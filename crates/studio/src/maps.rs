//! The label and region maps of one key and their undo/redo history (docs/studio.md,
//! "Engine"): the page rasterises every tool into patches; one patch is one undo step, and so is
//! one camera edit (the history is the key's, in the order the user made them).

use crate::camera::StudioCamera;
use crate::error::{Result, StudioError};
use crate::protocol::Layer;

/// Byte of a patch that leaves its pixel as it is.
pub const KEEP: u8 = 255;

/// Undo steps kept per key; the oldest go first.
pub const HISTORY: usize = 256;

/// One step of the history: what it changed, to undo and redo it.
#[derive(Clone, Debug)]
enum Step {
    /// A patch: (pixel index, before, after) for each changed pixel of `layer`.
    Patch { layer: Layer, changes: Vec<(u32, u8, u8)> },
    /// A camera edit: the camera before and after it, and the drag it belongs to, if any.
    Camera { before: Box<StudioCamera>, after: Box<StudioCamera>, gesture: Option<u64> },
}

/// What an undo or redo changed.
#[derive(Clone, Debug, PartialEq)]
pub enum Undone {
    /// This layer's map.
    Layer(Layer),
    /// A camera: put this one in its place.
    Camera(StudioCamera),
}

/// The label map (0 background, k camera k) and region map of one key, with their history.
#[derive(Clone, Debug)]
pub struct Maps {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Camera label per pixel, row-major.
    pub labels: Vec<u8>,
    /// Region index per pixel, row-major.
    pub regions: Vec<u8>,
    undo: Vec<Step>,
    redo: Vec<Step>,
}

impl Maps {
    /// Blank maps (all background, one region).
    pub fn new(width: u32, height: u32) -> Self {
        let n = width as usize * height as usize;
        Self { width, height, labels: vec![0; n], regions: vec![0; n], undo: Vec::new(), redo: Vec::new() }
    }

    /// Maps with the given contents and an empty history.
    pub fn with(width: u32, height: u32, labels: Vec<u8>, regions: Vec<u8>) -> Self {
        Self { labels, regions, ..Self::new(width, height) }
    }

    /// The map of `layer`.
    pub fn layer(&self, layer: Layer) -> &[u8] {
        match layer {
            Layer::Labels => &self.labels,
            Layer::Regions => &self.regions,
        }
    }

    fn layer_mut(&mut self, layer: Layer) -> &mut Vec<u8> {
        match layer {
            Layer::Labels => &mut self.labels,
            Layer::Regions => &mut self.regions,
        }
    }

    /// Checks a patch of `bytes` at `rect` against the maps' size and `valid` values (255 keeps
    /// a pixel), changing nothing.
    pub fn check(&self, rect: [u32; 4], bytes: &[u8], valid: impl Fn(u8) -> bool) -> Result<()> {
        let [x, y, w, h] = rect.map(u64::from);
        if w == 0 || h == 0 || x + w > self.width as u64 || y + h > self.height as u64 {
            return Err(StudioError::request(format!(
                "rect [{x}, {y}, {w}, {h}] is empty or leaves the {}x{} map",
                self.width, self.height
            )));
        }
        if bytes.len() as u64 != w * h {
            return Err(StudioError::request(format!(
                "data has {} bytes; a {w}x{h} rect needs {}",
                bytes.len(),
                w * h
            )));
        }
        if let Some(&b) = bytes.iter().find(|&&b| b != KEEP && !valid(b)) {
            return Err(StudioError::request(format!("data holds {b}, which names no camera or region")));
        }
        Ok(())
    }

    /// Applies a checked patch as one undo step (nothing when it changes nothing); returns
    /// whether anything changed. The redo history is dropped.
    pub fn paint(&mut self, layer: Layer, rect: [u32; 4], bytes: &[u8]) -> bool {
        let [x0, y0, w, _] = rect;
        let width = self.width;
        let map = self.layer_mut(layer);
        let mut changes = Vec::new();
        for (k, &b) in bytes.iter().enumerate() {
            let (x, y) = (x0 + k as u32 % w, y0 + k as u32 / w);
            let i = (y * width + x) as usize;
            if b != KEEP && map[i] != b {
                changes.push((i as u32, map[i], b));
                map[i] = b;
            }
        }
        if changes.is_empty() {
            return false;
        }
        self.push(Step::Patch { layer, changes });
        true
    }

    /// Records a camera edit (`before` → `after`) as one undo step. The edits of one drag
    /// (the page sends one every 40 ms, all with the drag's `gesture` number) make one step:
    /// an edit of the same camera in the same gesture as the last step extends it. An edit that
    /// changes nothing records nothing, so an undo always undoes something.
    pub fn camera_edited(&mut self, before: StudioCamera, after: StudioCamera, gesture: Option<u64>) {
        if let (Some(g), Some(Step::Camera { before: first, after: last, gesture: Some(top) })) =
            (gesture, self.undo.last_mut())
            && g == *top
            && first.index == after.index
            && self.redo.is_empty()
        {
            if **first == after {
                self.undo.pop();
            } else {
                **last = after;
            }
            return;
        }
        if before != after {
            self.push(Step::Camera { before: Box::new(before), after: Box::new(after), gesture });
        }
    }

    /// A new step: the oldest goes past [`HISTORY`], the redo history is dropped.
    fn push(&mut self, step: Step) {
        self.undo.push(step);
        if self.undo.len() > HISTORY {
            self.undo.remove(0);
        }
        self.redo.clear();
    }

    /// Undoes the last step; returns what it changed, `None` when there is nothing to undo.
    pub fn undo(&mut self) -> Option<Undone> {
        let step = self.undo.pop()?;
        let undone = match &step {
            Step::Patch { layer, changes } => {
                let map = self.layer_mut(*layer);
                for &(i, before, _) in changes.iter().rev() {
                    map[i as usize] = before;
                }
                Undone::Layer(*layer)
            }
            Step::Camera { before, .. } => Undone::Camera(before.as_ref().clone()),
        };
        self.redo.push(step);
        Some(undone)
    }

    /// Redoes the last undone step; returns what it changed.
    pub fn redo(&mut self) -> Option<Undone> {
        let step = self.redo.pop()?;
        let redone = match &step {
            Step::Patch { layer, changes } => {
                let map = self.layer_mut(*layer);
                for &(i, _, after) in changes {
                    map[i as usize] = after;
                }
                Undone::Layer(*layer)
            }
            Step::Camera { after, .. } => Undone::Camera(after.as_ref().clone()),
        };
        self.undo.push(step);
        Some(redone)
    }

    /// Whether there is a step to undo.
    pub fn can_undo(&self) -> bool {
        !self.undo.is_empty()
    }

    /// Whether there is a step to redo.
    pub fn can_redo(&self) -> bool {
        !self.redo.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_undo_and_redo_exactly() {
        let mut m = Maps::new(4, 3);
        let patch = [1, 1, KEEP, 2];
        m.check([1, 1, 2, 2], &patch, |b| b <= 2).unwrap();
        assert!(m.paint(Layer::Labels, [1, 1, 2, 2], &patch));
        assert_eq!(m.labels, [0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 2, 0]);
        assert!(!m.paint(Layer::Labels, [1, 1, 2, 2], &patch), "a patch that changes nothing is no step");
        assert!(m.paint(Layer::Regions, [0, 0, 1, 1], &[3]));
        assert_eq!(m.undo(), Some(Undone::Layer(Layer::Regions)));
        assert_eq!(m.regions, [0; 12]);
        assert_eq!(m.undo(), Some(Undone::Layer(Layer::Labels)));
        assert_eq!(m.labels, [0; 12]);
        assert_eq!(m.undo(), None);
        assert_eq!(m.redo(), Some(Undone::Layer(Layer::Labels)));
        assert_eq!(m.labels, [0, 0, 0, 0, 0, 1, 1, 0, 0, 0, 2, 0]);
        assert!(m.can_redo());
        m.paint(Layer::Labels, [0, 0, 1, 1], &[2]);
        assert!(!m.can_redo(), "a new step drops the redo history");
    }

    #[test]
    fn bad_patches_are_refused_whole() {
        let m = Maps::new(4, 3);
        assert!(m.check([3, 0, 2, 1], &[1, 1], |_| true).unwrap_err().to_string().contains("leaves"));
        assert!(m.check([0, 0, 2, 1], &[1], |_| true).unwrap_err().to_string().contains("needs 2"));
        assert!(m.check([0, 0, 2, 1], &[1, 9], |b| b < 3).unwrap_err().to_string().contains("holds 9"));
        assert!(m.check([0, 0, 0, 1], &[], |_| true).is_err());
    }
}
