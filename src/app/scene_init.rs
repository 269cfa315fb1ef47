//! `irpol scene init`: writes a commented starter scene, so that the
//! scene format can be discovered. The scene is a procedural sphere on a procedural plane with inline materials,
//! so it renders as written from whatever folder it lands in, with no mesh or material library.

use crate::atomic::write_new_file;
use std::path::{Path, PathBuf};

/// The starter scene's text (docs/scenes.md describes every key it uses).
pub fn starter_scene() -> &'static str {
    include_str!("starter_scene.toml")
}

#[derive(Debug, thiserror::Error)]
pub enum SceneInitError {
    #[error(
        "{} already exists; irpol scene init never overwrites a file (remove it or give \
         --out another name)",
        crate::text::path(.0)
    )]
    Exists(PathBuf),
    #[error("{}: cannot write: {source}", crate::text::path(path))]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
}

/// Writes [`starter_scene`] to `path`, creating its folder. An existing file (or folder) at
/// `path` is refused, and the file appears complete or not at all.
pub fn write_starter_scene(path: &Path) -> Result<(), SceneInitError> {
    // `symlink_metadata` so that a dangling symbolic link also counts as taken.
    if path.symlink_metadata().is_ok() {
        return Err(SceneInitError::Exists(path.to_owned()));
    }
    write_new_file(path, starter_scene().as_bytes()).map_err(|source| {
        if source.kind() == std::io::ErrorKind::AlreadyExists {
            SceneInitError::Exists(path.to_owned())
        } else {
            SceneInitError::Write {
                path: path.to_owned(),
                source,
            }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_starter_is_written_once_and_loads() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("new/scene.toml");
        write_starter_scene(&path).unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), starter_scene());
        let scene = crate::scene::load_scene(&path).unwrap();
        assert_eq!(scene.object_names, ["sphere", "ground"]);
        let again = write_starter_scene(&path).unwrap_err().to_string();
        assert!(again.contains("already exists"), "{again}");
        assert!(!again.contains('\n'));
        // Only the scene: no temporary file left beside it.
        assert_eq!(
            std::fs::read_dir(path.parent().unwrap()).unwrap().count(),
            1
        );
    }
}
