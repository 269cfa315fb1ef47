//! Expanding the command line's CSV-or-folder arguments (docs/design.md §4, `irpol fit <CSV or
//! folder>...`) into the list of measurement files.

use std::path::{Path, PathBuf};

use super::error::{MeasureError, MeasureErrorKind, Refusal};

/// Files are kept as given (whatever their extension); a folder contributes its `*.csv` files
/// (extension matched case-insensitively, not recursive), sorted by name. A missing path, an
/// unreadable folder or a folder without any CSV file is an error, so a mistyped argument is
/// never silently skipped.
pub fn collect_measurement_files(inputs: &[PathBuf]) -> Result<Vec<PathBuf>, MeasureError> {
    let mut files = Vec::new();
    for input in inputs {
        let refuse = |kind| Refusal::new(1, 1, kind).in_file(input);
        let meta = std::fs::metadata(input).map_err(|e| {
            refuse(match e.kind() {
                std::io::ErrorKind::NotFound => MeasureErrorKind::NotFound,
                _ => MeasureErrorKind::Unreadable {
                    reason: e.to_string(),
                },
            })
        })?;
        if !meta.is_dir() {
            files.push(input.clone());
            continue;
        }
        let unreadable = |e: std::io::Error| {
            refuse(MeasureErrorKind::Unreadable {
                reason: e.to_string(),
            })
        };
        let mut in_folder = Vec::new();
        for entry in std::fs::read_dir(input).map_err(unreadable)? {
            let path = entry.map_err(unreadable)?.path();
            if has_csv_extension(&path) && path.is_file() {
                in_folder.push(path);
            }
        }
        if in_folder.is_empty() {
            return Err(refuse(MeasureErrorKind::NoCsvInFolder));
        }
        in_folder.sort();
        files.extend(in_folder);
    }
    Ok(files)
}

fn has_csv_extension(path: &Path) -> bool {
    path.extension()
        .is_some_and(|ext| ext.eq_ignore_ascii_case("csv"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_expand_to_sorted_csv_files_and_files_stay_as_given() {
        let dir = tempfile::tempdir().unwrap();
        for name in ["b.csv", "a.CSV", "notes.txt", "c.csv"] {
            std::fs::write(dir.path().join(name), "x").unwrap();
        }
        std::fs::create_dir(dir.path().join("sub.csv")).unwrap();
        let explicit = dir.path().join("notes.txt");
        let files =
            collect_measurement_files(&[explicit.clone(), dir.path().to_path_buf()]).unwrap();
        let names: Vec<_> = files
            .iter()
            .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
            .collect();
        assert_eq!(names, ["notes.txt", "a.CSV", "b.csv", "c.csv"]);
        assert_eq!(files[0], explicit);
    }

    #[test]
    fn missing_paths_and_empty_folders_are_errors() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("nope.csv");
        let err = collect_measurement_files(std::slice::from_ref(&missing)).unwrap_err();
        assert_eq!(
            err.to_string(),
            format!("{}:1:1: no such file or directory", missing.display())
        );
        let err = collect_measurement_files(&[dir.path().to_path_buf()]).unwrap_err();
        assert_eq!(err.kind, MeasureErrorKind::NoCsvInFolder);
    }
}
