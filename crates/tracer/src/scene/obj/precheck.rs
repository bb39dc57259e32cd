//! Line-level checks of OBJ and MTL text that tobj does not make (docs/design.md §3.1, §8: every
//! malformed input is an error naming the file and line, never a panic).
//!
//! - MTL values: tobj 4.0.5 reads `Ka`/`Kd`/`Ks`/`Ke` with `parse_float3`, which **panics** (an
//!   `unwrap` on a 3-element conversion, tobj/src/lib.rs:783) when the statement has fewer than
//!   three numbers, and accepts `nan`/`inf`. [`prescan_mtl`] runs first: it expands MTL's
//!   one-number form `Kd r` (meaning `r r r`) and refuses any other count, non-numbers and
//!   non-finite values with the line number, so tobj only ever sees three finite numbers.
//! - OBJ face indices that make tobj's index arithmetic overflow (0, relative indices before the
//!   first element): [`check_faces`] refuses them with the line number.
//! - OBJ statements tobj ignores silently (free-form geometry, typos, garbage):
//!   [`unknown_statements`] lists them for a warning naming file and line. They are not errors:
//!   the OBJ specification says unknown statements are ignored, and every importer does so.

/// MTL statements holding a colour: one number (grey) or three (r g b). tobj parses the first
/// four; `Tf` is read by the loader itself.
const COLOURS: &[&str] = &["Ka", "Kd", "Ks", "Ke", "Tf"];
/// MTL statements holding one number.
const SCALARS: &[&str] = &["Ns", "Ni", "d", "Tr"];

/// Checks an MTL library's numeric values and rewrites `K? r` as `K? r r r`. Returns the text
/// tobj can parse, or `line N: what is wrong`.
pub(super) fn prescan_mtl(text: &[u8]) -> Result<Vec<u8>, String> {
    let mut out = Vec::with_capacity(text.len() + 16);
    for (k, raw) in text.split(|&b| b == b'\n').enumerate() {
        let line = k + 1;
        if k > 0 {
            out.push(b'\n');
        }
        // Not UTF-8: left for tobj, whose refusal is then located by bisection.
        let Ok(s) = std::str::from_utf8(raw) else {
            out.extend_from_slice(raw);
            continue;
        };
        let mut words = s.split_whitespace();
        let Some(keyword) = words.next() else {
            out.extend_from_slice(raw);
            continue;
        };
        let values: Vec<&str> = words.collect();
        let shown = values.join(" ");
        let numbers: Option<Vec<f32>> = values.iter().map(|w| w.parse::<f32>().ok()).collect();
        if COLOURS.contains(&keyword) {
            if matches!(values.first(), Some(&("spectral" | "xyz"))) {
                return Err(format!(
                    "line {line}: {keyword} '{shown}': spectral and CIE XYZ colours are not supported; give r g b"
                ));
            }
            let Some(v) = numbers.filter(|v| v.len() == 1 || v.len() == 3) else {
                return Err(format!("line {line}: {keyword} '{shown}' is not one or three numbers"));
            };
            if v.iter().any(|x| !x.is_finite()) {
                return Err(format!("line {line}: {keyword} '{shown}' is not finite"));
            }
            if let [grey] = v[..] {
                // MTL's one-number form: the same value for r, g and b.
                out.extend_from_slice(format!("{keyword} {grey} {grey} {grey}").as_bytes());
                continue;
            }
        } else if SCALARS.contains(&keyword) {
            let Some(v) = numbers.filter(|v| v.len() == 1) else {
                return Err(format!("line {line}: {keyword} '{shown}' is not one number"));
            };
            if !v[0].is_finite() {
                return Err(format!("line {line}: {keyword} '{shown}' is not finite"));
            }
        }
        out.extend_from_slice(raw);
    }
    Ok(out)
}

/// Checks the face (`f`, `l`) indices tobj would turn into overflowing arithmetic: 0 (OBJ counts
/// from 1; tobj computes `0 - 1` as usize::MAX) and relative (negative) indices reaching before
/// the first vertex, position, texture coordinate or normal. tobj then multiplies such an index
/// (`vt * 2 + 1`), which panics where overflow checks are on (debug and fuzzing builds).
/// Absolute indices past the end are left to tobj, which refuses them without overflow.
/// Returns `line N: what is wrong`.
pub(super) fn check_faces(text: &[u8]) -> Result<(), String> {
    let text = String::from_utf8_lossy(text);
    // Vertices, texture coordinates and normals defined so far.
    let mut counts = [0usize; 3];
    const KINDS: [&str; 3] = ["vertex", "texture coordinate", "normal"];
    for (k, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => counts[0] += 1,
            Some("vt") => counts[1] += 1,
            Some("vn") => counts[2] += 1,
            Some("f" | "l") => {
                for word in words {
                    for (kind, part) in word.split('/').enumerate().take(3) {
                        // Not a number: tobj refuses the line itself.
                        let Ok(index) = part.parse::<isize>() else { continue };
                        let line = k + 1;
                        if index == 0 {
                            return Err(format!(
                                "line {line}: {} index 0 in '{word}' is invalid (OBJ counts from 1)",
                                KINDS[kind]
                            ));
                        }
                        if index < 0 && index.unsigned_abs() > counts[kind] {
                            return Err(format!(
                                "line {line}: relative {} index {index} in '{word}' reaches before the first \
                                 (only {} defined so far)",
                                KINDS[kind], counts[kind]
                            ));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(())
}

/// OBJ statements that are read (tobj or the loader) or harmless to skip without a word
/// (`s`: smoothing groups, which every exporter writes; normals are taken from the file).
const KNOWN_OBJ: &[&str] = &["v", "vt", "vn", "f", "l", "o", "g", "s", "mtllib", "usemtl"];
/// OBJ statements the specification defines that this renderer does not draw.
const UNSUPPORTED_OBJ: &[&str] = &[
    "vp",
    "p",
    "cstype",
    "deg",
    "bmat",
    "step",
    "curv",
    "curv2",
    "surf",
    "parm",
    "trim",
    "hole",
    "scrv",
    "sp",
    "end",
    "con",
    "mg",
    "bevel",
    "c_interp",
    "d_interp",
    "lod",
    "usemap",
    "maplib",
    "shadow_obj",
    "trace_obj",
    "ctech",
    "stech",
    "call",
    "csh",
];
/// At most this many distinct ignored statements are reported (the rest are counted).
const MAX_REPORTED: usize = 5;

/// One warning per distinct statement tobj ignores (its first line and how many lines hold it),
/// in file order, plus a count of any further ones.
pub(super) fn unknown_statements(text: &[u8]) -> Vec<String> {
    let text = String::from_utf8_lossy(text);
    // (keyword, first line, lines), in order of first appearance.
    let mut found: Vec<(&str, usize, usize)> = Vec::new();
    for (k, line) in text.lines().enumerate() {
        let Some(keyword) = line.split_whitespace().next() else { continue };
        if keyword.starts_with('#') || KNOWN_OBJ.contains(&keyword) {
            continue;
        }
        match found.iter_mut().find(|f| f.0 == keyword) {
            Some(f) => f.2 += 1,
            None => found.push((keyword, k + 1, 1)),
        }
    }
    let mut warnings: Vec<String> = found
        .iter()
        .take(MAX_REPORTED)
        .map(|&(keyword, line, count)| {
            let what = if UNSUPPORTED_OBJ.contains(&keyword) {
                format!("statement '{keyword}' (free-form geometry, points) is not supported")
            } else {
                format!("unknown statement '{keyword}'")
            };
            let more = if count > 1 { format!(" ({count} lines)") } else { String::new() };
            format!("line {line}: {what}; ignored{more}")
        })
        .collect();
    if found.len() > MAX_REPORTED {
        warnings.push(format!("{} more kinds of unknown statement ignored", found.len() - MAX_REPORTED));
    }
    warnings
}

/// The 1-based line where `fails` first holds for the prefix of `bytes` ending there: the
/// shortest failing prefix, found by bisection (tobj's errors carry no line number). Only run
/// after a parse has failed.
pub(super) fn failing_line(bytes: &[u8], fails: impl Fn(&[u8]) -> bool) -> Option<usize> {
    let ends: Vec<usize> = bytes
        .iter()
        .enumerate()
        .filter(|(_, b)| **b == b'\n')
        .map(|(i, _)| i + 1)
        .chain([bytes.len()])
        .collect();
    let prefix_fails = |lines: usize| fails(bytes.get(..ends[lines - 1]).unwrap_or(bytes));
    let (mut lo, mut hi) = (1, ends.len());
    if !prefix_fails(hi) {
        return None;
    }
    while lo < hi {
        let mid = (lo + hi) / 2;
        if prefix_fails(mid) { hi = mid } else { lo = mid + 1 }
    }
    Some(lo)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_mtl_prescan_expands_grey_and_refuses_bad_values() {
        let ok = prescan_mtl(b"newmtl a\nKd 0.5\nKs 0.1 0.2 0.3\nNs 10\n").unwrap();
        assert_eq!(String::from_utf8(ok).unwrap(), "newmtl a\nKd 0.5 0.5 0.5\nKs 0.1 0.2 0.3\nNs 10\n");
        // The expanded text is what tobj reads: one number means grey.
        let (mats, _) = tobj::load_mtl_buf(&mut &prescan_mtl(b"newmtl a\nKe 2\n").unwrap()[..]).unwrap();
        assert_eq!(mats[0].emissive, Some([2.0; 3]));
        for (text, want) in [
            ("newmtl a\nKd 1 2\n", "line 2: Kd '1 2' is not one or three numbers"),
            ("newmtl a\n\nKa\n", "line 3: Ka '' is not one or three numbers"),
            ("newmtl a\nKd 0.8 nan 0.1\n", "line 2: Kd '0.8 nan 0.1' is not finite"),
            ("newmtl a\nKs 1 x 1\n", "line 2: Ks '1 x 1' is not one or three numbers"),
            ("Kd spectral f.spd\n", "line 1: Kd 'spectral f.spd': spectral"),
            ("newmtl a\nNs not-a-number\n", "line 2: Ns 'not-a-number' is not one number"),
            ("newmtl a\nd inf\n", "line 2: d 'inf' is not finite"),
        ] {
            let e = prescan_mtl(text.as_bytes()).unwrap_err();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn scene_obj_face_check_refuses_index_zero_and_relative_indices_before_the_first() {
        let head = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\n";
        assert_eq!(check_faces(format!("{head}f 1 2 3\nf -3 -2 -1\nf 1/1 2/-1 3/1\n").as_bytes()), Ok(()));
        // An absolute index past the end is tobj's to refuse (no overflow there).
        assert_eq!(check_faces(format!("{head}f 1 2 9\n").as_bytes()), Ok(()));
        for (face, want) in [
            ("f 1/0 2/1 3/1", "line 5: texture coordinate index 0 in '1/0' is invalid"),
            ("f 0 1 2", "line 5: vertex index 0 in '0' is invalid"),
            ("f -4 1 2", "line 5: relative vertex index -4 in '-4' reaches before the first (only 3"),
            (
                "f 1//-1 2//1 3//1",
                "line 5: relative normal index -1 in '1//-1' reaches before the first (only 0",
            ),
        ] {
            let e = check_faces(format!("{head}{face}\n").as_bytes()).unwrap_err();
            assert!(e.starts_with(want), "{face}: {e}");
        }
    }

    #[test]
    fn scene_obj_unknown_statements_are_listed_by_first_line() {
        let text = b"# c\n#c\nv 0 0 0\ns off\nbogus 1\ncurv 0 1\nbogus 2\n\nf 1 1 1\n";
        assert_eq!(
            unknown_statements(text),
            [
                "line 5: unknown statement 'bogus'; ignored (2 lines)",
                "line 6: statement 'curv' (free-form geometry, points) is not supported; ignored"
            ]
        );
        let many: String = (0..8).map(|k| format!("x{k}\n")).collect();
        let w = unknown_statements(many.as_bytes());
        assert_eq!(w.len(), MAX_REPORTED + 1);
        assert_eq!(w[MAX_REPORTED], "3 more kinds of unknown statement ignored");
    }
}
