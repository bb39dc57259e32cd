//! Shared harness of the fuzz targets; see `harness.rs` (also compiled into the root package's
//! `tests/fuzz_properties.rs`).
pub mod harness;

/// The allocation ceiling of the cargo-fuzz build (`alloc_limit.rs` says why).
#[cfg(fuzzing)]
pub mod alloc_limit;

/// Every fuzz target links this library, so this allocator serves all four.
#[cfg(fuzzing)]
#[global_allocator]
static ALLOCATOR: alloc_limit::LimitedAllocator = alloc_limit::LimitedAllocator;
