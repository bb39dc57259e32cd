//! The render threads' scheduling priority (docs/studio.md, "Engine"): the studio renders while
//! the user paints in a browser on the same machine, and Chromium sets its page's renderer
//! process to an absolute nice value (0 in front), whatever the nice of whoever started it. So
//! the studio's render threads lower themselves to an absolute nice too, below the page's,
//! and the page's handlers are never held up by the rendering.

/// The nice value the studio's render threads run at, at least: "background" on Linux.
pub const RENDER_NICE: i32 = 10;

/// Lowers the calling thread's scheduling priority to nice `nice` if it runs higher; never
/// raises it. On Linux the nice value is per thread; elsewhere this does nothing.
pub fn lower_current_thread(nice: i32) {
    #[cfg(target_os = "linux")]
    // SAFETY: getpriority and setpriority take plain integers and touch only the calling
    // thread's scheduling attributes (`who` = 0 is the calling thread on Linux); errno is this
    // thread's own.
    unsafe {
        *libc::__errno_location() = 0;
        let now = libc::getpriority(libc::PRIO_PROCESS, 0);
        if *libc::__errno_location() == 0 && now < nice {
            // A failure leaves the thread where it was, which is only slower for the page.
            libc::setpriority(libc::PRIO_PROCESS, 0, nice);
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = nice;
}

/// The calling thread's nice value (Linux), for tests.
#[cfg(all(test, target_os = "linux"))]
pub(crate) fn current_nice() -> i32 {
    // SAFETY: as above.
    unsafe { libc::getpriority(libc::PRIO_PROCESS, 0) }
}

#[cfg(all(test, target_os = "linux"))]
mod tests {
    use super::*;

    #[test]
    fn lowers_this_thread_only_and_never_raises() {
        let before = current_nice();
        let (lowered, raised) = std::thread::spawn(|| {
            lower_current_thread(RENDER_NICE);
            let lowered = current_nice();
            lower_current_thread(lowered - 5);
            (lowered, current_nice())
        })
        .join()
        .unwrap();
        assert_eq!(lowered, before.max(RENDER_NICE), "the thread runs at the render nice");
        assert_eq!(raised, lowered, "asking for a higher priority leaves it where it was");
        assert_eq!(current_nice(), before, "other threads keep theirs");
    }
}
