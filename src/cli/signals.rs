//! Interrupts (SIGINT, SIGTERM) during a run: remove what the run was staging, then exit with
//! the conventional status 128 + signal, so an interrupted render leaves no temporary folder and
//! the previous output set untouched.

use signal_hook::consts::{SIGINT, SIGTERM};
use signal_hook::iterator::Signals;
use std::path::PathBuf;

/// Watches for SIGINT/SIGTERM on a background thread; on one, removes `staging` and exits.
pub fn remove_on_interrupt(staging: Vec<PathBuf>) {
    let Ok(mut signals) = Signals::new([SIGINT, SIGTERM]) else {
        return;
    };
    std::thread::spawn(move || {
        if let Some(signal) = signals.forever().next() {
            for path in &staging {
                let _ = std::fs::remove_dir_all(path);
            }
            std::process::exit(128 + signal);
        }
    });
}
