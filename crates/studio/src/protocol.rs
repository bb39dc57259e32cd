//! The messages between the page and the server (docs/studio.md, "Protocol"): JSON text
//! messages `{"type": …, "id": n, …}` from the page; JSON text and PNG binary messages back.

use serde::{Deserialize, Serialize};
use serde_json::{Value, json};

/// Which map a paint patch edits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Layer {
    /// Camera labels: 0 background, k camera k.
    Labels,
    /// Region indices: 0 the default region, k region k.
    Regions,
}

/// What the canvas shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Deserialize, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ViewMode {
    /// The remapped rerender preview.
    #[default]
    Final,
    /// The label map in the cameras' colours.
    Labels,
    /// One camera's source view.
    Source,
    /// One camera's remapper weights.
    Weights,
    /// The camera with the largest weight per pixel.
    Dominant,
    /// The region map.
    Regions,
}

/// A camera as the page edits it.
#[derive(Clone, Copy, Debug, Deserialize)]
pub struct CameraEdit {
    /// The camera's 1-based tag number.
    pub index: u32,
    /// Eye position.
    pub eye: [f32; 3],
    /// The point looked at.
    pub target: [f32; 3],
    /// Roughly up.
    pub up: [f32; 3],
    /// Vertical field of view in degrees.
    pub fov_deg: f32,
    /// The drag this edit belongs to (the page numbers its drags): one drag is one undo step.
    #[serde(default)]
    pub gesture: Option<u64>,
}

/// A message from the page.
#[derive(Clone, Debug, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case")]
pub enum Request {
    /// Ask for the whole state (and the maps and latest images).
    Hello,
    /// Overwrite a rectangle of a map; byte 255 leaves a pixel as it is. One undo step.
    Paint {
        /// The map.
        layer: Layer,
        /// x, y, width, height.
        rect: [u32; 4],
        /// base64 of width × height bytes.
        data: String,
    },
    /// Undo the last paint.
    Undo,
    /// Redo the last undone paint.
    Redo,
    /// Move a camera or change its field of view.
    CameraEdit(CameraEdit),
    /// Copy a camera as a new one.
    CameraDuplicate {
        /// The camera to copy.
        index: u32,
    },
    /// Switch what the canvas shows.
    View {
        /// The picture.
        mode: ViewMode,
        /// The camera, for `source` and `weights`.
        camera: Option<u32>,
    },
    /// Change the remapper's settings.
    Settings {
        /// The seamless blend (`--seamless`).
        seamless: bool,
    },
    /// Show the preview and thumbnails denoised, or their raw samples.
    Denoise {
        /// Denoised.
        on: bool,
    },
    /// Switch to (or create) the key at a frame.
    Frame {
        /// The frame.
        frame: u32,
    },
    /// Write the project folder.
    Save,
    /// Render the final image.
    RenderFinal {
        /// Output width and height.
        res: [u32; 2],
        /// Samples per pixel.
        spp: u32,
        /// Motion blur, as `rerender --shutter OPEN..CLOSE`: \[open, close\] in frames after the
        /// key's frame (0 ≤ open ≤ close ≤ 1); absent: none.
        #[serde(default)]
        shutter: Option<[f32; 2]>,
    },
    /// Stop the final render.
    CancelFinal,
    /// Answer the offer of an earlier session's autosave.
    Autosave {
        /// Restore it (else discard it).
        restore: bool,
    },
}

/// A parsed message with its id.
#[derive(Clone, Debug)]
pub struct Envelope {
    /// The page's id, echoed in the reply.
    pub id: Option<u64>,
    /// The request.
    pub request: Request,
}

impl Envelope {
    /// Parses a text message; the error is what the `error` reply says.
    pub fn parse(text: &str) -> Result<Self, (Option<u64>, String)> {
        let value: Value = serde_json::from_str(text).map_err(|e| (None, format!("not JSON: {e}")))?;
        let id = value.get("id").and_then(Value::as_u64);
        if !value.is_object() {
            return Err((id, "a message is a JSON object with a \"type\"".into()));
        }
        let request = serde_json::from_value(value).map_err(|e| (id, format!("bad message: {e}")))?;
        Ok(Self { id, request })
    }
}

/// A message to the page.
#[derive(Clone, Debug, PartialEq)]
pub enum Outbound {
    /// A JSON text message.
    Text(String),
    /// An image: its JSON header, then the PNG bytes as one binary message.
    Image {
        /// The header (`{"type":"image", …}`).
        header: String,
        /// The PNG.
        png: Vec<u8>,
    },
}

impl Outbound {
    /// A JSON message.
    pub fn json(value: Value) -> Self {
        Self::Text(value.to_string())
    }

    /// An `error` reply to message `id`.
    pub fn error(id: Option<u64>, message: impl Into<String>) -> Self {
        Self::json(json!({"type": "error", "id": id, "message": message.into()}))
    }
}

/// What kind of picture an image message carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ImageKind {
    /// The canvas's rerender preview.
    Preview,
    /// A camera's thumbnail.
    Thumb,
    /// The picture of the current view mode.
    View,
    /// The final render.
    Final,
}

/// The header of an image message.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct ImageHeader {
    /// What the picture is.
    pub kind: ImageKind,
    /// The camera it shows, if one.
    pub camera: Option<u32>,
    /// The state it was made from (the page drops older ones).
    pub seq: u64,
    /// Samples per pixel (0 for pictures that are not renders).
    pub spp: u32,
    /// Width.
    pub w: u32,
    /// Height.
    pub h: u32,
}

impl ImageHeader {
    /// The image message carrying `png`.
    pub fn message(&self, png: Vec<u8>) -> Outbound {
        let mut value = serde_json::to_value(self).expect("a header serialises");
        value["type"] = json!("image");
        Outbound::Image { header: value.to_string(), png }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_requests_and_keeps_the_id_of_bad_ones() {
        let e = Envelope::parse(r#"{"type":"paint","id":7,"layer":"labels","rect":[1,2,3,4],"data":"AA=="}"#)
            .unwrap();
        assert_eq!(e.id, Some(7));
        assert!(matches!(e.request, Request::Paint { layer: Layer::Labels, rect: [1, 2, 3, 4], .. }));
        let e = Envelope::parse(r#"{"type":"view","mode":"weights","camera":2}"#).unwrap();
        assert!(matches!(e.request, Request::View { mode: ViewMode::Weights, camera: Some(2) }));
        assert_eq!(Envelope::parse(r#"{"type":"paint","id":3}"#).unwrap_err().0, Some(3));
        assert_eq!(Envelope::parse(r#"{"type":"fly","id":4}"#).unwrap_err().0, Some(4));
        assert_eq!(Envelope::parse("[1]").unwrap_err().0, None);
        assert!(Envelope::parse("{").unwrap_err().1.starts_with("not JSON"));
    }
}
