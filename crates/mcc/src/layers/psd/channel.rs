//! A PSD layer's channel data (Adobe's specification, "Channel image data"): raw, PackBits
//! (RLE, each row's byte count first) or zlib, with or without prediction, always checked to
//! give exactly the layer's `width × height` samples.

use crate::error::{MccError, Result};
use std::io::Read;
use std::path::Path;

/// Decodes one channel of `width × height` samples of `depth` bits, widened to 16 bits.
pub(super) fn decode_channel(
    data: &[u8],
    width: usize,
    height: usize,
    depth: u16,
    path: &Path,
    entry: &str,
) -> Result<Vec<u16>> {
    let err = |message: String| MccError::layered(path, entry, message);
    let bps = depth as usize / 8;
    let row = width * bps;
    let need = row * height;
    let compression = u16::from_be_bytes([data[0], data[1]]);
    let data = &data[2..];
    let raw: Vec<u8> = match compression {
        0 => {
            if data.len() != need {
                return Err(err(format!(
                    "holds {} bytes, but {width}x{height} raw samples are {need}",
                    data.len()
                )));
            }
            data.to_vec()
        }
        1 => {
            if data.len() < 2 * height {
                return Err(err(format!("too short for the {height} row lengths of its PackBits data")));
            }
            let (counts, mut rest) = data.split_at(2 * height);
            let mut out = Vec::with_capacity(need);
            for (y, count) in counts.chunks_exact(2).enumerate() {
                let n = u16::from_be_bytes([count[0], count[1]]) as usize;
                if n > rest.len() {
                    return Err(err(format!(
                        "row {y} claims {n} bytes of PackBits data, but {} remain",
                        rest.len()
                    )));
                }
                let (packed, tail) = rest.split_at(n);
                rest = tail;
                unpack_bits(packed, row, &mut out).map_err(|m| err(format!("row {y}: {m}")))?;
            }
            out
        }
        2 | 3 => {
            let mut out = Vec::with_capacity(need);
            flate2::read::ZlibDecoder::new(data)
                .take(need as u64 + 1)
                .read_to_end(&mut out)
                .map_err(|e| err(format!("bad zlib data: {e}")))?;
            if out.len() != need {
                return Err(err(format!(
                    "zlib data decodes to {} bytes, not the {need} of {width}x{height} samples",
                    out.len().min(need + 1)
                )));
            }
            if compression == 3 {
                undo_prediction(&mut out, row, bps);
            }
            out
        }
        other => return Err(err(format!("compression {other} is unknown (0 to 3 are defined)"))),
    };
    Ok(if bps == 1 {
        raw.iter().map(|&a| a as u16 * 257).collect()
    } else {
        raw.chunks_exact(2).map(|a| u16::from_be_bytes([a[0], a[1]])).collect()
    })
}

/// Appends one PackBits row that must unpack to exactly `row` bytes.
fn unpack_bits(mut packed: &[u8], row: usize, out: &mut Vec<u8>) -> std::result::Result<(), String> {
    let start = out.len();
    while let Some((&header, rest)) = packed.split_first() {
        packed = rest;
        let header = header as i8;
        if header >= 0 {
            let n = header as usize + 1;
            if n > packed.len() {
                return Err(format!("a literal run of {n} bytes is cut short"));
            }
            out.extend_from_slice(&packed[..n]);
            packed = &packed[n..];
        } else if header != -128 {
            let Some((&byte, rest)) = packed.split_first() else {
                return Err("a repeat run is cut short".to_owned());
            };
            packed = rest;
            out.extend(std::iter::repeat_n(byte, (1 - header as isize) as usize));
        }
        if out.len() - start > row {
            return Err(format!("unpacks to more than the row's {row} bytes"));
        }
    }
    if out.len() - start != row {
        return Err(format!("unpacks to {} bytes, not the row's {row}", out.len() - start));
    }
    Ok(())
}

/// Undoes zlib-with-prediction's per-row differences (of bytes, or of 16-bit big-endian samples).
fn undo_prediction(data: &mut [u8], row: usize, bps: usize) {
    for line in data.chunks_exact_mut(row.max(1)) {
        if bps == 1 {
            for i in 1..line.len() {
                line[i] = line[i].wrapping_add(line[i - 1]);
            }
        } else {
            let mut last = 0u16;
            for s in line.chunks_exact_mut(2) {
                last = last.wrapping_add(u16::from_be_bytes([s[0], s[1]]));
                s.copy_from_slice(&last.to_be_bytes());
            }
        }
    }
}
