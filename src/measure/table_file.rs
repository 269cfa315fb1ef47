//! What the two measurement tables share (docs/design.md §2.1 and §2.8): a §2.1 file is read as
//! a table whose columns are §2.1's own, a layout's table as one whose columns the layout names;
//! both are the same file underneath — UTF-8 lines, `# key: value` metadata wherever it stands,
//! a header row (the first line that is neither blank nor `#`), then data rows — split by
//! [`crate::table_text`] and grouped by wavelength here, each row pushed straight into the
//! columns of its wavelength's [`MeasurementRows`]. The one place rows become
//! [`MeasurementSet`]s is here too.

use std::collections::BTreeMap;
use std::path::Path;

use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::metadata::{wavelength_in_range, HeaderWavelength};
use super::{MeasurementRow, MeasurementRows, MeasurementSet, MAX_MUELLER_SR};
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
        points: MeasurementRows,
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

/// The rows of a file by wavelength, filled as the rows are read (no list of the whole file's
/// rows is made): all at the header's wavelength, or one group per distinct row wavelength
/// (equal within [`WAVELENGTH_RELATIVE_TOLERANCE`], the group keeping its first row's value),
/// rows in file order. Unless `spectral`, a second wavelength is refused at its first row, once
/// every row has been read (the rows' own refusals come first, in file order).
pub(crate) struct WavelengthGroups {
    /// Each wavelength met and its rows, in order of first appearance.
    groups: Vec<(HeaderWavelength, MeasurementRows)>,
    /// Whether a row gives its own wavelength (no `# wavelength_um:` line).
    per_row: bool,
    spectral: bool,
    /// The refusal of the first row of a second wavelength in a file read as one.
    mixed: Option<Refusal>,
    has_uncertainty: Vec<bool>,
    /// Rows to reserve room for in the first group: the file's data rows.
    capacity: usize,
}

impl WavelengthGroups {
    /// No rows yet of the elements whose uncertainty flags are `has_uncertainty`, at `header`'s
    /// wavelength (a `# wavelength_um:` line) or each row's own; `capacity` data rows expected.
    pub(crate) fn new(
        header: Option<&HeaderWavelength>,
        spectral: bool,
        has_uncertainty: Vec<bool>,
        capacity: usize,
    ) -> WavelengthGroups {
        let groups = header
            .map(|h| {
                let rows = MeasurementRows::with_capacity(&has_uncertainty, capacity);
                vec![(h.clone(), rows)]
            })
            .unwrap_or_default();
        WavelengthGroups {
            groups,
            per_row: header.is_none(),
            spectral,
            mixed: None,
            has_uncertainty,
            capacity,
        }
    }

    /// Adds a row to its wavelength's group: `wavelength` is the row's own with its column
    /// ([`row_wavelength`]; `None` under a header wavelength), the rest as
    /// [`MeasurementRows::push`] takes it.
    pub(crate) fn push(
        &mut self,
        wavelength: Option<(HeaderWavelength, u64)>,
        angles: [f64; 4],
        values: &[f64],
        uncertainties: &[Option<f64>],
        line: u64,
    ) {
        let group = match wavelength {
            None => 0,
            Some((row, column)) => self.group_of(row, column),
        };
        self.groups[group]
            .1
            .push(angles, values, uncertainties, line);
    }

    /// The group of a row at wavelength `row` (in `column`), made if it is the first there.
    fn group_of(&mut self, row: HeaderWavelength, column: u64) -> usize {
        if let Some(i) = self
            .groups
            .iter()
            .position(|(w, _)| same_wavelength(w.um, row.um))
        {
            return i;
        }
        if let Some((first, _)) = self.groups.first().filter(|_| !self.spectral) {
            self.mixed.get_or_insert_with(|| {
                Refusal::new(
                    row.line,
                    column,
                    MeasureErrorKind::MixedWavelengths {
                        value: shown(&row.text),
                        first: shown(&first.text),
                        first_line: first.line,
                    },
                )
            });
        }
        // The first group gets the room of the whole file: one wavelength is the usual file.
        let capacity = if self.groups.is_empty() {
            self.capacity
        } else {
            0
        };
        let rows = MeasurementRows::with_capacity(&self.has_uncertainty, capacity);
        self.groups.push((row, rows));
        self.groups.len() - 1
    }

    /// Every row read so far, group by group.
    pub(crate) fn rows(&self) -> impl Iterator<Item = MeasurementRow<'_>> + Clone {
        self.groups.iter().flat_map(|(_, rows)| rows.iter())
    }

    /// Number of rows read.
    pub(crate) fn len(&self) -> usize {
        self.groups.iter().map(|(_, rows)| rows.len()).sum()
    }

    /// The groups by wavelength, ascending, or the refusal of a second wavelength.
    pub(crate) fn finish(mut self) -> Result<Vec<(f64, MeasurementRows)>, Refusal> {
        if let Some(refusal) = self.mixed {
            return Err(refusal);
        }
        if self.per_row && self.groups.len() > 1 {
            // The first group reserved room for every row of the file.
            self.groups[0].1.shrink_to_fit();
        }
        self.groups.sort_by(|a, b| a.0.um.total_cmp(&b.0.um));
        Ok(self
            .groups
            .into_iter()
            .map(|(w, rows)| (w.um, rows))
            .collect())
    }
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
/// Why a Mueller element of `value` sr⁻¹ (read from column `name` as `text`) cannot be measured
/// data, if it cannot: beyond ±[`MAX_MUELLER_SR`]. Every table reader (§2.1 files and layouts,
/// whose normalized elements are checked once multiplied by m00) refuses through this one check.
pub(crate) fn element_value_refusal(
    name: &str,
    value: f64,
    text: &str,
) -> Option<MeasureErrorKind> {
    (!value.is_finite() || value.abs() > MAX_MUELLER_SR).then(|| {
        MeasureErrorKind::ElementTooLarge {
            column: name.to_owned(),
            value: shown(text),
        }
    })
}

/// Why a wavelength_um field's (finite) value is not a wavelength irpol models, if it is not.
pub(crate) fn wavelength_refusal(value: f64, text: &str) -> Option<MeasureErrorKind> {
    if value <= 0.0 {
        Some(MeasureErrorKind::NonPositiveWavelength { value: shown(text) })
    } else if !wavelength_in_range(value) {
        Some(MeasureErrorKind::WavelengthOutOfRange {
            place: "column 'wavelength_um'".to_string(),
            value: shown(text),
        })
    } else {
        None
    }
}
