//! The one entry of every command that reads measurement files (docs/design.md §2.8): a file is
//! read through a layout when the caller gives one or when the file names its own on a
//! `# layout: FILE` line (relative to the file's folder), else as docs/design.md §2.1 says.

use std::path::{Path, PathBuf};

use super::csv_reader::{parse_sets_reading, read_scanned_sets};
use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::layout::{parse_with_layout_reading, Layout};
use super::metadata::split_metadata_line;
use super::selection::{RowSelection, SelectionError};
use super::streaming::scan_file;
use super::table_file::{decode_utf8, read_bytes};
use super::units::AngleReading;
use super::MeasurementSet;
use crate::table_text;
use crate::text::shown;

pub use super::metadata::LAYOUT_KEY;

/// Reads one measurement file as one set per wavelength, ascending: through `layout` if given,
/// else through the layout its `# layout:` line names, else as a docs/design.md §2.1 file. A
/// file whose line names another layout than `layout` is refused naming both.
pub fn read_measurement_file(
    path: &Path,
    layout: Option<&Layout>,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    read_file(path, layout, AngleReading::Auto)
}

/// [`read_measurement_file`] with the angles read as `angles` says (`--angles`).
fn read_file(
    path: &Path,
    layout: Option<&Layout>,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    if starts_as_tensor_file(path) {
        if angles != AngleReading::Auto {
            return Err(Refusal::new(
                1,
                1,
                MeasureErrorKind::AnglesFlag {
                    flag: "--angles",
                    reason: "a Mitsuba table has no angle columns to read: drop --angles".into(),
                },
            )
            .in_file(path));
        }
        if layout.is_some() {
            return Err(Refusal::new(
                1,
                1,
                MeasureErrorKind::Table(crate::interop::TensorError::file(
                    "--layout reads CSV tables; a Mitsuba table has its own layout: drop --layout",
                )),
            )
            .in_file(path));
        }
        return super::pbsdf::read_table_measurements(path);
    }
    if layout.is_none() {
        // A §2.1 file is read as a stream; a table read through a layout, whole.
        let scan = scan_file(path)?;
        if scan.layout.is_none() {
            return read_scanned_sets(path, scan, angles);
        }
    }
    let bytes = read_bytes(path)?;
    parse_file(path, &bytes, layout, angles)
}

/// Whether the file at `path` begins with a Mitsuba tensor file's magic (docs/design.md §2.10):
/// such a table is read as measurements without taking its bytes into memory at once.
fn starts_as_tensor_file(path: &Path) -> bool {
    let mut head = [0u8; 12];
    std::fs::File::open(path)
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut head))
        .is_ok_and(|()| crate::interop::is_tensor_file(&head))
}

/// [`read_measurement_file`] of a file's bytes; `source` names them and locates a relative
/// `# layout:` path.
pub fn parse_measurement_file(
    source: &Path,
    bytes: &[u8],
    layout: Option<&Layout>,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    parse_file(source, bytes, layout, AngleReading::Auto)
}

fn parse_file(
    source: &Path,
    bytes: &[u8],
    layout: Option<&Layout>,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    let through = |layout: &Layout| parse_with_layout_reading(source, bytes, layout, angles);
    match (layout, named_layout(source, bytes)?) {
        (None, None) => parse_sets_reading(source, bytes, angles),
        (Some(layout), None) => through(layout),
        (None, Some((named, _))) => through(&named),
        (Some(given), Some((named, at))) => {
            if same_meaning(given, &named) {
                through(given)
            } else {
                Err(at.refusal(MeasureErrorKind::LayoutsDisagree {
                    named: crate::text::path(&named.source),
                    given: crate::text::path(&given.source),
                }))
            }
        }
    }
}

/// Whether two layouts read a table the same way (wherever their files are).
fn same_meaning(a: &Layout, b: &Layout) -> bool {
    a.columns == b.columns && a.conventions == b.conventions && a.uncertainty == b.uncertainty
}

/// Where a `# layout:` line's value stands, for messages.
struct LineAt<'a> {
    file: &'a Path,
    line: u64,
    column: u64,
}

impl LineAt<'_> {
    fn refusal(&self, kind: MeasureErrorKind) -> MeasureError {
        Refusal::new(self.line, self.column, kind).in_file(self.file)
    }
}

/// The layout a file names on its first `# layout:` line, read; `None` without one (or for bytes
/// that are not text, which the reader then refuses with its own message).
fn named_layout<'a>(
    source: &'a Path,
    bytes: &[u8],
) -> Result<Option<(Layout, LineAt<'a>)>, MeasureError> {
    let Ok(text) = decode_utf8(bytes) else {
        return Ok(None);
    };
    let found = table_text::lines(text).find_map(|(number, line)| {
        split_metadata_line(line)
            .filter(|(key, _, _)| *key == LAYOUT_KEY)
            .map(|(_, value, column)| (number, value, column))
    });
    let Some((line, value, column)) = found else {
        return Ok(None);
    };
    let at = LineAt {
        file: source,
        line,
        column,
    };
    if value.is_empty() {
        return Err(at.refusal(MeasureErrorKind::EmptyHeaderValue {
            key: LAYOUT_KEY.to_string(),
        }));
    }
    let path = beside(source, value);
    match Layout::read(&path) {
        Ok(layout) => Ok(Some((layout, at))),
        Err(error) if error.is_unreadable_path() => {
            Err(at.refusal(MeasureErrorKind::NamedLayoutUnreadable {
                value: shown(value),
                path: crate::text::path(&path),
                reason: error.kind.to_string(),
            }))
        }
        Err(error) => Err(error),
    }
}

/// A path a file names, relative to that file's folder unless absolute.
fn beside(file: &Path, named: &str) -> PathBuf {
    let named = Path::new(named);
    match file.parent() {
        Some(folder) if named.is_relative() => folder.join(named),
        _ => named.to_path_buf(),
    }
}

/// How a command reads its measurement files: through which layout (if the files do not name
/// their own), which rows it keeps and how it reads their angles (`--angles`). The default reads
/// every file as it says and keeps all.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ReadOptions {
    pub layout: Option<Layout>,
    pub selection: RowSelection,
    pub angles: AngleReading,
}

/// Why a measurement file cannot be read as asked.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReadError {
    #[error(transparent)]
    Measure(#[from] MeasureError),
    #[error(transparent)]
    Selection(#[from] SelectionError),
}

impl ReadOptions {
    /// One file's sets, one per wavelength, ascending ([`read_measurement_file`]), with only the
    /// selected rows.
    pub fn read(&self, path: &Path) -> Result<Vec<MeasurementSet>, ReadError> {
        let sets = read_file(path, self.layout.as_ref(), self.angles)?;
        Ok(self.selection.apply(sets)?)
    }

    /// [`ReadOptions::read`] of a file's bytes; `source` names them.
    pub fn parse(&self, source: &Path, bytes: &[u8]) -> Result<Vec<MeasurementSet>, ReadError> {
        let sets = parse_file(source, bytes, self.layout.as_ref(), self.angles)?;
        Ok(self.selection.apply(sets)?)
    }
}
