//! An output set written as a whole. Every file is first written to a temporary sibling; only when
//! all of them are on disk are they renamed over their targets, in the order staged (a command
//! stages the files that others point to, such as library entries, last). A failure before the
//! renames leaves every target as it was, and the temporaries and any folders made for them are
//! removed.

use super::{file_name_of, parent_of, stale_entries, temporary_beside, write_synced};
use crate::interrupt::WriteGuard;
use std::path::{Path, PathBuf};

/// Files staged for one output set; dropped without [`OutputSet::commit`], it removes them.
#[derive(Default)]
pub struct OutputSet {
    /// (temporary file, target) in staging order.
    staged: Vec<(PathBuf, PathBuf)>,
    /// Folders this set created, outermost first.
    created_dirs: Vec<PathBuf>,
}

impl OutputSet {
    pub fn new() -> OutputSet {
        OutputSet::default()
    }

    /// Writes `bytes` to a temporary file beside `target` (creating its folder), synced to disk.
    /// Refused before anything is written where the target cannot be replaced by a file (it
    /// is a folder) or is already staged in this set (two outputs of one name: the second
    /// would overwrite the first).
    pub fn stage(&mut self, target: &Path, bytes: &[u8]) -> std::io::Result<()> {
        let _guard = WriteGuard::start()?;
        if self.staged.iter().any(|(_, staged)| staged == target) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::AlreadyExists,
                "two outputs of this run have this name; nothing was written",
            ));
        }
        check_replaceable(target)?;
        let dir = parent_of(target);
        crate::interrupt::note_temporaries_in(dir);
        self.create_dir(dir)?;
        remove_stale_temporaries(target);
        let temp = temporary_beside(target);
        self.staged.push((temp.clone(), target.to_owned()));
        write_synced(&temp, bytes)
    }

    /// Creates `dir` and its missing ancestors, remembering which were missing.
    fn create_dir(&mut self, dir: &Path) -> std::io::Result<()> {
        let missing: Vec<PathBuf> = dir
            .ancestors()
            .filter(|a| !a.as_os_str().is_empty())
            .take_while(|a| !a.exists())
            .map(Path::to_owned)
            .collect();
        std::fs::create_dir_all(dir)?;
        self.created_dirs.extend(missing.into_iter().rev());
        Ok(())
    }

    /// Renames every staged file over its target, in staging order, once every target is
    /// checked to be replaceable (none became a folder since it was staged): a set that cannot
    /// be put in place whole is not put in place at all.
    pub fn commit(mut self) -> std::io::Result<()> {
        let _guard = WriteGuard::start()?;
        for (_, target) in &self.staged {
            check_replaceable(target).map_err(|error| {
                std::io::Error::new(
                    error.kind(),
                    format!("{}: {error}", crate::text::path(target)),
                )
            })?;
        }
        let staged = std::mem::take(&mut self.staged);
        let mut renames = staged.iter();
        for (temp, target) in renames.by_ref() {
            if let Err(error) = std::fs::rename(temp, target) {
                // The rest stays unrenamed: put their temporaries back for the drop to remove.
                self.staged = renames.cloned().collect();
                self.staged.push((temp.clone(), target.clone()));
                self.created_dirs.clear();
                return Err(error);
            }
        }
        self.created_dirs.clear();
        Ok(())
    }
}

/// Refuses a `target` a file cannot be renamed over: a folder (a symbolic link is replaced
/// itself, as a file).
fn check_replaceable(target: &Path) -> std::io::Result<()> {
    match std::fs::symlink_metadata(target) {
        Ok(meta) if meta.is_dir() => Err(std::io::Error::other(
            "it is a folder, not a file; nothing was written (move the folder away)",
        )),
        _ => Ok(()),
    }
}

/// Removes `.<name>.<pid>.tmp` files beside `target` left by processes that no longer run
/// (a SIGKILL during staging; SIGINT/SIGTERM clean up themselves).
fn remove_stale_temporaries(target: &Path) {
    let prefix = format!(".{}.", file_name_of(target));
    for stale in stale_entries(parent_of(target), &prefix, ".tmp", false) {
        let _ = std::fs::remove_file(stale);
    }
}

impl Drop for OutputSet {
    fn drop(&mut self) {
        for (temp, _) in &self.staged {
            let _ = std::fs::remove_file(temp);
        }
        // Innermost first; a folder that holds anything else stays.
        for dir in self.created_dirs.iter().rev() {
            let _ = std::fs::remove_dir(dir);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nothing_changes_until_commit_and_an_abandoned_set_leaves_no_trace() {
        let dir = tempfile::tempdir().unwrap();
        let old = dir.path().join("a.txt");
        std::fs::write(&old, "old").unwrap();
        let new_dir = dir.path().join("new/deeper");
        {
            let mut set = OutputSet::new();
            set.stage(&old, b"new").unwrap();
            set.stage(&new_dir.join("b.txt"), b"b").unwrap();
            assert_eq!(std::fs::read_to_string(&old).unwrap(), "old");
        }
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "old");
        assert!(!dir.path().join("new").exists());
        let entries = std::fs::read_dir(dir.path()).unwrap().count();
        assert_eq!(entries, 1, "temporaries removed");

        let mut set = OutputSet::new();
        set.stage(&old, b"new").unwrap();
        set.stage(&new_dir.join("b.txt"), b"b").unwrap();
        set.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&old).unwrap(), "new");
        assert_eq!(std::fs::read_to_string(new_dir.join("b.txt")).unwrap(), "b");
    }

    /// A target that is a folder, or one staged twice, is refused before any file of the set is
    /// replaced (issue 42: `fit` wrote its reports, then failed on `fits/X.toml` being a folder;
    /// `validate` staged two pages of one name and lost the first).
    #[test]
    fn a_set_with_an_unreplaceable_or_repeated_target_changes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let (a, folder) = (dir.path().join("a.txt"), dir.path().join("X.toml"));
        std::fs::write(&a, "old").unwrap();
        std::fs::create_dir(&folder).unwrap();
        let mut set = OutputSet::new();
        set.stage(&a, b"new").unwrap();
        let error = set.stage(&folder, b"entry").unwrap_err();
        assert!(error.to_string().contains("it is a folder"), "{error}");
        drop(set);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert!(folder.is_dir());

        // A folder appearing after staging: the commit refuses before the first rename.
        let late = dir.path().join("late.toml");
        let mut set = OutputSet::new();
        set.stage(&a, b"new").unwrap();
        set.stage(&late, b"entry").unwrap();
        std::fs::create_dir(&late).unwrap();
        let error = set.commit().unwrap_err();
        assert!(
            error.to_string().contains("late.toml: it is a folder"),
            "{error}"
        );
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");

        let mut set = OutputSet::new();
        set.stage(&a, b"one").unwrap();
        let error = set.stage(&a, b"two").unwrap_err();
        assert!(error.to_string().contains("two outputs"), "{error}");
        drop(set);
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        let entries = std::fs::read_dir(dir.path()).unwrap().count();
        assert_eq!(entries, 3, "no temporary left");
    }
}
