//! The atmosphere table of docs/design.md §2.9: a CSV of a radiative-transfer code's path
//! transmittance and path radiance over range, refused with `file:line: what is wrong and what to
//! do` (a whole-file problem without the line).
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
    /// A problem at a line of the file (1-based).
    #[error("{}:{line}: {message}", crate::text::path(file))]
    Line {
        file: PathBuf,
        line: usize,
        message: String,
    },
    /// A problem of the whole file (too few rows, the band not covered).
    #[error("{}: {message}", crate::text::path(file))]
    Table { file: PathBuf, message: String },
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
            .map_err(|e| AtmosphereTableError::Table {
                file: self.file.clone(),
                message: format!(
                    "the wavelengths cover {}–{} µm, not the whole sensor band {}–{} µm: add rows \
                     over the band (or narrow sensor.band_um)",
                    number(e.table_um.0),
                    number(e.table_um.1),
                    number(e.band_um.0),
                    number(e.band_um.1)
                ),
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
    let bytes = bytes.strip_prefix(b"\xef\xbb\xbf").unwrap_or(bytes);
    let refuse = |(line, message): Refusal| match line {
        Some(line) => AtmosphereTableError::Line {
            file: path.to_owned(),
            line,
            message,
        },
        None => AtmosphereTableError::Table {
            file: path.to_owned(),
            message,
        },
    };
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&b| b == b'\n')
            .count()
            + 1;
        refuse((
            Some(line),
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

/// A refusal at a line (or of the whole file), before the path is attached.
type Refusal = (Option<usize>, String);

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

/// Where each column is in a row.
struct Layout {
    /// Field index of each [`Column`] (by `Column as usize`), if present.
    index: [Option<usize>; 5],
    width: usize,
    spectral: bool,
}

/// Notes and rows of the text of a table.
fn parse_text(text: &str) -> Result<(Notes, TableRows), Refusal> {
    let mut notes = Notes::default();
    let mut layout: Option<Layout> = None;
    let mut band = BandBuilder::default();
    let mut spectral = SpectralBuilder::default();
    let mut last_line = 0;
    for (i, raw) in text.lines().enumerate() {
        let (line, trimmed) = (i + 1, raw.trim());
        if trimmed.is_empty() {
            continue;
        }
        if let Some(comment) = trimmed.strip_prefix('#') {
            notes.take(comment);
            continue;
        }
        let Some(layout) = &layout else {
            layout = Some(parse_header(trimmed, line)?);
            continue;
        };
        let [w, r, t, l] = parse_row(trimmed, line, layout)?;
        if layout.spectral {
            spectral.push(line, w, r, t, l)?;
        } else {
            band.push(line, r, t, l)?;
        }
        last_line = line;
    }
    let layout = layout.ok_or((
        Some(1),
        "no header row: the file is empty or only comments; the first other line names the \
         columns ("
            .to_owned()
            + KINDS
            + ")",
    ))?;
    let rows = if layout.spectral {
        TableRows::Spectral(spectral.finish(last_line)?)
    } else {
        TableRows::Band(band.finish(last_line)?)
    };
    Ok((notes, rows))
}

/// The header row: known names, no duplicates, exactly the columns of one kind.
fn parse_header(text: &str, line: usize) -> Result<Layout, Refusal> {
    let refuse = |message: String| Err((Some(line), message));
    let mut index = [None; 5];
    let names: Vec<&str> = text.split(',').map(str::trim).collect();
    for (i, name) in names.iter().enumerate() {
        let Some(&(column, _)) = COLUMNS.iter().find(|(_, known)| known == name) else {
            return refuse(unknown_column(name));
        };
        if index[column as usize].replace(i).is_some() {
            return refuse(format!("column '{name}' appears twice: keep one"));
        }
    }
    let has = |column: Column| index[column as usize].is_some();
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
    if let Some(missing) = required.iter().find(|&&c| !has(c)) {
        return refuse(format!("missing column '{}' ({KINDS})", missing.name()));
    }
    Ok(Layout {
        index,
        width: names.len(),
        spectral,
    })
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
fn parse_row(text: &str, line: usize, layout: &Layout) -> Result<[f64; 4], Refusal> {
    let fields: Vec<&str> = text.split(',').map(str::trim).collect();
    if fields.len() != layout.width {
        return Err((
            Some(line),
            format!(
                "the row has {} fields, the header row has {}",
                fields.len(),
                layout.width
            ),
        ));
    }
    let radiance = if layout.spectral {
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
        let Some(i) = layout.index[column as usize] else {
            continue;
        };
        let value = parse_number(fields[i])
            .map_err(|why| (Some(line), format!("column '{}': {why}", column.name())))?;
        if let Some(why) = column.problem(value) {
            return Err((Some(line), format!("column '{}': {why}", column.name())));
        }
        values[slot] = value;
    }
    Ok(values)
}

/// Why a field is not a finite number.
struct NotANumber(String);

impl std::fmt::Display for NotANumber {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// A field as a finite number, or why not.
fn parse_number(text: &str) -> Result<f64, NotANumber> {
    if text.is_empty() {
        return Err(NotANumber("empty, expected a number".into()));
    }
    match text.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(NotANumber(format!(
            "'{}' is not a finite number",
            shown(text)
        ))),
        Err(_) => Err(NotANumber(format!("'{}' is not a number", shown(text)))),
    }
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
    (
        (line > 0).then_some(line),
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
            return Err((Some(line), not_increasing(r, previous, "")));
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
                    return Err((
                        Some(line),
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
                return Err((Some(line), not_increasing(r, previous, &within)));
            }
            rows.ranges_m.push(r);
        } else if rows.ranges_m.get(k) != Some(&r) {
            return Err((Some(line), other_ranges(rows, k, r, &within)));
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
        return Err((
            Some(line),
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
