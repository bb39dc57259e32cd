//! Ray files (binary .mcr and text): `RayFile::parse` and `RayFile::read`.
//! The checks are in `fuzz/harness/src/lib.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mcctrace_fuzz::harness::ray_file(data));
