//! The studio page's browser test (`tests/studio_page/`) as a test binary of its own (`[[test]]
//! page` in the top-level Cargo.toml): it asserts that no handler of the page runs over 50 ms,
//! a measure of the browser's main thread. Inside `suite` it ran beside ~120 other tests that
//! keep CI's two cores busy with renders, and the bound then measured their load, not the
//! studio's (three fresh-clone runs of unchanged code failed it at load 8). Cargo runs test
//! binaries one after another, so here the page shares the machine only with its own server.
//! Run it: `cargo test --release -p mcctrace-suite --test page -- --nocapture`.

mod common;
mod studio_page;
