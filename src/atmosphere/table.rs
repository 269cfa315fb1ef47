//! The atmosphere table of docs/design.md §2.9: a CSV of a radiative-transfer code's path
//! transmittance and path radiance over range, read by [`crate::table_text`] and refused with
//! `file:line: what is wrong and what to do` (a whole-file problem without the line).
//!
//! Lines starting with `#` are comments (`# source: …` and `# geometry: …` are kept for
//! `summary.json`), blank lines are skipped; the first other line is the header row, naming the
//! columns in any order. Two kinds, told apart by the header:
//! - band-integrated: `range_m`, `transmittance`, `path_radiance_w_m2_sr`; one row per range;
//! - spectral: `wavelength_um`, `range_m`, `transmittance`, `path_radiance_w_m2_sr_um`; rows grouped
//!   by wavelength (ascending), every wavelength with the same ranges.
//!
//! Ranges ≥ 0 m and strictly increasing (within each wavelength), at least two; transmittance
//! within [0, 1]; radiances within 0…1e9; wavelengths > 0; every value a finite number; UTF-8
//! text.

use super::{integrate_spectral, BandRows};
use crate::optics::Band;
use crate::table_text::{
    self, is_comment, parse_finite, split_fields, ColumnMap, HeaderProblem, NumberProblem, Problem,
    TableError,
};
use crate::text::{number, shown, shown_at_most};
use std::path::{Path, PathBuf};

/// Characters of a `# source:` or `# geometry:` line kept.
const NOTE_CHARS: usize = 300;

/// Largest radiance of a table (W·m⁻²·sr⁻¹, or per µm): a blackbody at irpol's hottest 10⁴ K
/// emits ~1e4 W·m⁻²·sr⁻¹·µm⁻¹ at 10 µm and 2e7 W·m⁻²·sr⁻¹ over all wavelengths, so any real
/// path is far below, and band integrals of the table stay finite.
const MAX_RADIANCE: f64 = 1e9;

/// What is wrong with an atmosphere table; each message is one line naming the file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AtmosphereTableError {
    #[error(
        "{}: cannot read the atmosphere table: {reason}",
        crate::text::path(file)
    )]
    Read { file: PathBuf, reason: String },
    /// A problem at a line of the file, or of the whole file (too few rows, the band not
    /// covered: line 0).
    #[error(transparent)]
    Table(TableError<Problem>),
}

/// An atmosphere table as read, before it meets a sensor band.
#[derive(Debug, Clone, PartialEq)]
pub struct AtmosphereTable {
    /// The file, as the scene's folder and the scene's key name it.
    pub file: PathBuf,
    /// The `# source:` line(s), joined.
    pub source: Option<String>,
    /// The `# geometry:` line(s), joined.
    pub geometry: Option<String>,
    pub rows: TableRows,
}

/// The rows of either kind of table.
#[derive(Debug, Clone, PartialEq)]
pub enum TableRows {
    Band(BandRows),
    Spectral(SpectralRows),
}

/// A spectral table: every wavelength (ascending) at the same ranges (ascending).
#[derive(Debug, Clone, PartialEq)]
pub struct SpectralRows {
    pub wavelengths_um: Vec<f64>,
    pub ranges_m: Vec<f64>,
    /// τ[w][j] at wavelength w and range j.
    pub transmittance: Vec<Vec<f64>>,
    /// L_λ[w][j] (W·m⁻²·sr⁻¹·µm⁻¹).
    pub radiance_per_um: Vec<Vec<f64>>,
}

impl AtmosphereTable {
    /// The band rows over `band`: a band table's own, a spectral table's integrated with a
    /// blackbody at `reference_k` as the weight of τ; refused when a spectral table does not
    /// cover the band.
    pub fn band_rows(
        &self,
        band: &Band,
        reference_k: f64,
    ) -> Result<BandRows, AtmosphereTableError> {
        match &self.rows {
            TableRows::Band(rows) => Ok(rows.clone()),
            TableRows::Spectral(s) => integrate_spectral(
                band,
                reference_k,
                &s.wavelengths_um,
                &s.ranges_m,
                &s.transmittance,
                &s.radiance_per_um,
            )
            .map_err(|e| {
                let message = format!(
                    "the wavelengths cover {}–{} µm, not the whole sensor band {}–{} µm: add rows \
                     over the band (or narrow sensor.band_um)",
                    number(e.table_um.0),
                    number(e.table_um.1),
                    number(e.band_um.0),
                    number(e.band_um.1)
                );
                AtmosphereTableError::Table(Refusal::at_line(0, message.into()).in_file(&self.file))
            }),
        }
    }
}

/// Reads and checks the table at `path`.
pub fn read_table(path: &Path) -> Result<AtmosphereTable, AtmosphereTableError> {
    let bytes = std::fs::read(path).map_err(|e| AtmosphereTableError::Read {
        file: path.to_owned(),
        reason: e.to_string(),
    })?;
    parse_table(path, &bytes)
}

/// [`read_table`] of a file's bytes; `path` names it in messages.
pub fn parse_table(path: &Path, bytes: &[u8]) -> Result<AtmosphereTable, AtmosphereTableError> {
    let refuse = |refusal: Refusal| AtmosphereTableError::Table(refusal.in_file(path));
    let text = table_text::decode_utf8(bytes).map_err(|refusal| {
        refuse(at(
            refusal.line as usize,
            "invalid UTF-8: an atmosphere table must be UTF-8 text (save it as UTF-8)".into(),
        ))
    })?;
    let (notes, rows) = parse_text(text).map_err(refuse)?;
    Ok(AtmosphereTable {
        file: path.to_owned(),
        source: notes.source,
        geometry: notes.geometry,
        rows,
    })
}

/// A refusal at a line (line 0: of the whole file), before the path is attached.
type Refusal = table_text::Refusal<Problem>;

/// The refusal of line `line` (0: the whole file) saying `message`.
fn at(line: usize, message: String) -> Refusal {
    Refusal::at_line(line as u64, Problem(message))
}

/// The `# source:` and `# geometry:` lines.
#[derive(Default)]
struct Notes {
    source: Option<String>,
    geometry: Option<String>,
}

impl Notes {
    /// Keeps a comment's text (after the `#`) if it is a source or geometry line.
    fn take(&mut self, comment: &str) {
        let comment = comment.trim();
        let Some((key, value)) = comment.split_once(':') else {
            return;
        };
        let slot = match key.trim().to_ascii_lowercase().as_str() {
            "source" => &mut self.source,
            "geometry" => &mut self.geometry,
            _ => return,
        };
        let value = shown_at_most(value.trim(), NOTE_CHARS);
        *slot = Some(match slot.take() {
            Some(earlier) => format!("{earlier} {value}"),
            None => value,
        });
    }
}

/// What a column holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Column {
    Wavelength,
    Range,
    Transmittance,
    BandRadiance,
    SpectralRadiance,
}

const COLUMNS: [(Column, &str); 5] = [
    (Column::Wavelength, "wavelength_um"),
    (Column::Range, "range_m"),
    (Column::Transmittance, "transmittance"),
    (Column::BandRadiance, "path_radiance_w_m2_sr"),
    (Column::SpectralRadiance, "path_radiance_w_m2_sr_um"),
];

/// The two kinds of table, for messages.
const KINDS: &str = "a band table has range_m, transmittance, path_radiance_w_m2_sr; a spectral \
                     table has wavelength_um, range_m, transmittance, path_radiance_w_m2_sr_um";

impl Column {
    fn name(self) -> &'static str {
        COLUMNS[self as usize].1
    }

    /// Why `value` cannot be in this column, if it cannot.
    fn problem(self, value: f64) -> Option<String> {
        let v = number(value);
        match self {
            Column::Wavelength if value <= 0.0 => Some(format!("{v} µm must be > 0")),
            Column::Range if value < 0.0 => Some(format!("{v} m must be ≥ 0")),
            Column::Transmittance if !(0.0..=1.0).contains(&value) => Some(format!(
                "{v} is outside [0, 1] (a fraction, not a percentage)"
            )),
            Column::BandRadiance | Column::SpectralRadiance if value < 0.0 => {
                Some(format!("{v} must be ≥ 0 (a radiance)"))
            }
            Column::BandRadiance | Column::SpectralRadiance if value > MAX_RADIANCE => Some(
                format!("{v} is beyond 1e9: not a radiance in W·m⁻²·sr⁻¹ (per µm if spectral)"),
            ),
            _ => None,
        }
    }
}

/// Where each column is in a row, and which kind of table the columns make.
struct Shape {
    columns: ColumnMap<Column>,
    spectral: bool,
}

/// Notes and rows of the text of a table.
fn parse_text(text: &str) -> Result<(Notes, TableRows), Refusal> {
    let mut notes = Notes::default();
    let mut shape: Option<Shape> = None;
    let mut band = BandBuilder::default();
    let mut spectral = SpectralBuilder::default();
    let mut last_line = 0;
    for (number, raw) in table_text::lines(text) {
        let (line, trimmed) = (number as usize, raw.trim());
        if trimmed.is_empty() {
            continue;
        }
        if is_comment(trimmed) {
            notes.take(&trimmed[1..]);
            continue;
        }
        let Some(shape) = &shape else {
            shape = Some(parse_header(trimmed, line)?);
            continue;
        };
        let [w, r, t, l] = parse_row(trimmed, line, shape)?;
        if shape.spectral {
            spectral.push(line, w, r, t, l)?;
        } else {
            band.push(line, r, t, l)?;
        }
        last_line = line;
    }
    let shape = shape.ok_or_else(|| {
        at(
            1,
            format!(
                "no header row: the file is empty or only comments; the first other line names \
                 the columns ({KINDS})"
            ),
        )
    })?;
    let rows = if shape.spectral {
        TableRows::Spectral(spectral.finish(last_line)?)
    } else {
        TableRows::Band(band.finish(last_line)?)
    };
    Ok((notes, rows))
}

/// The header row: known names, no duplicates, exactly the columns of one kind.
fn parse_header(text: &str, line: usize) -> Result<Shape, Refusal> {
    let refuse = |message: String| Err(at(line, message));
    let fields = split_fields(line as u64, text).map_err(|r| at(line, r.kind.to_string()))?;
    let known = |name: &str| COLUMNS.iter().find(|(_, k)| *k == name).map(|&(c, _)| c);
    let columns = ColumnMap::of_header(line as u64, &fields, known, false).map_err(|r| {
        at(
            line,
            match r.kind {
                HeaderProblem::Token(problem) => problem.to_string(),
                HeaderProblem::Empty => unknown_column(""),
                HeaderProblem::Unknown(name) => unknown_column(&name),
                HeaderProblem::Duplicate { name, .. } => {
                    format!("column '{name}' appears twice: keep one")
                }
            },
        )
    })?;
    let has = |column: Column| columns.has(column);
    let spectral = has(Column::Wavelength);
    if spectral && has(Column::BandRadiance) {
        return refuse(
            "column 'path_radiance_w_m2_sr' is band-integrated but the table has wavelength_um: \
             a spectral table gives path_radiance_w_m2_sr_um (per µm)"
                .into(),
        );
    }
    if !spectral && has(Column::SpectralRadiance) {
        return refuse(
            "column 'path_radiance_w_m2_sr_um' is per µm but the table has no wavelength_um: add \
             it, or give the band-integrated path_radiance_w_m2_sr"
                .into(),
        );
    }
    let required: &[Column] = if spectral {
        &[
            Column::Range,
            Column::Transmittance,
            Column::SpectralRadiance,
        ]
    } else {
        &[Column::Range, Column::Transmittance, Column::BandRadiance]
    };
    if let Some(missing) = columns.missing(required) {
        return refuse(format!("missing column '{}' ({KINDS})", missing.name()));
    }
    Ok(Shape { columns, spectral })
}

fn unknown_column(name: &str) -> String {
    if name.is_empty() {
        return "empty column name (a doubled or trailing ',' in the header row)".into();
    }
    match COLUMNS.iter().find(|(_, k)| k.eq_ignore_ascii_case(name)) {
        Some((_, known)) => format!(
            "unknown column '{}' (column names are case-sensitive: did you mean '{known}'?)",
            shown(name)
        ),
        None => format!("unknown column '{}' ({KINDS})", shown(name)),
    }
}

/// One data row as [wavelength (0 in a band table), range, τ, radiance].
fn parse_row(text: &str, line: usize, shape: &Shape) -> Result<[f64; 4], Refusal> {
    let fields = split_fields(line as u64, text).map_err(|r| at(line, r.kind.to_string()))?;
    if fields.len() != shape.columns.width() {
        return Err(at(
            line,
            format!(
                "the row has {} fields, the header row has {}",
                fields.len(),
                shape.columns.width()
            ),
        ));
    }
    let radiance = if shape.spectral {
        Column::SpectralRadiance
    } else {
        Column::BandRadiance
    };
    let mut values = [0.0; 4];
    for (slot, column) in [
        Column::Wavelength,
        Column::Range,
        Column::Transmittance,
        radiance,
    ]
    .into_iter()
    .enumerate()
    {
        let Some(i) = shape.columns.field(column) else {
            continue;
        };
        let text = fields[i].text.as_ref();
        let value = parse_finite(text).map_err(|problem| {
            let why = match problem {
                NumberProblem::Empty => "empty, expected a number".to_string(),
                NumberProblem::NotFinite => format!("'{}' is not a finite number", shown(text)),
                NumberProblem::NotANumber => format!("'{}' is not a number", shown(text)),
            };
            at(line, format!("column '{}': {why}", column.name()))
        })?;
        if let Some(why) = column.problem(value) {
            return Err(at(line, format!("column '{}': {why}", column.name())));
        }
        values[slot] = value;
    }
    Ok(values)
}

/// "`r` m is not after `previous` m" for a range out of order.
fn not_increasing(r: f64, previous: f64, within: &str) -> String {
    format!(
        "column 'range_m': {} m is not after {} m on the row before: ranges must be strictly \
         increasing{within}",
        number(r),
        number(previous)
    )
}

/// "N data row(s)" refusal of a table too short to interpolate.
fn too_few(count: usize, line: usize, what: &str) -> Refusal {
    // Line 0 (no data row at all) is the whole file.
    at(
        line,
        format!(
            "{count} range(s){what}: the table needs at least two ranges to interpolate between"
        ),
    )
}

#[derive(Default)]
struct BandBuilder {
    ranges: Vec<f64>,
    tau: Vec<f64>,
    radiance: Vec<f64>,
}

impl BandBuilder {
    fn push(&mut self, line: usize, r: f64, t: f64, l: f64) -> Result<(), Refusal> {
        if let Some(&previous) = self.ranges.last().filter(|&&p| r <= p) {
            return Err(at(line, not_increasing(r, previous, "")));
        }
        self.ranges.push(r);
        self.tau.push(t);
        self.radiance.push(l);
        Ok(())
    }

    fn finish(self, last_line: usize) -> Result<BandRows, Refusal> {
        if self.ranges.len() < 2 {
            return Err(too_few(self.ranges.len(), last_line, ""));
        }
        Ok(BandRows::new(self.ranges, self.tau, self.radiance))
    }
}

#[derive(Default)]
struct SpectralBuilder {
    rows: Option<SpectralRows>,
    /// The line where the current wavelength's rows began.
    block_line: usize,
}

impl SpectralBuilder {
    fn push(&mut self, line: usize, w: f64, r: f64, t: f64, l: f64) -> Result<(), Refusal> {
        let rows = self.rows.get_or_insert_with(|| SpectralRows {
            wavelengths_um: Vec::new(),
            ranges_m: Vec::new(),
            transmittance: Vec::new(),
            radiance_per_um: Vec::new(),
        });
        let current = rows.wavelengths_um.last().copied();
        if current != Some(w) {
            if let Some(previous) = current {
                if w < previous {
                    return Err(at(
                        line,
                        format!(
                            "column 'wavelength_um': {} µm comes after {} µm: group the rows by \
                             wavelength, wavelengths ascending (ranges ascending within each)",
                            number(w),
                            number(previous)
                        ),
                    ));
                }
                close_block(rows, self.block_line, line)?;
            }
            rows.wavelengths_um.push(w);
            rows.transmittance.push(Vec::new());
            rows.radiance_per_um.push(Vec::new());
            self.block_line = line;
        }
        let k = rows.transmittance.last().map_or(0, Vec::len);
        let first_block = rows.wavelengths_um.len() == 1;
        let within = format!(" within wavelength {} µm", number(w));
        if first_block {
            if let Some(&previous) = rows.ranges_m.last().filter(|&&p| r <= p) {
                return Err(at(line, not_increasing(r, previous, &within)));
            }
            rows.ranges_m.push(r);
        } else if rows.ranges_m.get(k) != Some(&r) {
            return Err(at(line, other_ranges(rows, k, r, &within)));
        }
        if let (Some(taus), Some(radiances)) = (
            rows.transmittance.last_mut(),
            rows.radiance_per_um.last_mut(),
        ) {
            taus.push(t);
            radiances.push(l);
        }
        Ok(())
    }

    fn finish(self, last_line: usize) -> Result<SpectralRows, Refusal> {
        let Some(rows) = self.rows else {
            return Err(too_few(0, last_line, ""));
        };
        if rows.ranges_m.len() < 2 {
            let what = format!(" at wavelength {} µm", number(rows.wavelengths_um[0]));
            return Err(too_few(rows.ranges_m.len(), last_line, &what));
        }
        close_block(&rows, self.block_line, last_line)?;
        Ok(rows)
    }
}

/// The refusal of a range `r` at place `k` of a later wavelength that differs from the first
/// wavelength's ranges.
fn other_ranges(rows: &SpectralRows, k: usize, r: f64, within: &str) -> String {
    let previous = rows
        .transmittance
        .last()
        .filter(|taus| !taus.is_empty())
        .map(|_| rows.ranges_m[k - 1]);
    match (previous, rows.ranges_m.get(k)) {
        (Some(p), _) if r <= p => not_increasing(r, p, within),
        (_, Some(&expected)) => format!(
            "column 'range_m': {} m where the first wavelength has {} m (its range number {}): \
             every wavelength needs the same ranges",
            number(r),
            number(expected),
            k + 1
        ),
        (_, None) => format!(
            "column 'range_m': {} m is one range more than the first wavelength's {}: every \
             wavelength needs the same ranges",
            number(r),
            rows.ranges_m.len()
        ),
    }
}

/// The current (last) wavelength must have had every range of the first; `line` is where the
/// next wavelength starts (or the last data line).
fn close_block(rows: &SpectralRows, block_line: usize, line: usize) -> Result<(), Refusal> {
    let count = rows.transmittance.last().map_or(0, Vec::len);
    if count < rows.ranges_m.len() {
        let w = rows.wavelengths_um.last().copied().unwrap_or_default();
        return Err(at(
            line,
            format!(
                "wavelength {} µm (from line {block_line}) has {count} range(s), the first \
                 wavelength {}: every wavelength needs the same ranges",
                number(w),
                rows.ranges_m.len()
            ),
        ));
    }
    Ok(())
}
