//! The malformed-input corpus (`tests/bad_inputs/`): generators of the binary inputs.
//! Generators of the binary inputs: tiny hand-written encoders, so every byte is deliberate and
//! the output never changes with a dependency's version.

use super::{H, W};

/// The triangle scene's buffer: 3 positions (VEC3 f32), 3 texture coordinates (VEC2 f32),
/// 3 u16 indices and 2 bytes of padding: 68 bytes (the same data as the committed
/// `gltf/ok-triangle.gltf`'s data URI).
pub(crate) fn triangle_buffer() -> Vec<u8> {
    let mut b = Vec::new();
    for v in [0f32, 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 1.] {
        b.extend_from_slice(&v.to_le_bytes());
    }
    for i in [0u16, 1, 2] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    b.extend_from_slice(&[0, 0]);
    b
}

/// The triangle scene for GLB: `ok-triangle.gltf` with its buffer in the BIN chunk.
pub(crate) const GLB_JSON: &str = r#"{"asset":{"version":"2.0","generator":"mcctrace bad_inputs corpus"},"scene":0,"scenes":[{"nodes":[0,1]}],"nodes":[{"name":"triangle","mesh":0},{"name":"front","camera":0,"translation":[0.3,0.3,2.0]}],"cameras":[{"type":"perspective","perspective":{"yfov":0.8,"znear":0.01}}],"meshes":[{"name":"triangle","primitives":[{"attributes":{"POSITION":0,"TEXCOORD_0":1},"indices":2,"material":0}]}],"materials":[{"name":"glow","pbrMetallicRoughness":{"baseColorFactor":[0.8,0.8,0.8,1.0],"metallicFactor":0.0},"emissiveFactor":[1.0,1.0,1.0]}],"accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3","min":[0,0,0],"max":[1,1,0]},{"bufferView":1,"componentType":5126,"count":3,"type":"VEC2"},{"bufferView":2,"componentType":5123,"count":3,"type":"SCALAR"}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":36},{"buffer":0,"byteOffset":36,"byteLength":24},{"buffer":0,"byteOffset":60,"byteLength":6}],"buffers":[{"byteLength":68}]}"#;

/// A GLB container: header, the JSON chunk (space-padded) and an optional BIN chunk.
pub(crate) fn glb(json: &[u8], bin: Option<&[u8]>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&0u32.to_le_bytes()); // total length, set below
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if let Some(bin) = bin {
        let mut bin = bin.to_vec();
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    let len = out.len() as u32;
    out[8..12].copy_from_slice(&len.to_le_bytes());
    out
}

/// The binary ray file magic (`mcc::ray_file` documents the layout).
pub(crate) const MCR_MAGIC: &[u8; 8] = b"\x89MCR\r\n\x1a\n";

/// A binary ray file: magic, version, width, height, frame, camera, flags, then the records.
pub(crate) fn mcr(
    width: u32,
    height: u32,
    frame: u32,
    camera: u32,
    flags: u32,
    version: u32,
    rays: &[[f32; 6]],
) -> Vec<u8> {
    let mut out = MCR_MAGIC.to_vec();
    for v in [version, width, height, frame, camera, flags] {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for r in rays {
        for v in r {
            out.extend_from_slice(&v.to_le_bytes());
        }
    }
    out
}

/// The rays of a (good) text ray file, in row-major order.
pub(crate) fn parse_text_rays(text: &[u8]) -> Vec<[f32; 6]> {
    let text = std::str::from_utf8(text).unwrap();
    let mut lines = text.lines();
    let header: Vec<usize> = lines.next().unwrap().split_whitespace().map(|v| v.parse().unwrap()).collect();
    let (w, h) = (header[0], header[1]);
    let mut rays = vec![[0f32; 6]; w * h];
    for line in lines.filter(|l| !l.trim().is_empty()) {
        let f: Vec<&str> = line.split_whitespace().collect();
        let (i, j): (usize, usize) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        for (slot, v) in rays[j * w + i].iter_mut().zip(&f[2..]) {
            *slot = v.parse().unwrap();
        }
    }
    rays
}

/// `rgb` with camera `id` in its 2 low bits per channel (docs/design/mcc.md §4.4, b = 2).
pub(crate) fn tag(rgb: [u8; 3], id: u32) -> [u8; 3] {
    let part = |k: u32| ((id >> (2 * k)) & 3) as u8;
    [(rgb[0] & !3) | part(0), (rgb[1] & !3) | part(1), (rgb[2] & !3) | part(2)]
}

/// The collage's pixel at (x, y): columns 0–3 camera 1, 4–5 background, 6 and beyond camera 2.
pub(crate) fn collage_pixel(x: u32, y: u32) -> [u8; 3] {
    match x {
        0..=3 => tag([200, 120 + 8 * y as u8, 60], 1),
        4 | 5 => [0, 0, 0],
        _ => tag([40, 160, 220 - 8 * y as u8], 2),
    }
}

/// The good collage, `width × height` (8 × 6 matches the ray files).
pub(crate) fn collage_png(width: u32, height: u32) -> Vec<u8> {
    let mut rgb = Vec::new();
    for y in 0..height {
        for x in 0..width {
            rgb.extend_from_slice(&collage_pixel(x, y));
        }
    }
    png(width, height, 2, 8, &rgb)
}

/// A `width × height` picture whose low bits are noise, as an untagged render's are: no pixel
/// black (none is background), the ids they decode to spread over the whole tag code.
pub(crate) fn untagged_png(width: u32, height: u32) -> Vec<u8> {
    let mut state = 2_654_435_769u32;
    let rgb: Vec<u8> = (0..width * height * 3)
        .map(|_| {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 24) as u8 | 0x40
        })
        .collect();
    png(width, height, 2, 8, &rgb)
}

/// [`untagged_png`] saved as a JPEG (by the `image` crate's encoder, quality 90).
pub(crate) fn untagged_jpeg(width: u32, height: u32) -> Vec<u8> {
    let picture = mcc::image::load_from_memory(&untagged_png(width, height)).expect("decode the PNG");
    let mut out = std::io::Cursor::new(Vec::new());
    picture.to_rgb8().write_to(&mut out, mcc::image::ImageFormat::Jpeg).expect("encode a JPEG");
    out.into_inner()
}

/// The good collage with column 4 blended half-way between camera 1 and the background, as an
/// antialiased selection edge leaves it: 6 pixels whose low bits name no camera with a ray file.
pub(crate) fn antialiased_png() -> Vec<u8> {
    let mut rgb = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let p = if x == 4 {
                let c = collage_pixel(3, y);
                // Half of camera 1's colour; force the low bits to a pattern that is no camera.
                let blended = [c[0] / 2, c[1] / 2, c[2] / 2];
                let id = [blended[0] & 3, blended[1] & 3, blended[2] & 3];
                if matches!(id, [1, 0, 0] | [2, 0, 0]) {
                    [blended[0] & !3, blended[1] & !3, blended[2] | 1]
                } else {
                    blended
                }
            } else {
                collage_pixel(x, y)
            };
            rgb.extend_from_slice(&p);
        }
    }
    png(W, H, 2, 8, &rgb)
}

/// The good collage with the top two rows of camera 2's columns tagged as camera 5, which has no
/// ray file: 4 pixels.
pub(crate) fn unknown_id_png() -> Vec<u8> {
    let mut rgb = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let p = if x >= 6 && y < 2 { tag(collage_pixel(x, y), 5) } else { collage_pixel(x, y) };
            rgb.extend_from_slice(&p);
        }
    }
    png(W, H, 2, 8, &rgb)
}

/// The good collage as 16-bit RGB: every value widened exactly (v · 257), or with pixel (2, 3)'s
/// red one code off when `inexact`.
pub(crate) fn collage_png16(inexact: bool) -> Vec<u8> {
    let mut bytes = Vec::new();
    for y in 0..H {
        for x in 0..W {
            for (c, v) in collage_pixel(x, y).into_iter().enumerate() {
                let mut wide = v as u16 * 257;
                if inexact && (x, y, c) == (2, 3, 0) {
                    wide += 1;
                }
                bytes.extend_from_slice(&wide.to_be_bytes());
            }
        }
    }
    png(W, H, 2, 16, &bytes)
}

/// A PNG of `width × height` with colour type `color_type` (0 grey, 2 RGB, 6 RGBA) and
/// `depth` bits per sample; `samples` are the rows' bytes without filter bytes. Deflate
/// "stored" blocks: no compression, byte-stable.
pub(crate) fn png(width: u32, height: u32, color_type: u8, depth: u8, samples: &[u8]) -> Vec<u8> {
    let channels = match color_type {
        0 => 1,
        2 => 3,
        4 => 2,
        6 => 4,
        _ => panic!("colour type {color_type}"),
    };
    let row = (width as usize * channels * depth as usize).div_ceil(8);
    assert_eq!(samples.len(), row * height as usize, "PNG sample count");
    let mut raw = Vec::new();
    for r in samples.chunks(row) {
        raw.push(0); // filter: none
        raw.extend_from_slice(r);
    }
    let mut z = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65535).collect();
    for (k, block) in blocks.iter().enumerate() {
        z.push(u8::from(k + 1 == blocks.len()));
        z.extend_from_slice(&(block.len() as u16).to_le_bytes());
        z.extend_from_slice(&(!(block.len() as u16)).to_le_bytes());
        z.extend_from_slice(block);
    }
    z.extend_from_slice(&adler32(&raw).to_be_bytes());
    let mut out = png_start(width, height, depth, color_type);
    png_chunk(&mut out, b"IDAT", &z);
    png_chunk(&mut out, b"IEND", &[]);
    out
}

/// A PNG that is only a (valid) header claiming `width × height` 8-bit pixels, then IEND: what
/// a corrupt or hostile file looks like to a reader that trusts its header.
pub(crate) fn png_header_only(width: u32, height: u32, color_type: u8) -> Vec<u8> {
    let mut out = png_start(width, height, 8, color_type);
    png_chunk(&mut out, b"IEND", &[]);
    out
}

pub(crate) fn png_start(width: u32, height: u32, depth: u8, color_type: u8) -> Vec<u8> {
    let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[depth, color_type, 0, 0, 0]);
    png_chunk(&mut out, b"IHDR", &ihdr);
    out
}

pub(crate) fn png_chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

pub(crate) fn crc32(bytes: &[u8]) -> u32 {
    let mut c = !0u32;
    for &b in bytes {
        c ^= u32::from(b);
        for _ in 0..8 {
            c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
        }
    }
    !c
}

pub(crate) fn adler32(bytes: &[u8]) -> u32 {
    let (mut a, mut b) = (1u32, 0u32);
    for &x in bytes {
        a = (a + u32::from(x)) % 65521;
        b = (b + a) % 65521;
    }
    (b << 16) | a
}

/// A single-part scan-line OpenEXR file, uncompressed, channels B, G, R as f32, claiming
/// `width × height` pixels. With `pixels` (row-major RGB) the offset table and scan lines
/// follow; without, the file ends after the header (a 10^6 × 10^6 claim in ~330 bytes).
pub(crate) fn exr(width: u32, height: u32, pixels: Option<&[[f32; 3]]>) -> Vec<u8> {
    fn attribute(out: &mut Vec<u8>, name: &str, kind: &str, value: &[u8]) {
        out.extend_from_slice(name.as_bytes());
        out.push(0);
        out.extend_from_slice(kind.as_bytes());
        out.push(0);
        out.extend_from_slice(&(value.len() as i32).to_le_bytes());
        out.extend_from_slice(value);
    }
    let mut out = vec![0x76, 0x2f, 0x31, 0x01];
    out.extend_from_slice(&2u32.to_le_bytes()); // version 2, single-part scan lines
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&2i32.to_le_bytes()); // FLOAT
        channels.extend_from_slice(&[0, 0, 0, 0]); // pLinear, reserved
        channels.extend_from_slice(&1i32.to_le_bytes()); // x sampling
        channels.extend_from_slice(&1i32.to_le_bytes()); // y sampling
    }
    channels.push(0);
    attribute(&mut out, "channels", "chlist", &channels);
    attribute(&mut out, "compression", "compression", &[0]); // NO_COMPRESSION
    let window: Vec<u8> =
        [0i32, 0, width as i32 - 1, height as i32 - 1].iter().flat_map(|v| v.to_le_bytes()).collect();
    attribute(&mut out, "dataWindow", "box2i", &window);
    attribute(&mut out, "displayWindow", "box2i", &window);
    attribute(&mut out, "lineOrder", "lineOrder", &[0]); // INCREASING_Y
    attribute(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute(&mut out, "screenWindowCenter", "v2f", &[0u8; 8]);
    attribute(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0); // end of header
    let Some(pixels) = pixels else { return out };
    assert_eq!(pixels.len(), (width * height) as usize, "EXR pixel count");
    // Offset table (one scan line per block without compression), then the blocks: y, size,
    // then the line's samples channel by channel (B, G, R).
    let line_bytes = width as usize * 3 * 4;
    let table_end = out.len() + 8 * height as usize;
    for y in 0..height as usize {
        out.extend_from_slice(&((table_end + y * (8 + line_bytes)) as u64).to_le_bytes());
    }
    for y in 0..height as usize {
        out.extend_from_slice(&(y as i32).to_le_bytes());
        out.extend_from_slice(&(line_bytes as i32).to_le_bytes());
        let row = &pixels[y * width as usize..(y + 1) * width as usize];
        for c in [2, 1, 0] {
            for p in row {
                out.extend_from_slice(&p[c].to_le_bytes());
            }
        }
    }
    out
}
