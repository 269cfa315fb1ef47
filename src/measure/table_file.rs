//! What the two measurement tables share (docs/design.md §2.1 and §2.8): a §2.1 file is read as
//! a table whose columns are §2.1's own, a layout's table as one whose columns the layout names;
//! both are the same file underneath — UTF-8 lines, `# key: value` metadata wherever it stands,
//! a header row (the first line that is neither blank nor `#`), then data rows — split by
//! [`crate::table_text`] and grouped by wavelength here. The one place a row becomes a
//! [`MeasurementPoint`] and rows become [`MeasurementSet`]s is here too.

use std::collections::BTreeMap;
use std::path::Path;

use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::metadata::HeaderWavelength;
use super::{MeasurementPoint, MeasurementSet};
use crate::table_text::{self, is_comment, last_column, Field};
use crate::text::shown;

/// Two wavelengths are the same when they agree to 1 ppm: tighter than any monochromator, looser
/// than the digits a file writer may drop between a header and a column.
const WAVELENGTH_RELATIVE_TOLERANCE: f64 = 1e-6;

pub(crate) fn same_wavelength(a: f64, b: f64) -> bool {
    (a - b).abs() <= WAVELENGTH_RELATIVE_TOLERANCE * a.max(b)
}

pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The bytes of a measurement file, refused with a message if it cannot be read.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, MeasureError> {
    let mut bytes = Vec::new();
    std::io::Read::read_to_end(&mut open_file(path)?, &mut bytes)
        .map_err(|e| unreadable(e).in_file(path))?;
    Ok(bytes)
}

/// A measurement file opened for reading, or refused as a whole (missing, a folder,
/// unreadable).
pub(crate) fn open_file(path: &Path) -> Result<std::fs::File, MeasureError> {
    let whole_file = |kind| Refusal::new(1, 1, kind).in_file(path);
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => return Err(whole_file(MeasureErrorKind::IsDirectory)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(whole_file(MeasureErrorKind::NotFound))
        }
        _ => {}
    }
    std::fs::File::open(path).map_err(|e| unreadable(e).in_file(path))
}

/// The refusal of a file the system could not read, as a whole.
pub(crate) fn unreadable(error: std::io::Error) -> Refusal {
    Refusal::new(
        1,
        1,
        MeasureErrorKind::Unreadable {
            reason: error.to_string(),
        },
    )
}

/// The text of the file without a leading byte-order mark, or its first byte that is not UTF-8.
pub(crate) fn decode_utf8(bytes: &[u8]) -> Result<&str, Refusal> {
    table_text::decode_utf8(bytes)
        .map_err(|r| r.map(|invalid| MeasureErrorKind::InvalidUtf8 { byte: invalid.byte }))
}

/// A line of the file, numbered from 1, without its terminator.
pub(crate) type NumberedLine<'a> = (u64, &'a str);

/// The file's non-blank lines, numbered from 1; a file without one is refused as empty.
pub(crate) fn numbered_lines(text: &str) -> Result<Vec<NumberedLine<'_>>, Refusal> {
    let lines: Vec<NumberedLine<'_>> = table_text::lines(text)
        .filter(|(_, line)| !line.trim().is_empty())
        .collect();
    if lines.is_empty() {
        return Err(Refusal::new(1, 1, MeasureErrorKind::EmptyFile));
    }
    Ok(lines)
}

/// A table's lines sorted by role: its `#` lines, then its header row and its data rows.
pub(crate) struct TableLines<'a> {
    pub comments: Vec<NumberedLine<'a>>,
    /// The header row first.
    content: Vec<NumberedLine<'a>>,
}

impl<'a> TableLines<'a> {
    /// The header row, or a refusal of a file without one (asked after the metadata, whose
    /// problems are reported first).
    pub(crate) fn header(&self) -> Result<NumberedLine<'a>, Refusal> {
        self.content
            .first()
            .copied()
            .ok_or_else(|| Refusal::new(1, 1, MeasureErrorKind::NoHeader))
    }

    /// The data rows, in file order.
    pub(crate) fn rows(&self) -> &[NumberedLine<'a>] {
        self.content.get(1..).unwrap_or_default()
    }
}

/// The lines of `text` by role, refusing an empty file.
pub(crate) fn table_lines(text: &str) -> Result<TableLines<'_>, Refusal> {
    let (comments, content) = numbered_lines(text)?
        .into_iter()
        .partition(|(_, line)| is_comment(line));
    Ok(TableLines { comments, content })
}

/// The fields of line `number`.
pub(crate) fn fields_of(number: u64, line: &str) -> Result<Vec<Field<'_>>, Refusal> {
    table_text::split_fields(number, line).map_err(|r| r.map(MeasureErrorKind::Token))
}

/// Refuses a row (line `number`, text `line`) of another number of fields than the header's
/// `expected`, pointing at its first extra field or just past its end.
pub(crate) fn check_width(
    number: u64,
    line: &str,
    fields: &[Field<'_>],
    expected: usize,
) -> Result<(), Refusal> {
    if fields.len() == expected {
        return Ok(());
    }
    let column = fields.get(expected).map_or(last_column(line), |f| f.column);
    Err(Refusal::new(
        number,
        column,
        MeasureErrorKind::FieldCount {
            found: fields.len(),
            expected,
        },
    ))
}

/// A finite number, or why the field is not one.
pub(crate) fn parse_number(column: &str, text: &str) -> Result<f64, MeasureErrorKind> {
    use crate::table_text::NumberProblem;
    table_text::parse_finite(text).map_err(|problem| match problem {
        NumberProblem::Empty => MeasureErrorKind::EmptyField {
            column: column.to_string(),
        },
        NumberProblem::NotFinite => MeasureErrorKind::NotFinite {
            column: column.to_string(),
            value: shown(text),
        },
        NumberProblem::NotANumber => MeasureErrorKind::NotANumber {
            column: column.to_string(),
            value: shown(text),
        },
    })
}

/// One row of a table in §2.1's meaning: the one place a row becomes a [`MeasurementPoint`].
/// Angles in degrees with θ ≥ 0; `values` and `uncertainties` aligned with the set's elements.
pub(crate) fn measurement_point(
    [theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg]: [f64; 4],
    values: Vec<f64>,
    uncertainties: Vec<Option<f64>>,
    line: u64,
) -> MeasurementPoint {
    MeasurementPoint {
        theta_i_deg,
        phi_i_deg,
        theta_r_deg,
        phi_r_deg,
        values,
        uncertainties,
        line,
    }
}

/// What every set read from one file shares.
pub(crate) struct FileFacts {
    pub sha256: String,
    pub material: String,
    pub metadata: BTreeMap<String, String>,
    pub elements: Vec<usize>,
}

impl FileFacts {
    /// The set of the file `source` at `wavelength_um` holding `points`, with `notes`: the one
    /// place rows become a [`MeasurementSet`].
    pub(crate) fn set(
        &self,
        source: &Path,
        wavelength_um: f64,
        points: Vec<MeasurementPoint>,
        notes: Vec<String>,
    ) -> MeasurementSet {
        MeasurementSet {
            source: source.to_path_buf(),
            sha256: self.sha256.clone(),
            material: self.material.clone(),
            wavelength_um,
            metadata: self.metadata.clone(),
            elements: self.elements.clone(),
            points,
            merged: Vec::new(),
            notes,
        }
    }
}

/// The material a file names in `# material:`, else the file's stem.
pub(crate) fn material_of(named: Option<&String>, source: &Path) -> String {
    match named {
        Some(material) => material.clone(),
        None => source
            .file_stem()
            .map(|stem| stem.to_string_lossy().into_owned())
            .unwrap_or_default(),
    }
}

/// The rows' wavelengths: the `# wavelength_um:` line's for all, or each row's own, with the
/// column it is in.
pub(crate) enum RowWavelengths {
    Header(f64),
    PerRow(Vec<(HeaderWavelength, u64)>),
}

/// The points by wavelength, ascending: all at the header's, or one group per distinct row
/// wavelength (equal within [`WAVELENGTH_RELATIVE_TOLERANCE`], the group keeping its first row's
/// value), rows in file order. Unless `spectral`, a second wavelength is refused at its first
/// row.
pub(crate) fn wavelength_groups(
    points: Vec<MeasurementPoint>,
    wavelengths: RowWavelengths,
    spectral: bool,
) -> Result<Vec<(f64, Vec<MeasurementPoint>)>, Refusal> {
    let rows = match wavelengths {
        RowWavelengths::Header(um) => return Ok(vec![(um, points)]),
        RowWavelengths::PerRow(rows) => rows,
    };
    let mut groups: Vec<(HeaderWavelength, Vec<MeasurementPoint>)> = Vec::new();
    for (point, (row, column)) in points.into_iter().zip(rows) {
        match groups
            .iter()
            .position(|(w, _)| same_wavelength(w.um, row.um))
        {
            Some(i) => groups[i].1.push(point),
            None if groups.is_empty() || spectral => groups.push((row, vec![point])),
            None => {
                let first = &groups[0].0;
                return Err(Refusal::new(
                    row.line,
                    column,
                    MeasureErrorKind::MixedWavelengths {
                        value: shown(&row.text),
                        first: shown(&first.text),
                        first_line: first.line,
                    },
                ));
            }
        }
    }
    groups.sort_by(|a, b| a.0.um.total_cmp(&b.0.um));
    Ok(groups
        .into_iter()
        .map(|(w, points)| (w.um, points))
        .collect())
}

/// A row's wavelength `um` (written `text` at `column` of line `line`): checked against the
/// `# wavelength_um:` line if there is one (then `None`), else the row's own.
pub(crate) fn row_wavelength(
    header: Option<&HeaderWavelength>,
    line: u64,
    column: u64,
    um: f64,
    text: &str,
) -> Result<Option<(HeaderWavelength, u64)>, Refusal> {
    match header {
        Some(header) if !same_wavelength(header.um, um) => Err(Refusal::new(
            line,
            column,
            MeasureErrorKind::WavelengthDisagrees {
                value: shown(text),
                header: shown(&header.text),
                header_line: header.line,
            },
        )),
        Some(_) => Ok(None),
        None => Ok(Some((
            HeaderWavelength {
                um,
                text: text.to_string(),
                line,
            },
            column,
        ))),
    }
}
