//! Interrupts (SIGINT, SIGTERM) during a run: remove what the run was staging, then exit with
//! the conventional status 128 + signal, so an interrupted render or fit leaves no temporary
//! file or folder and the previous outputs untouched.

use irpol::interrupt::{INTERRUPTED, WRITES_IN_PROGRESS};
use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::path::PathBuf;
use std::sync::atomic::Ordering;
use std::sync::{Mutex, Once};

/// What an interrupt removes: staging folders, and the folders whose staged files
/// (`.<name>.<pid>.tmp`) of this process go. Steps of one command (the demo fits, renders and runs
/// a thermal day) each add theirs; one handler removes them all.
static TO_REMOVE: Mutex<(Vec<PathBuf>, Vec<PathBuf>)> = Mutex::new((Vec::new(), Vec::new()));

/// Adds the folders `staging` and, in each folder of `temporaries_in`, this process's staged files
/// (see `irpol::atomic`) to what an interrupt removes, and starts watching for SIGINT/SIGTERM on a
/// background thread the first time: on a signal, everything added so far is removed, then the
/// process exits.
pub fn remove_on_interrupt(staging: Vec<PathBuf>, temporaries_in: Vec<PathBuf>) {
    if let Ok(mut lists) = TO_REMOVE.lock() {
        lists.0.extend(staging);
        lists.1.extend(temporaries_in);
    }
    static WATCHING: Once = Once::new();
    WATCHING.call_once(|| {
        let Ok(mut signals) = Signals::new([SIGINT, SIGTERM]) else {
            return;
        };
        std::thread::spawn(move || {
            if let Some(signal) = signals.forever().next() {
                clean_up_after_interrupt();
                std::process::exit(128 + signal);
            }
        });
    });
}

/// Starts watching for SIGINT/SIGTERM for any command: every write goes through the library's
/// staged writes, which record where their temporaries are, so one handler removes them all.
pub fn watch_interrupts() {
    remove_on_interrupt(Vec::new(), Vec::new());
}

/// Waits for good once an interrupt is being handled: the handler's thread clears up and exits
/// the process; returning from `main` first would cut its clean-up short (a run's own write,
/// refused after the signal, ends the run with an error at once).
pub fn wait_for_interrupt_handler() {
    while INTERRUPTED.load(Ordering::SeqCst) {
        std::thread::park_timeout(std::time::Duration::from_millis(100));
    }
}

fn clean_up_after_interrupt() {
    // No write starts from now on; one under way (a staged file, a commit) finishes, so the
    // outputs are the complete old or new set and no temporary appears after the clean-up below.
    INTERRUPTED.store(true, Ordering::SeqCst);
    while WRITES_IN_PROGRESS.load(Ordering::SeqCst) > 0 {
        std::thread::sleep(std::time::Duration::from_millis(1));
    }
    let Ok(lists) = TO_REMOVE.lock() else {
        return;
    };
    let (mut staging, mut temporaries_in) = lists.clone();
    // What the library recorded staging, whichever command did it.
    let (library_temporaries, library_staging) = irpol::interrupt::staged_so_far();
    staging.extend(library_staging);
    temporaries_in.extend(library_temporaries);
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
}
