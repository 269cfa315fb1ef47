//! Atomic writes: every file irpol writes goes through here, so a reader, a failed run or an
//! interrupted one sees the complete old output or the complete new one, never a torn file or a
//! mixed set.
//!
//! - [`write_atomically`]: one file, through a synced temporary sibling `.<name>.<pid>.tmp` and a
//!   rename (atomic on one filesystem); [`write_new_file`] the same with a hard link, which never
//!   replaces an existing file.
//! - [`OutputSet`]: files in any folders (`irpol fit`'s library entries, reports and index),
//!   each staged as such a temporary and all renamed into place only once every one is on disk.
//! - [`StagedFolder`]: a folder of outputs (a render) written into a staging folder
//!   `.<name>.irpol-staging-<pid>` and swapped with the target in one `renameat2(RENAME_EXCHANGE)`.
//!
//! Staging and committing are counted as writes in progress ([`crate::interrupt`]): the binary's
//! SIGINT/SIGTERM handler waits for them, then removes this process's temporaries (the names
//! above, [`staging_folder`]); those of a SIGKILLed run are removed by the next write beside them.

mod file_set;
mod staged_folder;

pub use file_set::OutputSet;
pub use staged_folder::{staging_folder, StagedDir, StagedFolder};

use crate::interrupt::process_is_alive;
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// Writes `bytes` to `path` through a temporary sibling and a rename (atomic on one filesystem):
/// an output set of one file.
pub fn write_atomically(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut set = OutputSet::new();
    set.stage(path, bytes)?;
    set.commit()
}

/// Writes `bytes` to a temporary sibling, then hard-links it to `path`. Unlike the rename of
/// [`write_atomically`], a link never replaces an existing file, so a file that appears between
/// a caller's check and the write is not overwritten either (the error is `AlreadyExists`).
pub fn write_new_file(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let _guard = crate::interrupt::WriteGuard::start()?;
    let dir = parent_of(path);
    crate::interrupt::note_temporaries_in(dir);
    std::fs::create_dir_all(dir)?;
    let temp = temporary_beside(path);
    let written = write_synced(&temp, bytes).and_then(|()| std::fs::hard_link(&temp, path));
    let _ = std::fs::remove_file(&temp);
    written
}

/// The folder `path` is in (`.` for a bare name).
fn parent_of(path: &Path) -> &Path {
    path.parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// `path`'s file name, lossily as text (empty for none).
fn file_name_of(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// `.<name>.<pid>.tmp` beside `target`: this process's temporary for it.
fn temporary_beside(target: &Path) -> PathBuf {
    parent_of(target).join(format!(
        ".{}.{}.tmp",
        file_name_of(target),
        std::process::id()
    ))
}

/// Creates (or truncates) `path` with `bytes`, synced to disk before returning.
fn write_synced(path: &Path, bytes: &[u8]) -> io::Result<()> {
    let mut file = std::fs::File::create(path)?;
    file.write_all(bytes)?;
    file.sync_all()
}

/// Entries of `dir` named `<prefix><pid><suffix>` whose process no longer runs (or, with
/// `including_own`, is this one): what a killed run left behind.
fn stale_entries(dir: &Path, prefix: &str, suffix: &str, including_own: bool) -> Vec<PathBuf> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    entries
        .flatten()
        .filter(|entry| {
            let name = entry.file_name().to_string_lossy().into_owned();
            let pid = name
                .strip_prefix(prefix)
                .and_then(|rest| rest.strip_suffix(suffix))
                .and_then(|pid| pid.parse::<u32>().ok());
            pid.is_some_and(|pid| {
                !process_is_alive(pid) || (including_own && pid == std::process::id())
            })
        })
        .map(|entry| entry.path())
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_is_replaced_whole_and_a_new_file_never_replaces() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub/a.txt");
        write_atomically(&path, b"one").unwrap();
        write_atomically(&path, b"two").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        let error = write_new_file(&path, b"three").unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::AlreadyExists);
        assert_eq!(std::fs::read(&path).unwrap(), b"two");
        write_new_file(&dir.path().join("sub/b.txt"), b"b").unwrap();
        let names = std::fs::read_dir(dir.path().join("sub")).unwrap().count();
        assert_eq!(names, 2, "no temporary left");
    }
}
