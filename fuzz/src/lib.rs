//! The fuzz targets' library: the checks of the harness crate (`harness/`, also the root package's
//! `tests/fuzz_properties.rs` uses it) and the cargo-fuzz build's allocation ceiling.
pub use fuzz_harness as harness;

/// The allocation ceiling of the cargo-fuzz build (`alloc_limit.rs` says why).
#[cfg(fuzzing)]
pub mod alloc_limit;

/// Every fuzz target links this library, so this allocator serves all five.
#[cfg(fuzzing)]
#[global_allocator]
static ALLOCATOR: alloc_limit::LimitedAllocator = alloc_limit::LimitedAllocator;
