//! Interrupts (SIGINT, SIGTERM) during a run: remove what the run was staging, then exit with
//! the conventional status 128 + signal, so an interrupted render or fit leaves no temporary
//! file or folder and the previous outputs untouched.

use irpol::interrupt::{INTERRUPTED, WRITES_IN_PROGRESS};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::path::PathBuf;
use std::sync::atomic::Ordering;

/// Watches for SIGINT/SIGTERM on a background thread; on one, removes the folders `staging` and,
/// in each folder of `temporaries_in`, this process's staged files (`.<name>.<pid>.tmp`, see
/// `irpol::atomic`), then exits.
pub fn remove_on_interrupt(staging: Vec<PathBuf>, temporaries_in: Vec<PathBuf>) {
    let Ok(mut signals) = Signals::new([SIGINT, SIGTERM]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            // No write starts from now on; one under way (a staged file, a commit) finishes, so
            // the outputs are the complete old or new set and no temporary appears after the
            // clean-up below.
            INTERRUPTED.store(true, Ordering::SeqCst);
            while WRITES_IN_PROGRESS.load(Ordering::SeqCst) > 0 {
                std::thread::sleep(std::time::Duration::from_millis(1));
            }
            for path in &staging {
                let _ = std::fs::remove_dir_all(path);
            }
            let suffix = format!(".{}.tmp", std::process::id());
            for dir in &temporaries_in {
                let Ok(entries) = std::fs::read_dir(dir) else {
                    continue;
                };
                for entry in entries.flatten() {
                    let name = entry.file_name().to_string_lossy().into_owned();
                    if name.starts_with('.') && name.ends_with(&suffix) {
                        let _ = std::fs::remove_file(entry.path());
                    }
                }
            }
            std::process::exit(128 + signal);
        }
    });
}
