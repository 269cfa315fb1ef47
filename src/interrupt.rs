//! Interrupts and output writes. The library never handles signals; it only counts
//! its writes of output sets and refuses to start new ones once the binary's SIGINT/SIGTERM
//! handler has set [`INTERRUPTED`]. The handler then waits for the writes under way to finish,
//! removes the temporaries and exits. Every staged write records where its temporaries are
//! ([`note_temporaries_in`], [`note_staging_folder`]), so one handler, installed once for every
//! command, finds them all whichever command wrote them.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Folders this process stages `.<name>.<pid>.tmp` files in, and its staging folders: what an
/// interrupt handler removes ([`staged_so_far`]).
static STAGED: Mutex<(Vec<PathBuf>, Vec<PathBuf>)> = Mutex::new((Vec::new(), Vec::new()));

/// Records that this process stages temporary files in `dir`.
pub fn note_temporaries_in(dir: &Path) {
    if let Ok(mut staged) = STAGED.lock() {
        if !staged.0.iter().any(|d| d == dir) {
            staged.0.push(dir.to_owned());
        }
    }
}

/// Records a staging folder of this process (removed whole on an interrupt).
pub fn note_staging_folder(folder: &Path) {
    if let Ok(mut staged) = STAGED.lock() {
        if !staged.1.iter().any(|d| d == folder) {
            staged.1.push(folder.to_owned());
        }
    }
}

/// (folders holding this process's temporaries, its staging folders) recorded so far.
pub fn staged_so_far() -> (Vec<PathBuf>, Vec<PathBuf>) {
    STAGED.lock().map(|s| s.clone()).unwrap_or_default()
}

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
