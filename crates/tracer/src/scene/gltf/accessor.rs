//! Accessor reading with every offset, stride and count checked against the buffers. The gltf
//! crate's own reader asserts (panics) when an accessor's type or stride does not match what is
//! read, and its offset arithmetic can overflow on hostile counts: here every such case is a
//! message naming the accessor.

use glam::{Vec2, Vec3, Vec4};
use gltf::accessor::sparse::IndexType;
use gltf::accessor::{Accessor, DataType, Dimensions};

use super::precheck::MAX_VIEWLESS_COUNT;

/// Element types of `POSITION` and `TEXCOORD_n`: floats, or any 8- or 16-bit integer,
/// normalised or not, as `KHR_mesh_quantization` allows (the node's transform dequantises).
pub(super) const QUANTIZED: &[(DataType, bool)] = &[
    (DataType::F32, false),
    (DataType::I8, false),
    (DataType::I8, true),
    (DataType::U8, false),
    (DataType::U8, true),
    (DataType::I16, false),
    (DataType::I16, true),
    (DataType::U16, false),
    (DataType::U16, true),
];

/// Floats only: core glTF's type for `POSITION`, `NORMAL`, `TANGENT` and animation outputs.
pub(super) const FLOAT: &[(DataType, bool)] = &[(DataType::F32, false)];

/// Element types of `NORMAL` and `TANGENT`: floats, or normalised signed bytes or shorts
/// (`KHR_mesh_quantization`).
pub(super) const UNIT: &[(DataType, bool)] =
    &[(DataType::F32, false), (DataType::I8, true), (DataType::I16, true)];

/// Element types of core glTF's `TEXCOORD_n`: floats or normalised unsigned bytes or shorts.
const CORE_UV: &[(DataType, bool)] = &[(DataType::F32, false), (DataType::U8, true), (DataType::U16, true)];

/// Reads a `VEC3` accessor whose element type is one of `allowed` (`POSITION`, `NORMAL`, an
/// animation's translation or scale output).
pub(super) fn read_vec3(
    acc: &Accessor,
    buffers: &[Vec<u8>],
    semantic: &str,
    allowed: &[(DataType, bool)],
) -> Result<Vec<Vec3>, String> {
    expect(acc, semantic, Dimensions::Vec3, allowed)?;
    let values = read(acc, buffers)?;
    Ok(values.chunks_exact(3).map(|c| Vec3::new(c[0] as f32, c[1] as f32, c[2] as f32)).collect())
}

/// Reads a `TANGENT` accessor: `VEC4` (xyz, w = bitangent sign) of an element type in `allowed`.
pub(super) fn read_vec4(
    acc: &Accessor,
    buffers: &[Vec<u8>],
    semantic: &str,
    allowed: &[(DataType, bool)],
) -> Result<Vec<Vec4>, String> {
    expect(acc, semantic, Dimensions::Vec4, allowed)?;
    let values = read(acc, buffers)?;
    Ok(values
        .chunks_exact(4)
        .map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32))
        .collect())
}

/// Reads a `TEXCOORD_n` accessor: `VEC2` of floats or normalised unsigned bytes/shorts, or with
/// `quantized` (the file uses `KHR_mesh_quantization`) any of [`QUANTIZED`].
pub(super) fn read_uv(
    acc: &Accessor,
    buffers: &[Vec<u8>],
    semantic: &str,
    quantized: bool,
) -> Result<Vec<Vec2>, String> {
    expect(acc, semantic, Dimensions::Vec2, if quantized { QUANTIZED } else { CORE_UV })?;
    let values = read(acc, buffers)?;
    Ok(values.chunks_exact(2).map(|c| Vec2::new(c[0] as f32, c[1] as f32)).collect())
}

/// Reads a `JOINTS_n` accessor: `VEC4` of unsigned bytes or shorts (not normalised).
pub(super) fn read_joints(
    acc: &Accessor,
    buffers: &[Vec<u8>],
    semantic: &str,
) -> Result<Vec<[u16; 4]>, String> {
    expect(acc, semantic, Dimensions::Vec4, &[(DataType::U8, false), (DataType::U16, false)])?;
    let values = read(acc, buffers)?;
    // Bytes and shorts hold their values exactly in f64 and fit u16.
    Ok(values.chunks_exact(4).map(|c| [c[0] as u16, c[1] as u16, c[2] as u16, c[3] as u16]).collect())
}

/// Reads a `WEIGHTS_n` accessor: `VEC4` of floats or normalised unsigned bytes or shorts.
pub(super) fn read_weights(acc: &Accessor, buffers: &[Vec<u8>], semantic: &str) -> Result<Vec<Vec4>, String> {
    read_vec4(acc, buffers, semantic, CORE_UV)
}

/// Reads a skin's `inverseBindMatrices`: `MAT4` of floats, column-major.
pub(super) fn read_mat4(acc: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<glam::Mat4>, String> {
    expect(acc, "inverseBindMatrices", Dimensions::Mat4, FLOAT)?;
    let values = read(acc, buffers)?;
    Ok(values
        .chunks_exact(16)
        .map(|c| glam::Mat4::from_cols_array(&std::array::from_fn(|i| c[i] as f32)))
        .collect())
}

/// Reads a `COLOR_n` accessor: `VEC3` or `VEC4` of floats or normalised unsigned bytes/shorts
/// (glTF §3.7.2.1), as linear RGBA (alpha 1 for `VEC3`).
pub(super) fn read_color(acc: &Accessor, buffers: &[Vec<u8>], semantic: &str) -> Result<Vec<Vec4>, String> {
    let allowed = [(DataType::F32, false), (DataType::U8, true), (DataType::U16, true)];
    let dims = if acc.dimensions() == Dimensions::Vec3 { Dimensions::Vec3 } else { Dimensions::Vec4 };
    expect(acc, semantic, dims, &allowed)?;
    let values = read(acc, buffers)?;
    Ok(match dims {
        Dimensions::Vec3 => {
            values.chunks_exact(3).map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, 1.0)).collect()
        }
        _ => values
            .chunks_exact(4)
            .map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32))
            .collect(),
    })
}

/// Reads an index accessor: `SCALAR` unsigned bytes, shorts or ints.
pub(super) fn read_indices(acc: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<u32>, String> {
    let allowed = [(DataType::U8, false), (DataType::U16, false), (DataType::U32, false)];
    expect(acc, "indices", Dimensions::Scalar, &allowed)?;
    // f64 holds every u32 exactly, so the round trip is lossless.
    Ok(read(acc, buffers)?.into_iter().map(|v| v as u32).collect())
}

/// Reads an animation sampler's input: `SCALAR` floats (key times in seconds).
pub(super) fn read_times(acc: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<f32>, String> {
    expect(acc, "animation input", Dimensions::Scalar, &[(DataType::F32, false)])?;
    Ok(read(acc, buffers)?.into_iter().map(|v| v as f32).collect())
}

/// Reads an animation sampler's `weights` output: `SCALAR` floats or normalised integers.
pub(super) fn read_scalars(acc: &Accessor, buffers: &[Vec<u8>], what: &str) -> Result<Vec<f32>, String> {
    let allowed = [
        (DataType::F32, false),
        (DataType::I8, true),
        (DataType::U8, true),
        (DataType::I16, true),
        (DataType::U16, true),
    ];
    expect(acc, what, Dimensions::Scalar, &allowed)?;
    Ok(read(acc, buffers)?.into_iter().map(|v| v as f32).collect())
}

/// Reads an animation sampler's rotation output: `VEC4` quaternions (xyzw) of floats or
/// normalised bytes or shorts (glTF §3.11).
pub(super) fn read_rotations(acc: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<Vec4>, String> {
    let allowed = [
        (DataType::F32, false),
        (DataType::I8, true),
        (DataType::U8, true),
        (DataType::I16, true),
        (DataType::U16, true),
    ];
    expect(acc, "rotation output", Dimensions::Vec4, &allowed)?;
    let values = read(acc, buffers)?;
    Ok(values
        .chunks_exact(4)
        .map(|c| Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32))
        .collect())
}

/// Checks an accessor's element type against what its use allows.
fn expect(acc: &Accessor, what: &str, dims: Dimensions, allowed: &[(DataType, bool)]) -> Result<(), String> {
    let (ty, norm) = (acc.data_type(), acc.normalized());
    if acc.dimensions() == dims && allowed.contains(&(ty, norm)) {
        return Ok(());
    }
    // A quantized type in a file that does not declare the extension: say which one would allow it.
    let hint = if acc.dimensions() == dims && QUANTIZED.contains(&(ty, norm)) {
        " (KHR_mesh_quantization allows it, but the file does not list that extension in extensionsUsed)"
    } else {
        ""
    };
    Err(format!(
        "accessor {} used as {what} is {:?} of {ty:?}{}, which glTF does not allow there{hint}",
        acc.index(),
        acc.dimensions(),
        if norm { " (normalized)" } else { "" }
    ))
}

fn component_size(ty: DataType) -> usize {
    match ty {
        DataType::I8 | DataType::U8 => 1,
        DataType::I16 | DataType::U16 => 2,
        DataType::U32 | DataType::F32 => 4,
    }
}

/// One component from exactly `component_size(ty)` bytes, normalised as glTF §3.11 says.
fn decode(ty: DataType, normalized: bool, c: &[u8]) -> f64 {
    let (v, max) = match (ty, c) {
        (DataType::I8, &[a]) => (f64::from(a as i8), 127.0),
        (DataType::U8, &[a]) => (f64::from(a), 255.0),
        (DataType::I16, &[a, b]) => (f64::from(i16::from_le_bytes([a, b])), 32767.0),
        (DataType::U16, &[a, b]) => (f64::from(u16::from_le_bytes([a, b])), 65535.0),
        (DataType::U32, &[a, b, c, d]) => (f64::from(u32::from_le_bytes([a, b, c, d])), 1.0),
        (DataType::F32, &[a, b, c, d]) => return f64::from(f32::from_le_bytes([a, b, c, d])),
        _ => return f64::NAN, // unreachable: callers slice by component_size
    };
    if normalized { (v / max).max(-1.0) } else { v }
}

/// All `count × components` values of an accessor, sparse substitutions applied.
fn read(acc: &Accessor, buffers: &[Vec<u8>]) -> Result<Vec<f64>, String> {
    let (ty, norm) = (acc.data_type(), acc.normalized());
    let dims = acc.dimensions().multiplicity();
    let size = component_size(ty);
    let elem = dims * size;
    let count = acc.count();
    let name = format!("accessor {}", acc.index());
    let total = count.checked_mul(dims).ok_or_else(|| format!("{name}: count {count} is too large"))?;
    let decode_elem = |bytes: &[u8], out: &mut [f64]| {
        for (o, c) in out.iter_mut().zip(bytes.chunks_exact(size)) {
            *o = decode(ty, norm, c);
        }
    };

    let mut out = match acc.view() {
        Some(view) => {
            let stride = view.stride().unwrap_or(elem);
            if stride < elem {
                return Err(format!("{name}: byteStride {stride} is smaller than its {elem}-byte elements"));
            }
            let bytes = elements(&view, acc.offset(), stride, elem, count, buffers, &name)?;
            let mut out = vec![0.0; total];
            for (i, o) in out.chunks_exact_mut(dims.max(1)).enumerate() {
                let e = bytes
                    .get(i * stride..i * stride + elem)
                    .ok_or_else(|| format!("{name}: element {i} is out of bounds"))?;
                decode_elem(e, o);
            }
            out
        }
        None if count > MAX_VIEWLESS_COUNT => {
            return Err(format!("{name}: count {count} without a buffer view is implausibly large"));
        }
        None => vec![0.0; total],
    };

    if let Some(sparse) = acc.sparse() {
        let n = sparse.count();
        let sname = format!("{name} (sparse)");
        if n > count {
            return Err(format!("{sname}: {n} substitutions for {count} elements"));
        }
        let indices = sparse.indices();
        let (isize, ity) = match indices.index_type() {
            IndexType::U8 => (1, DataType::U8),
            IndexType::U16 => (2, DataType::U16),
            IndexType::U32 => (4, DataType::U32),
        };
        // Sparse index and value views are tightly packed (glTF forbids a byteStride there).
        let ibytes = elements(&indices.view(), indices.offset(), isize, isize, n, buffers, &sname)?;
        let values = sparse.values();
        let vbytes = elements(&values.view(), values.offset(), elem, elem, n, buffers, &sname)?;
        for (k, (ib, vb)) in ibytes.chunks_exact(isize).zip(vbytes.chunks_exact(elem.max(1))).enumerate() {
            let target = decode(ity, false, ib) as usize;
            let slot = out
                .get_mut(target * dims..(target + 1) * dims)
                .ok_or_else(|| format!("{sname}: substitution {k} targets element {target} of {count}"))?;
            decode_elem(vb, slot);
        }
    }
    Ok(out)
}

/// The bytes spanning `count` elements of `elem` bytes, `stride` apart, from `offset` bytes into
/// `view`, checked against the view and the view against its buffer.
fn elements<'b>(
    view: &gltf::buffer::View,
    offset: usize,
    stride: usize,
    elem: usize,
    count: usize,
    buffers: &'b [Vec<u8>],
    name: &str,
) -> Result<&'b [u8], String> {
    let b = view.buffer().index();
    let buffer = buffers.get(b).ok_or_else(|| format!("{name}: buffer {b} is missing"))?;
    let view_bytes = view.offset().checked_add(view.length()).and_then(|end| buffer.get(view.offset()..end));
    let view_bytes = view_bytes.ok_or_else(|| {
        format!(
            "{name}: buffer view {} (bytes {}..{}) runs past the end of buffer {b} ({} bytes)",
            view.index(),
            view.offset(),
            view.offset().saturating_add(view.length()),
            buffer.len()
        )
    })?;
    if count == 0 {
        return Ok(&[]);
    }
    let end =
        stride.checked_mul(count - 1).and_then(|n| n.checked_add(elem)).and_then(|n| n.checked_add(offset));
    end.and_then(|end| view_bytes.get(offset..end)).ok_or_else(|| {
        format!(
            "{name}: {count} elements from byte {offset} need {} bytes but buffer view {} has {}",
            end.map_or_else(|| "more than 2^64".to_owned(), |e| e.to_string()),
            view.index(),
            view_bytes.len()
        )
    })
}
