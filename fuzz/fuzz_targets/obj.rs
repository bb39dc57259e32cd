//! OBJ scenes with their MTL library and a texture: `Scene::load` (input: OBJ, separator line, MTL, separator line, image).
//! The checks are in `fuzz/harness/src/lib.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mcctrace_fuzz::harness::obj(data));
