//! An output folder replaced as a whole (a render's outputs change together or not at
//! all). Files are written into a hidden staging folder beside the target,
//! `.<name>.irpol-staging-<pid>`, and the finished folder is swapped with the target in one
//! `renameat2(RENAME_EXCHANGE)` (Linux; a plain rename where there is no target yet), so a reader
//! or a killed run sees the complete old set or the complete new one, never a mix. Entries of the
//! target that belong to no set (a user's notes: neither written now nor listed by the caller as
//! an earlier output) are carried over first, files by hard link and folders rebuilt of hard links,
//! so that they are in the target before the swap and after it.
//! The staging folder is removed when the set is dropped uncommitted (an error), by the binary's
//! SIGINT/SIGTERM handler ([`staging_folder`] names it), and, after a SIGKILL, by the next run
//! into the same target.

use super::{parent_of, stale_entries};
use crate::interrupt::WriteGuard;
use std::fs;
use std::io;
use std::path::{Path, PathBuf};

/// The staging folder of process `pid` for `target`.
pub fn staging_folder(target: &Path, pid: u32) -> PathBuf {
    parent_of(target).join(format!("{}{pid}", staging_prefix(target)))
}

/// `.<name>.irpol-staging-`: what every staging folder of `target` is named before its pid.
fn staging_prefix(target: &Path) -> String {
    let name = target
        .file_name()
        .map_or("out".into(), |n| n.to_string_lossy().into_owned());
    format!(".{name}.irpol-staging-")
}

/// A folder being written; [`StagedFolder::commit`] swaps it into place.
pub struct StagedFolder {
    target: PathBuf,
    staging: PathBuf,
    committed: bool,
}

impl StagedFolder {
    /// Starts a fresh staging folder for `target` (removing those left by killed runs).
    pub fn begin(target: &Path) -> io::Result<StagedFolder> {
        let _guard = WriteGuard::start()?;
        fs::create_dir_all(parent_of(target))?;
        remove_stale_staging(target);
        let staging = staging_folder(target, std::process::id());
        crate::interrupt::note_staging_folder(&staging);
        if staging.exists() {
            fs::remove_dir_all(&staging)?;
        }
        fs::create_dir(&staging)?;
        Ok(StagedFolder {
            target: target.to_owned(),
            staging,
            committed: false,
        })
    }

    /// Writes one file of the set.
    pub fn write(&self, name: &str, bytes: &[u8]) -> io::Result<()> {
        self.root().write(name, bytes)
    }

    /// The set's top folder, to write files into.
    pub fn root(&self) -> StagedDir<'_> {
        StagedDir {
            dir: self.staging.clone(),
            _set: std::marker::PhantomData,
        }
    }

    /// A new folder `name` inside the set (a frame of a series), to write files into: it is
    /// swapped into place with the rest of the set.
    pub fn subfolder(&self, name: &str) -> io::Result<StagedDir<'_>> {
        let _guard = WriteGuard::start()?;
        let dir = self.staging.join(name);
        fs::create_dir(&dir)?;
        Ok(StagedDir {
            dir,
            _set: std::marker::PhantomData,
        })
    }

    /// Puts the set in place of the target in one step and removes the old set. `earlier_output`
    /// tells which names in the target an earlier run wrote (they go with the old set).
    pub fn commit(mut self, earlier_output: &dyn Fn(&str) -> bool) -> io::Result<()> {
        let _guard = WriteGuard::start()?;
        if !self.target.exists() {
            fs::rename(&self.staging, &self.target)?;
            self.committed = true;
            return Ok(());
        }
        if !self.target.is_dir() {
            return Err(io::Error::other(format!(
                "{} exists and is not a folder",
                crate::text::path(&self.target)
            )));
        }
        self.carry_over_foreign_files(earlier_output)?;
        rustix::fs::renameat_with(
            rustix::fs::CWD,
            &self.staging,
            rustix::fs::CWD,
            &self.target,
            rustix::fs::RenameFlags::EXCHANGE,
        )?;
        self.committed = true;
        // The staging path now holds the old set.
        fs::remove_dir_all(&self.staging)
    }

    /// Hard-links into the staging folder every entry of the target that is neither written now
    /// nor an earlier output; a folder is rebuilt there with its files hard-linked, so that the
    /// user's entries stay in the target until the swap and exist in both sets after it (a kill at
    /// any instant loses none of them).
    fn carry_over_foreign_files(&self, earlier_output: &dyn Fn(&str) -> bool) -> io::Result<()> {
        for entry in fs::read_dir(&self.target)? {
            let entry = entry?;
            let staged = self.staging.join(entry.file_name());
            if staged.exists() || earlier_output(&entry.file_name().to_string_lossy()) {
                continue;
            }
            link_entry(&entry.path(), &staged)?;
        }
        Ok(())
    }
}

/// `to` as a copy of `from` that shares its files' data: folders recreated, files hard-linked,
/// symbolic links recreated pointing where they pointed.
fn link_entry(from: &Path, to: &Path) -> io::Result<()> {
    let kind = fs::symlink_metadata(from)?.file_type();
    if kind.is_symlink() {
        std::os::unix::fs::symlink(fs::read_link(from)?, to)
    } else if kind.is_dir() {
        fs::create_dir(to)?;
        for entry in fs::read_dir(from)? {
            let entry = entry?;
            link_entry(&entry.path(), &to.join(entry.file_name()))?;
        }
        Ok(())
    } else {
        fs::hard_link(from, to)
    }
}

/// A folder of a [`StagedFolder`] being written (its top or a subfolder); it lives no longer than
/// the set, whose drop removes it.
pub struct StagedDir<'a> {
    dir: PathBuf,
    _set: std::marker::PhantomData<&'a StagedFolder>,
}

impl StagedDir<'_> {
    /// Writes one file into this folder.
    pub fn write(&self, name: &str, bytes: &[u8]) -> io::Result<()> {
        let _guard = WriteGuard::start()?;
        fs::write(self.dir.join(name), bytes)
    }
}

impl Drop for StagedFolder {
    fn drop(&mut self) {
        if !self.committed {
            let _ = fs::remove_dir_all(&self.staging);
        }
    }
}

/// Removes staging folders of `target` whose process no longer runs (a SIGKILL mid-write), and
/// one of this process's left by an earlier set.
fn remove_stale_staging(target: &Path) {
    for stale in stale_entries(parent_of(target), &staging_prefix(target), "", true) {
        let _ = fs::remove_dir_all(stale);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_committed_set_replaces_the_old_one_and_keeps_foreign_files() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out");
        let first = StagedFolder::begin(&target).unwrap();
        first.write("a.txt", b"1").unwrap();
        first.write("b.txt", b"1").unwrap();
        first.commit(&|_| false).unwrap();
        fs::write(target.join("notes.md"), b"mine").unwrap();
        fs::create_dir_all(target.join("analysis/plots")).unwrap();
        fs::write(target.join("analysis/plots/p.txt"), b"plot").unwrap();
        let second = StagedFolder::begin(&target).unwrap();
        second.write("a.txt", b"2").unwrap();
        second.commit(&|name| name.ends_with(".txt")).unwrap();
        assert_eq!(fs::read(target.join("a.txt")).unwrap(), b"2");
        assert!(
            !target.join("b.txt").exists(),
            "the old set is gone as a whole"
        );
        assert_eq!(fs::read(target.join("notes.md")).unwrap(), b"mine");
        assert_eq!(
            fs::read(target.join("analysis/plots/p.txt")).unwrap(),
            b"plot",
            "a user's folder is carried over whole"
        );
        let leftovers: Vec<_> = fs::read_dir(dir.path()).unwrap().flatten().collect();
        assert_eq!(leftovers.len(), 1, "no staging folder left");
    }

    #[test]
    fn an_uncommitted_set_changes_nothing_and_stale_staging_is_cleared() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("a.txt"), b"old").unwrap();
        // A folder left by a killed process (pid 4294967295 is never alive).
        let stale = staging_folder(&target, u32::MAX);
        fs::create_dir(&stale).unwrap();
        {
            let set = StagedFolder::begin(&target).unwrap();
            set.write("a.txt", b"new").unwrap();
            assert!(!stale.exists());
        }
        assert_eq!(fs::read(target.join("a.txt")).unwrap(), b"old");
        assert_eq!(fs::read_dir(dir.path()).unwrap().count(), 1);
    }
}
