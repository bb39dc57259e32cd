//! Ray files (docs/design/mcc.md §4.2): one eye ray (origin, unit direction) per pixel of a view or of
//! a rerender.
//!
//! Two encodings, told apart by the content (never by the file name):
//!
//! **Binary** (`.mcr`, the default). All integers and floats little-endian.
//!
//! | offset | size | field |
//! |-------:|-----:|-------|
//! | 0  | 8 | magic `89 4D 43 52 0D 0A 1A 0A` (`\x89MCR\r\n\x1a\n`, PNG-style: the high first byte and the line endings catch text-mode mangling and can never start a text ray file) |
//! | 8  | 4 | version, u32 = 1 |
//! | 12 | 4 | width, u32 ≥ 1 |
//! | 16 | 4 | height, u32 ≥ 1 |
//! | 20 | 4 | frame, u32 |
//! | 24 | 4 | camera id, u32 (0 for a rerender file, which belongs to no camera) |
//! | 28 | 4 | flags, u32: bit 0 = rays made by the remapper or the in-betweener, not a lens writer; every other bit must be 0 (a reader refuses flags it does not know) |
//! | 32 | 24·w·h | records in row-major order (pixel (i, j) at index j·w + i): ox oy oz dx dy dz as f32 |
//!
//! The file is exactly 32 + 24·w·h bytes. A record is a `#[repr(C)]` [`StoredRay`], so the reader
//! reads the whole payload in one `read_exact` straight into the ray vector (no per-record calls).
//!
//! **Text** (`.txt`, the column's): line 1 `width height`, then one line `i j ox oy oz dx dy dz`
//! per pixel, in any order (the column's parallel writer wrote them in any order). Floats are
//! written with Rust's shortest round-trip form, so text round-trips bit for bit. Blank lines are
//! ignored; text carries no frame or camera id (they read as 0; the file name has them).
//!
//! The reader checks everything before trusting a byte: magic, version, flags, sizes (each side
//! ≤ [`MAX_SIDE`], at most [`MAX_PIXELS`] pixels — refused *before* allocating), the exact file
//! length, that every pixel appears exactly once (text), that every float is finite and every
//! direction is unit: |‖d‖ − 1| ≤ [`UNIT_TOLERANCE`] (the tracer's `Ray::is_valid` bound). Errors
//! name the file and the first offending record: its line number for text, its index and pixel for
//! binary.

use crate::error::{MccError, Result};
use bytemuck::{Pod, Zeroable};
use glam::Vec3;
use rayon::prelude::*;
use std::fs::File;
use std::io::{Read, Write};
use std::path::Path;

/// The binary encoding's magic bytes.
pub const MAGIC: [u8; 8] = *b"\x89MCR\r\n\x1a\n";
/// The binary encoding's version this build reads and writes.
pub const VERSION: u32 = 1;
/// Bytes before the first binary record.
pub const HEADER_LEN: usize = 32;
/// Bytes per binary record.
pub const RECORD_LEN: usize = 24;
/// Flag bit: the rays come from the remapper or the in-betweener rather than a lens writer.
pub const FLAG_COMPUTED: u32 = 1;
/// Largest width or height accepted.
pub const MAX_SIDE: u32 = 1 << 16;
/// Largest pixel count accepted (2^27 ≈ 134 M pixels, 3.2 GB of rays: beyond any sane view).
pub const MAX_PIXELS: u64 = 1 << 27;
/// Largest accepted |‖d‖ − 1| of a stored direction.
pub const UNIT_TOLERANCE: f64 = 1e-4;
/// The fewest bytes a text record can take (`0 0 0 0 0 0 0 1` and its newline, less one for the
/// last line): used to refuse absurd headers of short files before allocating.
const MIN_TEXT_RECORD: u64 = 15;

/// One stored eye ray. `#[repr(C)]` with six f32 and no padding: the binary record layout.
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
#[repr(C)]
pub struct StoredRay {
    /// World-space origin.
    pub origin: Vec3,
    /// World-space unit direction.
    pub direction: Vec3,
}

impl StoredRay {
    /// A ray from `origin` along `direction`.
    #[inline]
    pub const fn new(origin: Vec3, direction: Vec3) -> Self {
        Self { origin, direction }
    }

    /// True when the ray can be stored: finite, with a unit direction (see [`UNIT_TOLERANCE`]).
    #[inline]
    #[allow(clippy::manual_range_contains)] // `contains` short-circuits: a branch per ray
    pub fn is_valid(&self) -> bool {
        // |‖d‖ − 1| ≤ tol ⇔ (1 − tol)² ≤ ‖d‖² ≤ (1 + tol)²: no square root, and a NaN or infinite
        // direction fails the range test by itself. `&` rather than `&&`: no branches, so the
        // check of a whole file vectorises.
        const LOW: f64 = (1.0 - UNIT_TOLERANCE) * (1.0 - UNIT_TOLERANCE);
        const HIGH: f64 = (1.0 + UNIT_TOLERANCE) * (1.0 + UNIT_TOLERANCE);
        let l2 = self.direction.as_dvec3().length_squared();
        let o = self.origin.abs();
        (o.x < f32::INFINITY) & (o.y < f32::INFINITY) & (o.z < f32::INFINITY) & (l2 >= LOW) & (l2 <= HIGH)
    }

    /// Why this ray cannot be stored (non-finite or non-unit direction), or `None` when it can.
    pub fn defect(&self) -> Option<String> {
        if !self.origin.is_finite() {
            return Some(format!("origin {} is not finite", self.origin));
        }
        if !self.direction.is_finite() {
            return Some(format!("direction {} is not finite", self.direction));
        }
        if !self.is_valid() {
            let len = self.direction.as_dvec3().length();
            return Some(format!(
                "direction {} has length {len}, not unit (tolerance {UNIT_TOLERANCE})",
                self.direction
            ));
        }
        None
    }
}

/// Which encoding to write.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum RayFormat {
    /// The binary encoding (`.mcr`): compact and fast.
    #[default]
    Binary,
    /// The column's text encoding (`.txt`): readable.
    Text,
}

impl RayFormat {
    /// The file extension docs/design/mcc.md §4.3 names give this encoding (without the dot).
    pub fn extension(self) -> &'static str {
        match self {
            RayFormat::Binary => "mcr",
            RayFormat::Text => "txt",
        }
    }
}

/// The rays of one view or rerender: `width × height` rays in row-major order.
#[derive(Clone, Debug, PartialEq)]
pub struct RayFile {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Frame number (0 when read from text).
    pub frame: u32,
    /// Camera id (0 for a rerender file, and when read from text).
    pub camera_id: u32,
    /// True when computed (remapper, in-betweener) rather than recorded by a lens writer.
    pub computed: bool,
    /// The rays, pixel (i, j) at index `j · width + i`.
    pub rays: Vec<StoredRay>,
}

impl RayFile {
    /// A SHA-256 of the size and the rays (their f32 bits, little-endian), in hex: the same for
    /// the same rays whichever file format held them (docs/farm.md).
    pub fn digest(&self) -> String {
        use sha2::{Digest, Sha256};
        let mut hash = Sha256::new();
        hash.update(self.width.to_le_bytes());
        hash.update(self.height.to_le_bytes());
        let mut bytes = Vec::with_capacity(24 << 12);
        for chunk in self.rays.chunks(1 << 12) {
            bytes.clear();
            let values =
                chunk.iter().flat_map(|r| r.origin.to_array().into_iter().chain(r.direction.to_array()));
            bytes.extend(values.flat_map(f32::to_le_bytes));
            hash.update(&bytes);
        }
        hash.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }

    /// A ray file from its parts; `rays` must hold exactly `width × height` rays.
    pub fn new(width: u32, height: u32, frame: u32, camera_id: u32, rays: Vec<StoredRay>) -> Result<Self> {
        check_size(width, height).map_err(|m| MccError::input("ray file", m))?;
        if rays.len() as u64 != width as u64 * height as u64 {
            return Err(MccError::input(
                "ray file",
                format!("{} rays for a {width}x{height} image ({} pixels)", rays.len(), width * height),
            ));
        }
        Ok(Self { width, height, frame, camera_id, computed: false, rays })
    }

    /// The ray of pixel (i, j).
    #[inline]
    pub fn get(&self, i: u32, j: u32) -> &StoredRay {
        &self.rays[j as usize * self.width as usize + i as usize]
    }

    /// The rays without a border of `n` pixels on each side (an overscan cut off, docs/design/workflow.md
    /// §8); `None` when the border leaves no pixel.
    pub fn without_border(&self, n: u32) -> Option<Self> {
        if 2 * n as u64 >= self.width.min(self.height) as u64 {
            return None;
        }
        let (w, h) = (self.width - 2 * n, self.height - 2 * n);
        let rays =
            (n..n + h).flat_map(|j| (n..n + w).map(move |i| (i, j))).map(|(i, j)| *self.get(i, j)).collect();
        Some(Self {
            width: w,
            height: h,
            frame: self.frame,
            camera_id: self.camera_id,
            computed: self.computed,
            rays,
        })
    }

    /// Reads a ray file in either encoding (told apart by its first bytes).
    pub fn read(path: &Path) -> Result<Self> {
        let mut file = File::open(path).map_err(|e| MccError::io(path, e))?;
        let len = file.metadata().map_err(|e| MccError::io(path, e))?.len();
        let mut head = [0u8; HEADER_LEN];
        let got = read_up_to(&mut file, &mut head).map_err(|e| MccError::io(path, e))?;
        if got >= MAGIC.len() && head[..MAGIC.len()] == MAGIC {
            if got < HEADER_LEN {
                return Err(truncated_header(len, path));
            }
            let header = BinaryHeader::parse(&head, len, path)?;
            let mut rays: Vec<StoredRay> = bytemuck::zeroed_vec(header.pixels());
            let invalid = read_records(&mut file, &mut rays).map_err(|e| MccError::io(path, e))?;
            header.finish(rays, invalid, path)
        } else {
            let mut bytes = Vec::with_capacity(len.min(1 << 30) as usize);
            bytes.extend_from_slice(&head[..got]);
            file.read_to_end(&mut bytes).map_err(|e| MccError::io(path, e))?;
            parse_text(&bytes, path)
        }
    }

    /// Parses a ray file held in memory; `path` is only used to name it in errors.
    pub fn parse(bytes: &[u8], path: &Path) -> Result<Self> {
        if bytes.len() >= MAGIC.len() && bytes[..MAGIC.len()] == MAGIC {
            if bytes.len() < HEADER_LEN {
                return Err(truncated_header(bytes.len() as u64, path));
            }
            let mut head = [0u8; HEADER_LEN];
            head.copy_from_slice(&bytes[..HEADER_LEN]);
            let header = BinaryHeader::parse(&head, bytes.len() as u64, path)?;
            let mut rays: Vec<StoredRay> = bytemuck::zeroed_vec(header.pixels());
            bytemuck::cast_slice_mut::<StoredRay, u8>(&mut rays).copy_from_slice(&bytes[HEADER_LEN..]);
            let invalid = rays
                .par_chunks_mut(CHUNK)
                .enumerate()
                .filter_map(|(k, chunk)| from_le_and_check(chunk).map(|i| k * CHUNK + i))
                .min();
            header.finish(rays, invalid, path)
        } else {
            parse_text(bytes, path)
        }
    }

    /// The first ray that cannot be stored, as (index, reason).
    pub fn first_defect(&self) -> Option<(usize, String)> {
        // Chunks in parallel, each scanned in order; the first bad chunk has the first bad ray.
        let index = self
            .rays
            .par_chunks(CHUNK)
            .enumerate()
            .filter_map(|(k, c)| first_invalid(c).map(|i| k * CHUNK + i))
            .min()?;
        Some((index, self.rays[index].defect().unwrap_or_default()))
    }

    /// Writes the file atomically in `format` (refusing rays the reader would refuse).
    pub fn write(&self, path: &Path, format: RayFormat) -> Result<()> {
        if let Some((index, message)) = self.first_defect() {
            return Err(MccError::RayRecord { path: path.into(), record: self.describe(index), message });
        }
        tracer::atomic::write_atomically(path, |w| self.encode(w, format))?;
        Ok(())
    }

    /// Encodes the file in `format` into `w` (no validation; see [`RayFile::write`]).
    pub fn encode(&self, w: &mut impl Write, format: RayFormat) -> std::io::Result<()> {
        match format {
            RayFormat::Binary => {
                let mut head = [0u8; HEADER_LEN];
                head[..8].copy_from_slice(&MAGIC);
                let flags = if self.computed { FLAG_COMPUTED } else { 0 };
                for (k, v) in
                    [VERSION, self.width, self.height, self.frame, self.camera_id, flags].iter().enumerate()
                {
                    head[8 + 4 * k..12 + 4 * k].copy_from_slice(&v.to_le_bytes());
                }
                w.write_all(&head)?;
                if cfg!(target_endian = "little") {
                    w.write_all(bytemuck::cast_slice(&self.rays))
                } else {
                    for r in &self.rays {
                        for v in r.origin.to_array().into_iter().chain(r.direction.to_array()) {
                            w.write_all(&v.to_le_bytes())?;
                        }
                    }
                    Ok(())
                }
            }
            RayFormat::Text => {
                writeln!(w, "{} {}", self.width, self.height)?;
                let width = self.width as usize;
                for (k, r) in self.rays.iter().enumerate() {
                    let (o, d) = (r.origin, r.direction);
                    // `{}` prints an f32's shortest round-trip form: text files reread bit for bit.
                    writeln!(
                        w,
                        "{} {} {} {} {} {} {} {}",
                        k % width,
                        k / width,
                        o.x,
                        o.y,
                        o.z,
                        d.x,
                        d.y,
                        d.z
                    )?;
                }
                Ok(())
            }
        }
    }

    /// `record 12 (pixel (0, 1))`: how errors locate a ray by its index.
    fn describe(&self, index: usize) -> String {
        let w = self.width.max(1) as usize;
        format!("record {index} (pixel ({}, {}))", index % w, index / w)
    }
}

fn truncated_header(len: u64, path: &Path) -> MccError {
    MccError::ray_file(
        path,
        format!("truncated binary header: {len} bytes, the header alone is {HEADER_LEN}"),
    )
}

/// Checks a width × height against the size limits, before anything is allocated.
fn check_size(width: u32, height: u32) -> std::result::Result<(), String> {
    if width == 0 || height == 0 {
        return Err(format!("size {width}x{height} is empty"));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width as u64 * height as u64 > MAX_PIXELS {
        return Err(format!(
            "size {width}x{height} is beyond the limits (each side ≤ {MAX_SIDE}, at most {MAX_PIXELS} pixels)"
        ));
    }
    Ok(())
}

/// Fills as much of `buf` as the reader has (short only at end of file).
fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(n) => got += n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Rays per chunk of parallel reading and checking (1.5 MB).
const CHUNK: usize = 1 << 16;

/// Index of the first invalid ray of `rays`.
fn first_invalid(rays: &[StoredRay]) -> Option<usize> {
    rays.iter().position(|r| !r.is_valid())
}

/// Brings little-endian records to host order (a no-op on little-endian hosts) and returns the
/// index of the first invalid one.
fn from_le_and_check(rays: &mut [StoredRay]) -> Option<usize> {
    if cfg!(target_endian = "big") {
        for v in bytemuck::cast_slice_mut::<StoredRay, u32>(rays) {
            *v = u32::from_le(*v);
        }
    }
    first_invalid(rays)
}

/// Reads the records that follow the header straight into `rays` and returns the index of the
/// first invalid one. On Unix, chunks are read at their offsets in parallel and checked while
/// still in cache: filling fresh memory is bound by page faults (a 1080p file is 50 MB, 12 000
/// pages), which then happen on every core at once.
fn read_records(file: &mut File, rays: &mut [StoredRay]) -> std::io::Result<Option<usize>> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileExt;
        let file = &*file;
        let found = rays
            .par_chunks_mut(CHUNK)
            .enumerate()
            .map(|(k, chunk)| {
                let offset = (HEADER_LEN + k * CHUNK * RECORD_LEN) as u64;
                file.read_exact_at(bytemuck::cast_slice_mut(chunk), offset)?;
                Ok(from_le_and_check(chunk).map(|i| k * CHUNK + i))
            })
            .collect::<std::io::Result<Vec<Option<usize>>>>()?;
        Ok(found.into_iter().flatten().min())
    }
    #[cfg(not(unix))]
    {
        file.read_exact(bytemuck::cast_slice_mut(rays))?;
        Ok(rays
            .par_chunks_mut(CHUNK)
            .enumerate()
            .filter_map(|(k, c)| from_le_and_check(c).map(|i| k * CHUNK + i))
            .min())
    }
}

/// A validated binary header.
struct BinaryHeader {
    width: u32,
    height: u32,
    frame: u32,
    camera_id: u32,
    flags: u32,
}

impl BinaryHeader {
    /// Parses and checks the header of a binary file `file_len` bytes long.
    fn parse(head: &[u8; HEADER_LEN], file_len: u64, path: &Path) -> Result<Self> {
        let word = |k: usize| {
            let o = 8 + 4 * k;
            u32::from_le_bytes([head[o], head[o + 1], head[o + 2], head[o + 3]])
        };
        let (version, width, height, frame, camera_id, flags) =
            (word(0), word(1), word(2), word(3), word(4), word(5));
        if version != VERSION {
            return Err(MccError::ray_file(
                path,
                format!(
                    "binary ray file version {version} is not supported (this build reads version {VERSION})"
                ),
            ));
        }
        if flags & !FLAG_COMPUTED != 0 {
            return Err(MccError::ray_file(
                path,
                format!("unknown flags {flags:#x} in the header (known: {FLAG_COMPUTED:#x})"),
            ));
        }
        check_size(width, height).map_err(|m| MccError::ray_file(path, format!("header: {m}")))?;
        let want = HEADER_LEN as u64 + RECORD_LEN as u64 * width as u64 * height as u64;
        if file_len != want {
            let what = if file_len < want { "truncated" } else { "trailing bytes after the last record" };
            return Err(MccError::ray_file(
                path,
                format!("{file_len} bytes, but a {width}x{height} binary ray file is {want} bytes ({what})"),
            ));
        }
        Ok(Self { width, height, frame, camera_id, flags })
    }

    fn pixels(&self) -> usize {
        self.width as usize * self.height as usize
    }

    /// Builds the file from records already in host order, `invalid` the first bad one.
    fn finish(self, rays: Vec<StoredRay>, invalid: Option<usize>, path: &Path) -> Result<RayFile> {
        let file = RayFile {
            width: self.width,
            height: self.height,
            frame: self.frame,
            camera_id: self.camera_id,
            computed: self.flags & FLAG_COMPUTED != 0,
            rays,
        };
        if let Some(index) = invalid {
            let message = file.rays[index].defect().unwrap_or_default();
            return Err(MccError::RayRecord { path: path.into(), record: file.describe(index), message });
        }
        Ok(file)
    }
}

/// Parses the text encoding.
fn parse_text(bytes: &[u8], path: &Path) -> Result<RayFile> {
    if bytes.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(MccError::ray_file(path, "empty file: no ray-file header"));
    }
    let mut lines = bytes.split(|&b| b == b'\n').enumerate().map(|(k, l)| (k + 1, l));
    let (_, first) = lines.next().unwrap_or((1, &[]));
    let header = std::str::from_utf8(first).ok().and_then(|s| {
        let mut t = s.split_ascii_whitespace();
        let w = t.next()?.parse::<u32>().ok()?;
        let h = t.next()?.parse::<u32>().ok()?;
        t.next().is_none().then_some((w, h))
    });
    let Some((width, height)) = header else {
        return Err(MccError::ray_file(
            path,
            "neither a binary ray file (no magic) nor a text one (line 1 must be `width height`)",
        ));
    };
    check_size(width, height).map_err(|m| MccError::ray_file(path, format!("line 1: {m}")))?;
    let n = width as u64 * height as u64;
    if (bytes.len() as u64) < n * MIN_TEXT_RECORD {
        return Err(MccError::ray_file(
            path,
            format!(
                "{} bytes cannot hold the {width}x{height} = {n} records line 1 announces \
                 (at least {MIN_TEXT_RECORD} bytes each): truncated, or a wrong header",
                bytes.len()
            ),
        ));
    }
    let mut rays: Vec<StoredRay> = bytemuck::zeroed_vec(n as usize);
    let mut seen = vec![false; n as usize];
    let record_error = |line: usize, pixel: Option<(u32, u32)>, message: String| {
        let record = match pixel {
            Some((i, j)) => format!("line {line} (pixel ({i}, {j}))"),
            None => format!("line {line}"),
        };
        MccError::RayRecord { path: path.into(), record, message }
    };
    let mut count = 0u64;
    let last_line = bytes.iter().filter(|&&b| b == b'\n').count() + 1;
    for (line, raw) in lines {
        let Ok(text) = std::str::from_utf8(raw) else {
            return Err(record_error(line, None, "not text (invalid UTF-8)".into()));
        };
        let mut tokens = text.split_ascii_whitespace();
        let Some(first) = tokens.next() else { continue };
        let mut fields = [first; 8];
        let mut k = 1;
        for t in tokens {
            if k == 8 {
                return Err(record_error(
                    line,
                    None,
                    "more than 8 fields (want `i j ox oy oz dx dy dz`)".into(),
                ));
            }
            fields[k] = t;
            k += 1;
        }
        if k < 8 {
            // A short last line without its newline is where a copy or a download stopped.
            let cut = if line == last_line && !bytes.ends_with(b"\n") {
                "; the file ends in the middle of this record: truncated"
            } else {
                ""
            };
            return Err(record_error(
                line,
                None,
                format!("{k} fields, want 8 (`i j ox oy oz dx dy dz`){cut}"),
            ));
        }
        let index = |f: &str, what: &str, limit: u32| match f.parse::<u32>() {
            Ok(v) if v < limit => Ok(v),
            Ok(v) => Err(record_error(line, None, format!("{what} {v} is outside the image (0..{limit})"))),
            Err(_) => Err(record_error(line, None, format!("{what} `{f}` is not a pixel index"))),
        };
        let i = index(fields[0], "column", width)?;
        let j = index(fields[1], "row", height)?;
        let mut v = [0f32; 6];
        for (slot, f) in v.iter_mut().zip(&fields[2..]) {
            *slot = f
                .parse::<f32>()
                .map_err(|_| record_error(line, Some((i, j)), format!("`{f}` is not a number")))?;
        }
        let ray = StoredRay::new(Vec3::new(v[0], v[1], v[2]), Vec3::new(v[3], v[4], v[5]));
        if let Some(message) = ray.defect() {
            return Err(record_error(line, Some((i, j)), message));
        }
        let at = j as usize * width as usize + i as usize;
        if std::mem::replace(&mut seen[at], true) {
            return Err(record_error(line, Some((i, j)), "a second record for this pixel".into()));
        }
        rays[at] = ray;
        count += 1;
    }
    if let Some(at) = seen.iter().position(|s| !s) {
        let (i, j) = (at % width as usize, at / width as usize);
        return Err(MccError::RayRecord {
            path: path.into(),
            record: format!("pixel ({i}, {j})"),
            message: format!("no record (the file has {count} of {n}): truncated?"),
        });
    }
    Ok(RayFile { width, height, frame: 0, camera_id: 0, computed: false, rays })
}

#[cfg(test)]
mod tests;
