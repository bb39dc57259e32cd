//! What tests and benchmarks share, and nothing the shipped binary uses (behind the
//! `test-support` feature; the crate's own unit tests have it through `cfg(test)`): image
//! statistics ([`compare`]) and the generator of random test inputs ([`Rng`]).

pub mod compare;
mod rng;

pub use rng::Rng;
