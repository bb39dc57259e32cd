//! The bytes of a glTF asset: the GLB container and the buffers the JSON points to (external
//! files, data URIs, the GLB binary chunk). Written here rather than taken from the gltf crate
//! because its GLB reader and `import_buffers` can panic on malformed headers and URIs, and
//! their errors do not say which file or buffer is at fault.

use std::path::Path;

const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

/// Splits a GLB file into its JSON chunk and optional BIN chunk; the message says what is wrong.
pub(super) fn split_glb(bytes: &[u8]) -> Result<(&[u8], Option<&[u8]>), String> {
    let version = u32_at(bytes, 4).ok_or("the 12-byte GLB header is truncated")?;
    let length = u32_at(bytes, 8).ok_or("the 12-byte GLB header is truncated")? as usize;
    if version != 2 {
        return Err(format!("GLB container version {version} is not supported (only 2)"));
    }
    let bytes = bytes.get(..length).ok_or_else(|| {
        format!("the GLB header declares {length} bytes but the file has only {}", bytes.len())
    })?;
    let (mut json, mut bin) = (None, None);
    let mut at = 12;
    while at < bytes.len() {
        let (Some(len), Some(kind)) = (u32_at(bytes, at), u32_at(bytes, at + 4)) else {
            return Err(format!("the chunk header at byte {at} is truncated"));
        };
        let start = at + 8;
        let data =
            start.checked_add(len as usize).and_then(|end| bytes.get(start..end)).ok_or_else(|| {
                format!("the chunk at byte {at} declares {len} bytes but only {} remain", bytes.len() - start)
            })?;
        match kind {
            CHUNK_JSON if json.is_none() && at == 12 => json = Some(data),
            _ if at == 12 => return Err("the first GLB chunk is not the JSON chunk".to_owned()),
            CHUNK_BIN if bin.is_none() => bin = Some(data),
            CHUNK_JSON | CHUNK_BIN => {
                return Err(format!("a second {} chunk at byte {at}", chunk_name(kind)));
            }
            // The GLB spec tells readers to skip chunk types they do not know.
            _ => {}
        }
        at = start + data.len();
    }
    Ok((json.ok_or("the GLB has no JSON chunk")?, bin))
}

fn chunk_name(kind: u32) -> &'static str {
    if kind == CHUNK_JSON { "JSON" } else { "BIN" }
}

fn u32_at(bytes: &[u8], at: usize) -> Option<u32> {
    let b: [u8; 4] = bytes.get(at..at.checked_add(4)?)?.try_into().ok()?;
    Some(u32::from_le_bytes(b))
}

/// Loads every buffer of a glTF file, each cut to its declared `byteLength`. External files are
/// resolved against `base` (the .gltf's folder); `bin` is the GLB binary chunk, if any. A buffer
/// that `skip` marks (a meshopt fallback) is not read and stays empty.
pub(super) fn load(
    declared_buffers: &[gltf::json::buffer::Buffer],
    base: &Path,
    bin: Option<&[u8]>,
    skip: &[bool],
) -> Result<Vec<Vec<u8>>, String> {
    let mut bin = bin;
    let mut buffers = Vec::with_capacity(declared_buffers.len());
    for (i, buffer) in declared_buffers.iter().enumerate() {
        if skip.get(i).copied().unwrap_or(false) {
            buffers.push(Vec::new());
            continue;
        }
        let (mut data, origin) = match &buffer.uri {
            None => {
                // Only one buffer may use the BIN chunk; `take` makes a second claim an error.
                let data = bin
                    .take()
                    .ok_or_else(|| format!("buffer {i} refers to the GLB binary chunk, but there is none"))?;
                (data.to_vec(), "the GLB binary chunk".to_owned())
            }
            Some(uri) => read_uri(uri, base).map_err(|m| format!("buffer {i}: {m}"))?,
        };
        let declared = usize::try_from(buffer.byte_length.0).unwrap_or(usize::MAX);
        if data.len() < declared {
            return Err(format!(
                "buffer {i} ({origin}) has {} bytes but the glTF declares {declared}",
                data.len()
            ));
        }
        data.truncate(declared);
        buffers.push(data);
    }
    Ok(buffers)
}

/// Reads a buffer or image URI: a `data:` URI or a (%-encoded) path relative to `base`. Returns the bytes and a
/// description of where they came from, for messages.
pub(super) fn read_uri(uri: &str, base: &Path) -> Result<(Vec<u8>, String), String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let (header, payload) = rest.split_once(',').ok_or("the data URI has no ',' before its payload")?;
        let data =
            if header.ends_with(";base64") { decode_base64(payload)? } else { percent_decode(payload)? };
        return Ok((data, "a data URI".to_owned()));
    }
    // A ':' before any '/' is a URI scheme (http:, file: …): glTF allows only relative paths.
    if uri.split('/').next().is_some_and(|first| first.contains(':')) {
        return Err(format!("URI '{uri}' is neither a relative path nor a data: URI"));
    }
    let decoded = String::from_utf8(percent_decode(uri)?)
        .map_err(|_| format!("URI '{uri}' does not decode to UTF-8"))?;
    let file = base.join(decoded);
    let data = std::fs::read(&file).map_err(|e| format!("cannot read {}: {e}", file.display()))?;
    Ok((data, file.display().to_string()))
}

/// Decodes RFC 4648 base64 (standard or URL-safe alphabet, padding optional).
pub(super) fn decode_base64(text: &str) -> Result<Vec<u8>, String> {
    let text = text.trim_end_matches('=');
    let mut out = Vec::with_capacity(text.len() / 4 * 3 + 3);
    let (mut acc, mut bits) = (0u32, 0u32);
    for (i, c) in text.bytes().enumerate() {
        let v = match c {
            b'A'..=b'Z' => c - b'A',
            b'a'..=b'z' => c - b'a' + 26,
            b'0'..=b'9' => c - b'0' + 52,
            b'+' | b'-' => 62,
            b'/' | b'_' => 63,
            _ => return Err(format!("invalid base64 character {:?} at position {i}", c as char)),
        };
        acc = (acc << 6) | u32::from(v);
        bits += 6;
        if bits >= 8 {
            bits -= 8;
            out.push((acc >> bits) as u8);
            acc &= (1 << bits) - 1;
        }
    }
    Ok(out)
}

/// Decodes `%XX` escapes.
fn percent_decode(text: &str) -> Result<Vec<u8>, String> {
    let bytes = text.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while let Some(&b) = bytes.get(i) {
        if b == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| format!("bad %-escape at position {i} of '{text}'"))?;
            out.push(hex);
            i += 3;
        } else {
            out.push(b);
            i += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_base64_and_percent_decoding() {
        assert_eq!(decode_base64("TWFu").unwrap(), b"Man");
        assert_eq!(decode_base64("TWE=").unwrap(), b"Ma");
        assert_eq!(decode_base64("TQ==").unwrap(), b"M");
        assert!(decode_base64("T*E=").unwrap_err().contains("position 1"));
        assert_eq!(percent_decode("a%20b.bin").unwrap(), b"a b.bin");
        assert!(percent_decode("a%2").is_err());
        assert!(percent_decode("a%zz").is_err());
    }

    #[test]
    fn scene_malformed_glb_headers_are_errors() {
        assert!(split_glb(b"glTF").unwrap_err().contains("truncated"));
        let mut glb = b"glTF".to_vec();
        glb.extend(2u32.to_le_bytes());
        glb.extend(4u32.to_le_bytes()); // shorter than the header itself
        assert!(split_glb(&glb).unwrap_err().contains("no JSON chunk"));
        glb.truncate(8);
        glb.extend(100u32.to_le_bytes());
        assert!(split_glb(&glb).unwrap_err().contains("declares 100 bytes"));
        glb.truncate(8);
        glb.extend(24u32.to_le_bytes());
        glb.extend(99u32.to_le_bytes());
        glb.extend(CHUNK_JSON.to_le_bytes());
        glb.extend(b"{}  ");
        assert!(split_glb(&glb).unwrap_err().contains("declares 99 bytes"));
    }
}
