//! Collage and region images: image bytes → `Collage::load`/`Collage::decode` (several camera sets and tag codes) and `Regions::load`.
//! The checks are in `fuzz/harness/src/lib.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mcctrace_fuzz::harness::collage(data));
