//! glTF scenes (.gltf JSON with data-URI buffers, and .glb): `Scene::load`, then `Scene::at_time` for animated ones.
//! The checks are in `fuzz/harness/src/lib.rs`.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| mcctrace_fuzz::harness::gltf(data));
