//! Shared harness of the fuzz targets; see `harness.rs` (also compiled into the root package's
//! `tests/fuzz_properties.rs`).
pub mod harness;
