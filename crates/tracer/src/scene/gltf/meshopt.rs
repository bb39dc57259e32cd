//! `EXT_meshopt_compression` and `KHR_meshopt_compression`: buffer views stored with
//! meshoptimizer's vertex and index codecs and its filters (gltfpack writes them). Each
//! compressed view is decoded once at load into a buffer of its own, and the view is pointed at
//! it, so accessors read it like any other view. A buffer marked as the extension's `fallback`
//! holds no data a decoder needs and is not read.
//!
//! meshoptimizer's decoders accept untrusted input (garbage in, garbage out) but `assert` their
//! size arguments, so every count, stride, mode and filter is checked here first.

use gltf::json::{Index, Root, buffer::Buffer, validation::USize64};
use serde_json::Value;

/// The extension's two names: the original and its ratified form (same layout; KHR adds the
/// COLOR filter and meshoptimizer's second vertex codec version, which the decoder reads).
pub(super) const EXTENSIONS: [&str; 2] = ["EXT_meshopt_compression", "KHR_meshopt_compression"];

/// Largest decoded view accepted: a count is not bounded by the compressed bytes, so a hostile
/// file could ask for terabytes.
const MAX_DECODED: usize = 1 << 31;

/// How a compressed view was encoded (the extension's `mode`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

/// The post-decoding transform (the extension's `filter`).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
    Color,
}

/// One compressed buffer view, as its extension object describes it.
#[derive(Clone, Debug, PartialEq)]
struct Compressed {
    view: usize,
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

/// The compressed views of a file and the buffers that are only their fallbacks.
#[derive(Debug, Default)]
pub(super) struct Views {
    compressed: Vec<Compressed>,
    /// Per buffer: the extension marks it `fallback` (its bytes are never needed).
    pub fallback: Vec<bool>,
}

impl Views {
    /// Reads the extension objects from the untyped JSON; empty when the file uses neither name.
    pub(super) fn read(raw: &Value) -> Result<Self, String> {
        let ext = |v: &Value| EXTENSIONS.iter().find_map(|name| v.get("extensions")?.get(*name).cloned());
        let list = |key: &str| raw.get(key).and_then(Value::as_array).cloned().unwrap_or_default();
        let fallback = list("buffers")
            .iter()
            .map(|b| ext(b).and_then(|e| e.get("fallback")?.as_bool()).unwrap_or(false))
            .collect();
        let mut compressed = Vec::new();
        for (view, v) in list("bufferViews").iter().enumerate() {
            if let Some(e) = ext(v) {
                compressed.push(
                    parse(view, &e).map_err(|m| format!("buffer view {view}: meshopt compression: {m}"))?,
                );
            }
        }
        Ok(Self { compressed, fallback })
    }

    /// Whether there is nothing to decode.
    pub(super) fn is_empty(&self) -> bool {
        self.compressed.is_empty()
    }

    /// Decodes every compressed view into a new buffer appended to `buffers` (and declared in
    /// `root`), and points the view at it.
    pub(super) fn decode(&self, root: &mut Root, buffers: &mut Vec<Vec<u8>>) -> Result<(), String> {
        for c in &self.compressed {
            let name = format!("buffer view {} (meshopt compressed)", c.view);
            let source =
                buffers.get(c.buffer).ok_or_else(|| format!("{name}: buffer {} does not exist", c.buffer))?;
            if self.fallback.get(c.buffer).copied().unwrap_or(false) {
                return Err(format!(
                    "{name}: its data lies in buffer {}, which is marked as a fallback",
                    c.buffer
                ));
            }
            let bytes = c.offset.checked_add(c.length).and_then(|end| source.get(c.offset..end)).ok_or_else(
                || {
                    format!(
                        "{name}: bytes {}..{} run past the end of buffer {} ({} bytes)",
                        c.offset,
                        c.offset.saturating_add(c.length),
                        c.buffer,
                        source.len()
                    )
                },
            )?;
            let decoded = decode_view(c, bytes).map_err(|m| format!("{name}: {m}"))?;
            let view = root.buffer_views.get_mut(c.view).ok_or_else(|| format!("{name} does not exist"))?;
            let declared = view.byte_length.0 as usize;
            if declared > decoded.len() {
                return Err(format!(
                    "{name}: byteLength {declared} is more than the {} bytes its {} elements of {} bytes decode to",
                    decoded.len(),
                    c.count,
                    c.stride
                ));
            }
            view.buffer = Index::new(root.buffers.len() as u32);
            view.byte_offset = Some(USize64(0));
            root.buffers.push(Buffer {
                byte_length: USize64(decoded.len() as u64),
                name: None,
                uri: None,
                extensions: None,
                extras: Default::default(),
            });
            buffers.push(decoded);
        }
        Ok(())
    }
}

/// Reads one extension object, checking what meshoptimizer's decoders would assert.
fn parse(view: usize, e: &Value) -> Result<Compressed, String> {
    let size = |key: &str, default: Option<usize>| match e.get(key) {
        Some(v) => {
            v.as_u64().and_then(|v| usize::try_from(v).ok()).ok_or_else(|| format!("{key} is not a count"))
        }
        None => default.ok_or_else(|| format!("{key} is missing")),
    };
    let mode = match e.get("mode").and_then(Value::as_str) {
        Some("ATTRIBUTES") => Mode::Attributes,
        Some("TRIANGLES") => Mode::Triangles,
        Some("INDICES") => Mode::Indices,
        other => return Err(format!("mode {other:?} is not ATTRIBUTES, TRIANGLES or INDICES")),
    };
    let filter = match e.get("filter").and_then(Value::as_str).unwrap_or("NONE") {
        "NONE" => Filter::None,
        "OCTAHEDRAL" => Filter::Octahedral,
        "QUATERNION" => Filter::Quaternion,
        "EXPONENTIAL" => Filter::Exponential,
        "COLOR" => Filter::Color,
        other => return Err(format!("filter '{other}' is not one the extension defines")),
    };
    let c = Compressed {
        view,
        buffer: size("buffer", None)?,
        offset: size("byteOffset", Some(0))?,
        length: size("byteLength", None)?,
        stride: size("byteStride", None)?,
        count: size("count", None)?,
        mode,
        filter,
    };
    let stride_ok = match c.mode {
        Mode::Attributes => c.stride > 0 && c.stride <= 256 && c.stride.is_multiple_of(4),
        Mode::Triangles | Mode::Indices => c.stride == 2 || c.stride == 4,
    };
    if !stride_ok {
        return Err(format!("byteStride {} is not allowed for mode {:?}", c.stride, c.mode));
    }
    if c.mode == Mode::Triangles && !c.count.is_multiple_of(3) {
        return Err(format!("count {} of mode TRIANGLES is not a multiple of 3", c.count));
    }
    let filter_ok = match c.filter {
        Filter::None => true,
        Filter::Octahedral | Filter::Color => c.stride == 4 || c.stride == 8,
        Filter::Quaternion => c.stride == 8,
        Filter::Exponential => c.stride.is_multiple_of(4),
    };
    if c.filter != Filter::None && c.mode != Mode::Attributes || !filter_ok {
        return Err(format!(
            "filter {:?} does not fit mode {:?} with byteStride {}",
            c.filter, c.mode, c.stride
        ));
    }
    match c.count.checked_mul(c.stride) {
        Some(n) if n <= MAX_DECODED => Ok(c),
        _ => Err(format!("{} elements of {} bytes is implausibly large", c.count, c.stride)),
    }
}

/// Decodes one view's bytes (sizes checked by [`parse`]).
fn decode_view(c: &Compressed, bytes: &[u8]) -> Result<Vec<u8>, String> {
    use meshopt::ffi;
    let mut out = vec![0u8; c.count * c.stride];
    let dst = out.as_mut_ptr().cast();
    // SAFETY: `out` holds exactly count × stride bytes, the decoders write no more, and `parse`
    // checked every size argument they assert on (stride range, index size, count % 3).
    let code = unsafe {
        match c.mode {
            Mode::Attributes => {
                ffi::meshopt_decodeVertexBuffer(dst, c.count, c.stride, bytes.as_ptr(), bytes.len())
            }
            Mode::Triangles => {
                ffi::meshopt_decodeIndexBuffer(dst, c.count, c.stride, bytes.as_ptr(), bytes.len())
            }
            Mode::Indices => {
                ffi::meshopt_decodeIndexSequence(dst, c.count, c.stride, bytes.as_ptr(), bytes.len())
            }
        }
    };
    if code != 0 {
        return Err(format!("the {:?} data does not decode (meshoptimizer error {code})", c.mode));
    }
    let dst = out.as_mut_ptr().cast();
    // SAFETY: the filters rewrite count elements of stride bytes in place, within `out`; `parse`
    // checked each filter's stride.
    unsafe {
        match c.filter {
            Filter::None => {}
            Filter::Octahedral => ffi::meshopt_decodeFilterOct(dst, c.count, c.stride),
            Filter::Quaternion => ffi::meshopt_decodeFilterQuat(dst, c.count, c.stride),
            Filter::Exponential => ffi::meshopt_decodeFilterExp(dst, c.count, c.stride),
            Filter::Color => ffi::meshopt_decodeFilterColor(dst, c.count, c.stride),
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn one(ext: Value) -> Result<Views, String> {
        Views::read(&json!({"bufferViews": [{"buffer": 0, "byteLength": 12,
            "extensions": {"EXT_meshopt_compression": ext}}]}))
    }

    #[test]
    fn scene_meshopt_sizes_the_decoders_assert_on_are_refused() {
        let base = json!({"buffer": 0, "byteLength": 8, "byteStride": 12, "count": 1, "mode": "ATTRIBUTES"});
        assert_eq!(one(base.clone()).unwrap().compressed.len(), 1);
        let with = |k: &str, v: Value| {
            let mut e = base.clone();
            e[k] = v;
            one(e).unwrap_err()
        };
        assert!(with("byteStride", json!(6)).contains("byteStride 6"));
        assert!(with("byteStride", json!(260)).contains("byteStride 260"));
        assert!(with("mode", json!("STRIPS")).contains("STRIPS"));
        assert!(with("filter", json!("QUATERNION")).contains("Quaternion"));
        assert!(with("filter", json!("ZIGZAG")).contains("ZIGZAG"));
        assert!(with("count", json!(1u64 << 40)).contains("implausibly large"));
        assert!(with("count", json!(-1)).contains("count is not a count"));
        let mut tri = base.clone();
        tri["mode"] = json!("TRIANGLES");
        tri["byteStride"] = json!(2);
        tri["count"] = json!(4);
        assert!(one(tri).unwrap_err().contains("multiple of 3"));
        let mut e = base.clone();
        e.as_object_mut().unwrap().remove("byteLength");
        assert!(one(e).unwrap_err().contains("byteLength is missing"));
    }

    #[test]
    fn scene_meshopt_round_trips_meshoptimizers_own_encoding() {
        // Vertices of 12 bytes and a triangle list, encoded by meshoptimizer, decode to the same bytes.
        let vertices: Vec<[u32; 3]> = (0..100u32).map(|i| [i, i * 7 % 13, u32::MAX - i]).collect();
        let indices: Vec<u32> = (0..99u32).map(|i| (i * 31) % 100).collect();
        let vbytes = meshopt::encoding::encode_vertex_buffer(&vertices).unwrap();
        let ibytes = meshopt::encoding::encode_index_buffer(&indices, 100).unwrap();
        let sbytes = meshopt::encoding::encode_index_sequence(&indices, 100).unwrap();
        let mut buffer = vbytes.clone();
        buffer.extend(&ibytes);
        buffer.extend(&sbytes);
        let ext = |offset: usize, length: usize, stride: usize, count: usize, mode: &str| {
            json!({"buffer": 0, "byteOffset": offset, "byteLength": length, "byteStride": stride,
                   "count": count, "mode": mode})
        };
        let raw = json!({
            "buffers": [{"byteLength": buffer.len()}, {"byteLength": 0,
                "extensions": {"KHR_meshopt_compression": {"fallback": true}}}],
            "bufferViews": [
                {"buffer": 1, "byteLength": 1200, "extensions": {"EXT_meshopt_compression":
                    ext(0, vbytes.len(), 12, 100, "ATTRIBUTES")}},
                {"buffer": 1, "byteLength": 396, "extensions": {"EXT_meshopt_compression":
                    ext(vbytes.len(), ibytes.len(), 4, 99, "TRIANGLES")}},
                {"buffer": 1, "byteLength": 396, "extensions": {"KHR_meshopt_compression":
                    ext(vbytes.len() + ibytes.len(), sbytes.len(), 4, 99, "INDICES")}}]});
        let views = Views::read(&raw).unwrap();
        assert_eq!(views.fallback, [false, true]);
        let mut root: Root = serde_json::from_value(json!({"asset": {"version": "2.0"},
            "buffers": raw["buffers"], "bufferViews": [
                {"buffer": 1, "byteLength": 1200}, {"buffer": 1, "byteLength": 396},
                {"buffer": 1, "byteLength": 396}]}))
        .unwrap();
        let mut buffers = vec![buffer, Vec::new()];
        views.decode(&mut root, &mut buffers).unwrap();
        assert_eq!(buffers.len(), 5);
        let words = |b: &[u8]| {
            b.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect::<Vec<_>>()
        };
        assert_eq!(words(&buffers[2]), vertices.concat());
        // The triangle codec may rotate a triangle's corners (keeping its winding).
        let rotated = |t: &[u32]| {
            let m = (0..3).min_by_key(|&k| t[k]).unwrap();
            [t[m], t[(m + 1) % 3], t[(m + 2) % 3]]
        };
        let triangles = |i: &[u32]| i.chunks_exact(3).map(rotated).collect::<Vec<_>>();
        assert_eq!(triangles(&words(&buffers[3])), triangles(&indices));
        assert_eq!(words(&buffers[4]), indices);
        assert_eq!(root.buffer_views[0].buffer.value(), 2);
        assert_eq!(root.buffers.len(), 5);

        // Corrupt data is an error naming the view, never a crash.
        let mut bad = vec![vec![0xA0, 1, 2, 3], Vec::new()];
        let raw = json!({"bufferViews": [{"buffer": 0, "byteLength": 1200, "extensions": {"EXT_meshopt_compression":
            ext(0, 4, 12, 100, "ATTRIBUTES")}}]});
        let mut root: Root = serde_json::from_value(json!({"asset": {"version": "2.0"},
            "buffers": [{"byteLength": 4}], "bufferViews": [{"buffer": 0, "byteLength": 1200}]}))
        .unwrap();
        let err = Views::read(&raw).unwrap().decode(&mut root, &mut bad).unwrap_err();
        assert!(err.contains("buffer view 0") && err.contains("does not decode"), "{err}");
    }
}
