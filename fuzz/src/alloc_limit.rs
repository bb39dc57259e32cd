//! A ceiling on single allocations in the fuzz targets (fuzz/README.md, "CI"). libFuzzer's own
//! `-malloc_limit_mb` works only through a sanitizer's malloc hooks, and CI builds without
//! AddressSanitizer; without this, an input that makes a reader reserve memory in proportion to
//! a size it claims (memory that is never touched, so `-rss_limit_mb` does not see it either)
//! would pass unnoticed. Compiled only into the cargo-fuzz build (`cfg(fuzzing)`).

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;

/// The largest single allocation, in bytes, a fuzz input may cause: 2 GiB, libFuzzer's default
/// malloc limit for CI's `-rss_limit_mb=2048`. Every reader refuses a claimed size past
/// `MAX_PIXELS` or the file's length long before this.
pub const MAX_ALLOCATION: usize = 2048 << 20;

/// The system allocator, aborting (a crash to libFuzzer, which saves the input) on any single
/// request over [`MAX_ALLOCATION`].
pub struct LimitedAllocator;

/// Aborts when `size` is over the limit. Formatting an integer to the unbuffered stderr does not
/// allocate, so this cannot recurse.
fn check(size: usize) {
    if size > MAX_ALLOCATION {
        let _ = writeln!(
            std::io::stderr(),
            "==mcctrace-fuzz== ERROR: allocation of {size} bytes, over the {MAX_ALLOCATION}-byte \
             limit of fuzz/src/alloc_limit.rs: a reader reserves memory the input does not justify"
        );
        std::process::abort();
    }
}

// SAFETY: every method forwards its arguments unchanged to `System` after the size check, so
// `System` upholds the `GlobalAlloc` contract; the check itself never allocates or unwinds.
unsafe impl GlobalAlloc for LimitedAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        check(layout.size());
        // SAFETY: forwarded unchanged (see the impl).
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        check(layout.size());
        // SAFETY: forwarded unchanged (see the impl).
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        check(new_size);
        // SAFETY: forwarded unchanged (see the impl).
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: forwarded unchanged (see the impl).
        unsafe { System.dealloc(ptr, layout) }
    }
}
