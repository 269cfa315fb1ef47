//! Interrupts and output writes. The library never handles signals; it only counts
//! its writes of output sets and refuses to start new ones once the binary's SIGINT/SIGTERM
//! handler has set [`INTERRUPTED`]. The handler then waits for the writes under way to finish,
//! removes the temporaries and exits.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// Whether process `pid` still runs (Linux /proc): temporaries of one that does not were left by a
/// SIGKILL and may be removed.
pub fn process_is_alive(pid: u32) -> bool {
    std::path::Path::new("/proc").join(pid.to_string()).exists()
}

/// Writes of output sets in progress (staging a file or renaming a set into place), and whether
/// the process was told to stop. An interrupt handler sets [`INTERRUPTED`] and waits for
/// [`WRITES_IN_PROGRESS`] to reach 0 before it removes the temporaries and exits: no new write
/// starts after the flag, and a commit that started finishes, so a SIGTERM can neither cut a
/// commit in half nor leave a temporary written after the clean-up.
pub static WRITES_IN_PROGRESS: AtomicUsize = AtomicUsize::new(0);
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Counts one write in [`WRITES_IN_PROGRESS`] while alive; refuses to start after an interrupt.
pub struct WriteGuard;

impl WriteGuard {
    pub fn start() -> std::io::Result<WriteGuard> {
        WRITES_IN_PROGRESS.fetch_add(1, Ordering::SeqCst);
        let guard = WriteGuard;
        if INTERRUPTED.load(Ordering::SeqCst) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::Interrupted,
                "interrupted",
            ));
        }
        Ok(guard)
    }
}

impl Drop for WriteGuard {
    fn drop(&mut self) {
        WRITES_IN_PROGRESS.fetch_sub(1, Ordering::SeqCst);
    }
}
