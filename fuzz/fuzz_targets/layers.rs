//! Layered collages: bytes → `mcc::layers::open_collage` as an OpenRaster archive and as a PSD,
//! and `load_regions`. The checks are in `fuzz/harness/src/lib.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mcctrace_fuzz::harness::layers(data));
