//! Fuzzing-style property tests on stable Rust (issue "Trust", item 4): the same readers and the
//! same checks as the cargo-fuzz targets in `fuzz/` (both call the harness crate `fuzz/harness/`),
//! fed with proptest's random bytes and with random mutations of the committed seed corpus
//! `fuzz/corpus/<target>/`. The property: no panic, no failed consistency check; every bad input
//! is an `Err`.
//!
//! Bounded: a fixed number of cases per reader (`CASES`, a few seconds each in release) from a
//! fixed RNG seed, so the suite is deterministic. `MCCTRACE_FUZZ_CASES=n` runs n cases per reader
//! instead and `MCCTRACE_FUZZ_SEED=n` draws from another seed (`random` for a fresh one each run):
//! a longer local hunt without cargo-fuzz. A failure prints the shrunk input; reproduce it with
//! the matching cargo-fuzz target (fuzz/README.md) or by calling the harness function on it.

use fuzz_harness as harness;

use proptest::prelude::*;
use proptest::sample::Index;
use proptest::test_runner::{Config, RngSeed, TestCaseError, TestRunner};
use std::path::Path;

/// Cases per reader in the normal test suite.
const CASES: u32 = 400;

/// One edit of a seed.
#[derive(Clone, Debug)]
enum Mutation {
    /// Flip one bit.
    Flip(Index, u8),
    /// Overwrite one byte.
    Set(Index, u8),
    /// Insert bytes.
    Insert(Index, Vec<u8>),
    /// Insert one of the `INTERESTING` strings.
    Interesting(Index, Index),
    /// Delete up to n bytes.
    Delete(Index, usize),
    /// Copy a range of the input to another place (repeats structure: records, JSON objects).
    Duplicate(Index, usize, Index),
    /// Overwrite four bytes with a little-endian u32 near a boundary (binary headers, GLB
    /// lengths, accessor counts).
    Word(Index, u32),
    /// Cut the input short.
    Truncate(Index),
}

/// Tokens that reach the readers' edge cases in text formats.
const INTERESTING: &[&str] = &[
    "0",
    "-0",
    "1",
    "-1",
    "65536",
    "65537",
    "4294967295",
    "4294967296",
    "18446744073709551616",
    "1e39",
    "-1e39",
    "1e-46",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "0.99999",
    "1.0001",
    "\n",
    "\r\n",
    " ",
    "\0",
    "\u{feff}",
    "\u{ff}",
    "/",
    "\\",
    "//",
    "#",
    "-",
    "null",
    "[]",
    "{}",
    "\"\"",
    ",",
    ":",
    "\"uri\":\"data:,\"",
    "\"count\":4294967295",
    "\"byteOffset\":4294967295",
    "\"children\":[0]",
    "\"mode\":5",
    "\"mode\":6",
    "f 1 2 3",
    "f -1 -2 -3",
    "f 0 0 0",
    "v 0 0 0",
    "vt 0 0",
    "vn 0 0 0",
    "usemtl x",
    "newmtl x",
    "map_Kd t.png",
    "-o",
    "-s",
    "-clamp",
    "-bm",
    "illum 7",
];

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<Index>(), 0u8..8).prop_map(|(i, b)| Mutation::Flip(i, b)),
        (any::<Index>(), any::<u8>()).prop_map(|(i, b)| Mutation::Set(i, b)),
        (any::<Index>(), prop::collection::vec(any::<u8>(), 1..16)).prop_map(|(i, v)| Mutation::Insert(i, v)),
        (any::<Index>(), any::<Index>()).prop_map(|(i, k)| Mutation::Interesting(i, k)),
        (any::<Index>(), 1usize..64).prop_map(|(i, n)| Mutation::Delete(i, n)),
        (any::<Index>(), 1usize..256, any::<Index>()).prop_map(|(i, n, j)| Mutation::Duplicate(i, n, j)),
        (
            any::<Index>(),
            prop_oneof![
                Just(0u32),
                Just(1),
                Just(u32::MAX),
                Just(u32::MAX - 31),
                Just(1 << 16),
                Just(1 << 27),
                Just(0x8000_0000),
                any::<u32>()
            ]
        )
            .prop_map(|(i, w)| Mutation::Word(i, w)),
        any::<Index>().prop_map(Mutation::Truncate),
    ]
}

fn apply(seed: &[u8], mutations: &[Mutation]) -> Vec<u8> {
    let mut d = seed.to_vec();
    for m in mutations {
        let at = |i: &Index, len: usize| i.index(len + 1);
        match m {
            Mutation::Flip(i, b) if !d.is_empty() => {
                let k = i.index(d.len());
                d[k] ^= 1 << b;
            }
            Mutation::Set(i, v) if !d.is_empty() => {
                let k = i.index(d.len());
                d[k] = *v;
            }
            Mutation::Insert(i, v) => {
                let k = at(i, d.len());
                d.splice(k..k, v.iter().copied());
            }
            Mutation::Interesting(i, t) => {
                let k = at(i, d.len());
                let s = INTERESTING[t.index(INTERESTING.len())].as_bytes();
                d.splice(k..k, s.iter().copied());
            }
            Mutation::Delete(i, n) if !d.is_empty() => {
                let k = i.index(d.len());
                let end = (k + n).min(d.len());
                d.drain(k..end);
            }
            Mutation::Duplicate(i, n, j) if !d.is_empty() => {
                let k = i.index(d.len());
                let piece = d[k..(k + n).min(d.len())].to_vec();
                let to = at(j, d.len());
                d.splice(to..to, piece);
            }
            Mutation::Word(i, w) if d.len() >= 4 => {
                let k = i.index(d.len() - 3);
                d[k..k + 4].copy_from_slice(&w.to_le_bytes());
            }
            Mutation::Truncate(i) => {
                let k = at(i, d.len());
                d.truncate(k);
            }
            _ => {}
        }
    }
    d
}

/// The committed seeds of a target, sorted by name (so a case is reproducible).
fn seeds(target: &str) -> Vec<Vec<u8>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz").join("corpus").join(target);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("seed corpus {}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .collect();
    files.sort();
    let seeds: Vec<Vec<u8>> = files.iter().map(|p| std::fs::read(p).unwrap()).collect();
    assert!(!seeds.is_empty(), "no seeds in {}", dir.display());
    seeds
}

fn config() -> Config {
    let cases = std::env::var("MCCTRACE_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(CASES);
    let rng_seed = match std::env::var("MCCTRACE_FUZZ_SEED").as_deref() {
        Ok("random") => RngSeed::Random,
        Ok(v) => RngSeed::Fixed(v.parse().expect("MCCTRACE_FUZZ_SEED is a number or `random`")),
        Err(_) => RngSeed::Fixed(0x6d63_6374_7261_6365), // "mcctrace"
    };
    Config {
        cases,
        rng_seed,
        // No proptest-regressions/ files in the repository: a failure prints its input.
        failure_persistence: None,
        max_shrink_iters: 2048,
        ..Config::default()
    }
}

/// Runs `check` on every seed as it is, then on `config().cases` inputs: a third random bytes, two
/// thirds mutated seeds (1 to 8 edits).
fn run(target: &str, check: fn(&[u8])) {
    let seeds = seeds(target);
    for s in &seeds {
        check(s);
    }
    let input = prop_oneof![
        1 => prop::collection::vec(any::<u8>(), 0..1024),
        2 => (any::<Index>(), prop::collection::vec(mutation(), 1..8))
            .prop_map(move |(i, m)| apply(&seeds[i.index(seeds.len())], &m)),
    ];
    let mut runner = TestRunner::new(config());
    let result = runner.run(&input, |data| {
        // A panic inside the reader is caught by proptest and shrunk like a failed check.
        check(&data);
        Ok::<(), TestCaseError>(())
    });
    harness::remove_scratch();
    if let Err(e) = result {
        panic!("{target}: {e}");
    }
}

#[test]
fn fuzz_ray_file_never_panics() {
    run("ray_file", harness::ray_file);
}

#[test]
fn fuzz_collage_and_regions_never_panic() {
    run("collage", harness::collage);
}

#[test]
fn fuzz_layers_never_panic() {
    run("layers", harness::layers);
}

#[test]
fn fuzz_gltf_never_panics() {
    run("gltf", harness::gltf);
}

#[test]
fn fuzz_obj_never_panics() {
    run("obj", harness::obj);
}

#[test]
fn fuzz_obj_parts_split_at_separators() {
    let data =
        [&b"a"[..], harness::SEPARATOR, b"b", harness::SEPARATOR, b"c", harness::SEPARATOR, b"d"].concat();
    let parts = harness::split_parts(&data, 3);
    assert_eq!(parts[0], b"a");
    assert_eq!(parts[1], b"b");
    assert_eq!(parts[2], [&b"c"[..], harness::SEPARATOR, b"d"].concat());
    assert_eq!(harness::split_parts(b"only", 3), vec![&b"only"[..], b"", b""]);
}
