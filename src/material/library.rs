//! A library folder: finding a material's file and listing every material in it.

use super::{Material, MaterialError};
use std::path::{Path, PathBuf};

/// The file of material `name` in the library folder `dir`.
pub fn find_material(dir: &Path, name: &str) -> Result<PathBuf, MaterialError> {
    let path = dir.join(format!("{name}.toml"));
    if path.is_file() {
        Ok(path)
    } else {
        Err(MaterialError::NotFound {
            name: name.to_owned(),
            dir: dir.to_owned(),
        })
    }
}

/// A library folder as read: its materials, and the `.toml` files that are not one.
#[derive(Debug, Default)]
pub struct Library {
    /// Every material, sorted by file name.
    pub materials: Vec<(PathBuf, Material)>,
    /// Each `.toml` file that does not load as a material (a user's notes, a broken entry), with
    /// why: skipped, so one stray file does not stop a fit or a listing of the others.
    pub skipped: Vec<(PathBuf, MaterialError)>,
}

impl Library {
    /// One warning per skipped file.
    pub fn warnings(&self) -> Vec<String> {
        self.skipped
            .iter()
            .map(|(_, error)| {
                let mut text = error.to_string();
                let mut source = std::error::Error::source(error);
                while let Some(cause) = source {
                    text = format!("{text}: {cause}");
                    source = cause.source();
                }
                format!("{text}; skipped, the library holds only material files")
            })
            .collect()
    }
}

/// Every material in a library folder, sorted by file name; `.toml` files that do not load are
/// skipped and reported in [`Library::skipped`]. Only an unreadable folder is an error.
pub fn list_library(dir: &Path) -> Result<Library, MaterialError> {
    let entries = std::fs::read_dir(dir).map_err(|source| MaterialError::Read {
        path: dir.to_owned(),
        source,
    })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut library = Library::default();
    for path in paths {
        match Material::load(&path) {
            Ok(material) => library.materials.push((path, material)),
            Err(error) => library.skipped.push((path, error)),
        }
    }
    Ok(library)
}
