//! Reading a measurement CSV into a [`MeasurementSet`] (docs/design.md §2.1), refusing anything that is
//! not unambiguous with a `file:line:column` message. The reader never writes.
//!
//! Order of checks: UTF-8, then all `# key: value` metadata (wherever it stands), then the
//! header row (the first line that is neither blank nor `#`), then the data rows top to bottom,
//! fields left to right. The first problem found is reported.

use std::path::Path;

use sha2::{Digest, Sha256};

use super::columns::{parse_header_row, wrong_delimiter, Layout, Quantity};
use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::fields::{split_fields, Field};
use super::metadata::{split_metadata_line, wavelength_in_range, HeaderWavelength, Metadata};
use super::units::{check_degrees, converted_note, AngleReading};
use super::{MeasurementPoint, MeasurementSet, MAX_MUELLER_SR, MIN_UNCERTAINTY_SR};
use crate::pbrdf::{fold_signed_zenith, signed_zenith_note};
use crate::text::shown;

/// Default azimuths when the columns are absent: the plane of incidence, with the receiver on
/// the specular side (φ_r = φ_i + 180°, docs/design.md §1.1).
const DEFAULT_PHI_I_DEG: f64 = 0.0;
const DEFAULT_PHI_R_DEG: f64 = 180.0;

/// Two wavelengths are the same when they agree to 1 ppm: tighter than any monochromator, looser
/// than the digits a file writer may drop between a header and a column.
const WAVELENGTH_RELATIVE_TOLERANCE: f64 = 1e-6;

/// Reads and validates one measurement CSV. `path` is quoted as given in every message.
pub fn read_measurement_csv(path: &Path) -> Result<MeasurementSet, MeasureError> {
    let bytes = read_bytes(path)?;
    parse_measurement_csv(path, &bytes)
}

/// The bytes of a measurement file, refused with a message if it cannot be read.
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, MeasureError> {
    let whole_file = |kind| Refusal::new(1, 1, kind).in_file(path);
    match std::fs::metadata(path) {
        Ok(meta) if meta.is_dir() => return Err(whole_file(MeasureErrorKind::IsDirectory)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(whole_file(MeasureErrorKind::NotFound))
        }
        _ => {}
    }
    std::fs::read(path).map_err(|e| {
        whole_file(MeasureErrorKind::Unreadable {
            reason: e.to_string(),
        })
    })
}

/// Parses the bytes of a measurement CSV of one wavelength; `source` names it in messages and in
/// the result. [`read_measurement_csv`] is this plus reading the file. A file whose
/// wavelength_um column holds several wavelengths is refused at the first row of a second one
/// ([`parse_measurement_sets`] reads it).
pub fn parse_measurement_csv(source: &Path, bytes: &[u8]) -> Result<MeasurementSet, MeasureError> {
    let mut sets = parse_sets(source, bytes, false, AngleReading::Auto)?;
    Ok(sets.remove(0))
}

/// Reads one measurement CSV as one set per wavelength, ascending (a spectral file, docs/design.md
/// §1.9, holds several in its wavelength_um column; most files hold one).
pub fn read_measurement_sets(path: &Path) -> Result<Vec<MeasurementSet>, MeasureError> {
    let bytes = read_bytes(path)?;
    parse_sets(path, &bytes, true, AngleReading::Auto)
}

/// [`read_measurement_sets`] of bytes; `source` names them.
pub fn parse_measurement_sets(
    source: &Path,
    bytes: &[u8],
) -> Result<Vec<MeasurementSet>, MeasureError> {
    parse_sets(source, bytes, true, AngleReading::Auto)
}

/// [`parse_measurement_sets`] with the angles read as `angles` says (`--angles`): radians
/// declared as degrees are refused unless it says how to read them.
pub(crate) fn parse_sets_reading(
    source: &Path,
    bytes: &[u8],
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    parse_sets(source, bytes, true, angles)
}

fn parse_sets(
    source: &Path,
    bytes: &[u8],
    spectral: bool,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    let sha256 = hex(&Sha256::digest(bytes));
    let text = decode_utf8(bytes).map_err(|r| r.in_file(source))?;
    let radians = angles == AngleReading::Radians;
    let mut parsed = parse_text(text, radians).map_err(|r| r.in_file(source))?;
    let file = source.display().to_string();
    let angle_note = if radians {
        Some(converted_note(&file))
    } else {
        check_degrees(&file, &parsed.points, angles, PLAIN_FIX).map_err(|r| r.in_file(source))?
    };
    let groups = wavelength_groups(&mut parsed, spectral).map_err(|r| r.in_file(source))?;
    let material = match parsed.metadata.material {
        Some(material) => material,
        None => source
            .file_stem()
            .map(|stem| stem.to_string_lossy().into_owned())
            .unwrap_or_default(),
    };
    let notes: Vec<String> = angle_note
        .into_iter()
        .chain(signed_zenith_note(&file, parsed.signed_rows))
        .collect();
    Ok(groups
        .into_iter()
        .map(|(wavelength_um, points)| MeasurementSet {
            source: source.to_path_buf(),
            sha256: sha256.clone(),
            material: material.clone(),
            wavelength_um,
            metadata: parsed.metadata.entries.clone(),
            elements: parsed.layout.elements.clone(),
            points,
            merged: Vec::new(),
            // The file's notes go with every set (a set chosen by wavelength keeps them); the
            // fit says each note once.
            notes: notes.clone(),
        })
        .collect())
}

/// The rows of a parsed file by wavelength, ascending: all of them at the file's wavelength, or,
/// for a wavelength_um column without a header, one group per distinct wavelength (equal within
/// [`WAVELENGTH_RELATIVE_TOLERANCE`], the group keeping its first row's value). Unless `spectral`,
/// a second wavelength is refused at its first row.
fn wavelength_groups(
    parsed: &mut ParsedText,
    spectral: bool,
) -> Result<Vec<(f64, Vec<MeasurementPoint>)>, Refusal> {
    let points = std::mem::take(&mut parsed.points);
    let Some(rows) = parsed.row_wavelengths.take() else {
        return Ok(vec![(parsed.wavelength_um, points)]);
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

pub(crate) fn same_wavelength(a: f64, b: f64) -> bool {
    (a - b).abs() <= WAVELENGTH_RELATIVE_TOLERANCE * a.max(b)
}

pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// The text of the file without a leading byte-order mark (spreadsheets write one).
pub(crate) fn decode_utf8(bytes: &[u8]) -> Result<&str, Refusal> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        // The valid prefix is UTF-8 by construction, so the lossy decode is exact.
        let before = String::from_utf8_lossy(&bytes[..e.valid_up_to()]);
        let (last_line, line_number) = text_lines(without_bom(&before))
            .zip(1..)
            .last()
            .unwrap_or(("", 1));
        let byte = bytes[e.valid_up_to()];
        Refusal::new(
            line_number,
            last_column(last_line),
            MeasureErrorKind::InvalidUtf8 { byte },
        )
    })?;
    Ok(without_bom(text))
}

fn without_bom(text: &str) -> &str {
    text.strip_prefix('\u{feff}').unwrap_or(text)
}

/// The column just after the end of `line`.
pub(crate) fn last_column(line: &str) -> u64 {
    line.chars().count() as u64 + 1
}

/// The lines of a text without their terminators: "\r\n", "\n", or a bare "\r" (old Mac
/// spreadsheet exports) each end a line.
fn text_lines(text: &str) -> impl Iterator<Item = &str> {
    text.split('\n')
        .flat_map(|line| line.strip_suffix('\r').unwrap_or(line).split('\r'))
}

struct ParsedText {
    metadata: Metadata,
    layout: Layout,
    /// The file's wavelength (the header's, else the first row's).
    wavelength_um: f64,
    points: Vec<MeasurementPoint>,
    /// Each row's wavelength and the column it is in, for a wavelength_um column without a
    /// header (which may hold several wavelengths).
    row_wavelengths: Option<Vec<(HeaderWavelength, u64)>>,
    /// Rows whose θ_r was negative.
    signed_rows: usize,
}

/// A line of the file, numbered from 1, without its terminator.
type NumberedLine<'a> = (u64, &'a str);

/// The file's non-blank lines, numbered from 1; a file without one is refused as empty.
pub(crate) fn numbered_lines(text: &str) -> Result<Vec<NumberedLine<'_>>, Refusal> {
    let lines: Vec<NumberedLine<'_>> = text_lines(text)
        .zip(1..)
        .map(|(line, number)| (number, line))
        .filter(|(_, line)| !line.trim().is_empty())
        .collect();
    if lines.is_empty() {
        return Err(Refusal::new(1, 1, MeasureErrorKind::EmptyFile));
    }
    Ok(lines)
}

/// How to fix a §2.1 file whose angles look like radians.
const PLAIN_FIX: &str = "convert them to degrees, or pass --angles radians to convert them as \
     the file is read (--angles degrees if they are degrees)";

fn parse_text(text: &str, radians: bool) -> Result<ParsedText, Refusal> {
    let lines = numbered_lines(text)?;
    let is_hash_line = |line: &str| line.trim_start().starts_with('#');

    let mut metadata = Metadata::default();
    for &(number, line) in lines.iter().filter(|(_, line)| is_hash_line(line)) {
        if let Some((key, value, column)) = split_metadata_line(line) {
            metadata.add(number, key, value, column)?;
        }
    }

    let mut content = lines.iter().filter(|(_, line)| !is_hash_line(line));
    let &(header_line, header) = content
        .next()
        .ok_or_else(|| Refusal::new(1, 1, MeasureErrorKind::NoHeader))?;
    let header_fields = fields_of(header_line, header)?;
    let layout = parse_header_row(header_line, &header_fields)?;

    let wavelength = match (&metadata.wavelength, layout.has(Quantity::Wavelength)) {
        (Some(header), _) => WavelengthCheck::AgainstHeader(header.clone()),
        (None, true) => WavelengthCheck::PerRow,
        (None, false) => return Err(Refusal::new(header_line, 1, MeasureErrorKind::NoWavelength)),
    };
    let mut row_wavelengths = Vec::new();
    let mut points = content
        .map(|&(number, line)| parse_row(number, line, &layout, &wavelength, radians))
        .map(|row| {
            let (point, row_wavelength) = row?;
            row_wavelengths.extend(row_wavelength);
            Ok(point)
        })
        .collect::<Result<Vec<_>, Refusal>>()?;
    let signed_rows = fold_signed_detector_angles(&mut points);
    if points.is_empty() {
        return Err(Refusal::new(header_line, 1, MeasureErrorKind::NoDataRows));
    }
    // A file of zeros has no lobe: every model with ρ_d = 0 and σ anywhere fits it perfectly, so
    // a "fit" would report arbitrary parameters with χ² = 0.
    if points.iter().all(|p| p.values[0] == 0.0) {
        let m00_column = header_fields
            .iter()
            .zip(&layout.quantities)
            .find(|(_, q)| **q == Quantity::Element(0))
            .map_or(1, |(field, _)| field.column);
        return Err(Refusal::new(
            header_line,
            m00_column,
            MeasureErrorKind::AllM00Zero,
        ));
    }
    let (wavelength_um, row_wavelengths) = match wavelength {
        WavelengthCheck::AgainstHeader(header) => (header.um, None),
        // With a wavelength column and at least one row, the first row has one.
        WavelengthCheck::PerRow => (
            row_wavelengths
                .first()
                .map(|(w, _): &(HeaderWavelength, u64)| w.um)
                .ok_or_else(|| Refusal::new(header_line, 1, MeasureErrorKind::NoDataRows))?,
            Some(row_wavelengths),
        ),
    };
    Ok(ParsedText {
        metadata,
        layout,
        wavelength_um,
        points,
        row_wavelengths,
        signed_rows,
    })
}

/// Reads each row's θ_r < 0 as the detector across the normal, (|θ_r|, φ_r + 180°), once all
/// of the row's columns are known; returns how many rows were so read.
fn fold_signed_detector_angles(points: &mut [MeasurementPoint]) -> usize {
    let mut folded = 0;
    for point in points.iter_mut().filter(|p| p.theta_r_deg < 0.0) {
        (point.theta_r_deg, point.phi_r_deg) =
            fold_signed_zenith(point.theta_r_deg, point.phi_r_deg);
        folded += 1;
    }
    folded
}

fn fields_of(line_number: u64, line: &str) -> Result<Vec<Field<'_>>, Refusal> {
    split_fields(line).map_err(|(column, kind)| Refusal::new(line_number, column, kind))
}

/// How each row's wavelength_um is read: with a `# wavelength_um:` header every row must agree
/// with it (docs/design.md §2.1); without one each row carries its own (a spectral file may hold
/// several, docs/design.md §1.9).
enum WavelengthCheck {
    AgainstHeader(HeaderWavelength),
    PerRow,
}

impl WavelengthCheck {
    /// The row's own wavelength, for [`WavelengthCheck::PerRow`].
    fn check(
        &self,
        line: u64,
        column: u64,
        um: f64,
        text: &str,
    ) -> Result<Option<(HeaderWavelength, u64)>, Refusal> {
        match self {
            Self::AgainstHeader(header) if !same_wavelength(header.um, um) => Err(Refusal::new(
                line,
                column,
                MeasureErrorKind::WavelengthDisagrees {
                    value: shown(text),
                    header: shown(&header.text),
                    header_line: header.line,
                },
            )),
            Self::AgainstHeader(_) => Ok(None),
            Self::PerRow => Ok(Some((
                HeaderWavelength {
                    um,
                    text: text.to_string(),
                    line,
                },
                column,
            ))),
        }
    }
}

fn parse_row(
    line_number: u64,
    line: &str,
    layout: &Layout,
    wavelength: &WavelengthCheck,
    radians: bool,
) -> Result<(MeasurementPoint, Option<(HeaderWavelength, u64)>), Refusal> {
    let fields = fields_of(line_number, line)?;
    check_row_fields(line_number, line, &fields, layout.quantities.len())?;
    let mut point = MeasurementPoint {
        theta_i_deg: f64::NAN,
        phi_i_deg: DEFAULT_PHI_I_DEG,
        theta_r_deg: f64::NAN,
        phi_r_deg: DEFAULT_PHI_R_DEG,
        values: vec![f64::NAN; layout.elements.len()],
        uncertainties: vec![None; layout.elements.len()],
        line: line_number,
    };
    let mut row_wavelength = None;
    for ((field, &quantity), name) in fields.iter().zip(&layout.quantities).zip(&layout.names) {
        let refuse = |kind| Refusal::new(line_number, field.column, kind);
        let text = field.text.as_ref();
        let mut value = parse_number(name, text).map_err(refuse)?;
        let is_angle = matches!(
            quantity,
            Quantity::ThetaI | Quantity::ThetaR | Quantity::PhiI | Quantity::PhiR
        );
        let text = if radians && is_angle {
            value = value.to_degrees();
            format!("{text} rad")
        } else {
            text.to_owned()
        };
        let text = text.as_str();
        if quantity == Quantity::Wavelength {
            if let Some(kind) = wavelength_refusal(value, text) {
                return Err(refuse(kind));
            }
            row_wavelength = wavelength.check(line_number, field.column, value, text)?;
        } else {
            store_value(&mut point, layout, quantity, name, value, text).map_err(refuse)?;
        }
    }
    Ok((point, row_wavelength))
}

/// Refuses a row with a field separated by another delimiter than ',', or with another number
/// of fields than the header's `expected`.
fn check_row_fields(
    line_number: u64,
    line: &str,
    fields: &[Field<'_>],
    expected: usize,
) -> Result<(), Refusal> {
    if let Some(refusal) = fields
        .iter()
        .filter(|f| !f.quoted)
        .find_map(|f| wrong_delimiter(line_number, f))
    {
        return Err(refusal);
    }
    if fields.len() != expected {
        // Point at the first extra field, or at the end of a short row.
        let column = match fields.get(expected) {
            Some(extra) => extra.column,
            None => last_column(line),
        };
        return Err(Refusal::new(
            line_number,
            column,
            MeasureErrorKind::FieldCount {
                found: fields.len(),
                expected,
            },
        ));
    }
    Ok(())
}

/// Stores `value` (written `text`) of column `name`, holding `quantity` (not the wavelength),
/// in `point`, or says why it is refused.
fn store_value(
    point: &mut MeasurementPoint,
    layout: &Layout,
    quantity: Quantity,
    name: &str,
    value: f64,
    text: &str,
) -> Result<(), MeasureErrorKind> {
    match quantity {
        // Zenith angles of directions above the surface; 90° is grazing and leaves the
        // BRDF's 1/cosθ undefined (docs/design.md §1.3). The detector's may be signed (in-plane
        // scans are written −80…80°); parse_text folds the negative ones.
        Quantity::ThetaI => {
            if !(0.0..90.0).contains(&value) {
                return Err(MeasureErrorKind::ThetaOutOfRange {
                    column: name.to_owned(),
                    value: shown(text),
                });
            }
            point.theta_i_deg = value;
        }
        Quantity::ThetaR => {
            if !(value > -90.0 && value < 90.0) {
                return Err(MeasureErrorKind::DetectorThetaOutOfRange { value: shown(text) });
            }
            point.theta_r_deg = value;
        }
        Quantity::PhiI => point.phi_i_deg = value,
        Quantity::PhiR => point.phi_r_deg = value,
        // Checked against the header's or kept as the row's own by parse_row.
        Quantity::Wavelength => {}
        Quantity::Element(index) => {
            if index == 0 && value < 0.0 {
                return Err(MeasureErrorKind::NegativeM00 { value: shown(text) });
            }
            if let Some(kind) = element_value_refusal(name, value, text) {
                return Err(kind);
            }
            if let Some(slot) = layout.slot(index) {
                point.values[slot] = value;
            }
        }
        Quantity::Uncertainty(index) => {
            if value <= 0.0 {
                return Err(MeasureErrorKind::NonPositiveUncertainty {
                    column: name.to_owned(),
                    value: shown(text),
                });
            }
            if !(MIN_UNCERTAINTY_SR..=MAX_MUELLER_SR).contains(&value) {
                return Err(MeasureErrorKind::UncertaintyOutOfRange {
                    column: name.to_owned(),
                    value: shown(text),
                });
            }
            if let Some(slot) = layout.slot(index) {
                point.uncertainties[slot] = Some(value);
            }
        }
    }
    Ok(())
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

/// A finite number, or why the field is not one.
pub(crate) fn parse_number(column: &str, text: &str) -> Result<f64, MeasureErrorKind> {
    if text.is_empty() {
        return Err(MeasureErrorKind::EmptyField {
            column: column.to_string(),
        });
    }
    match text.parse::<f64>() {
        Ok(value) if value.is_finite() => Ok(value),
        // Rust parses "NaN", "inf" and overflowing literals such as 1e999 as non-finite.
        Ok(_) => Err(MeasureErrorKind::NotFinite {
            column: column.to_string(),
            value: shown(text),
        }),
        Err(_) => Err(MeasureErrorKind::NotANumber {
            column: column.to_string(),
            value: shown(text),
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<MeasurementSet, MeasureError> {
        parse_measurement_csv(Path::new("mem/sample.csv"), text.as_bytes())
    }

    fn message(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn defaults_apply_and_material_falls_back_to_the_stem() {
        let set =
            parse("# wavelength_um: 10.6\ntheta_i_deg,theta_r_deg,m00\n30,40,0.05\n").unwrap();
        assert_eq!(set.material, "sample");
        assert_eq!(set.wavelength_um, 10.6);
        assert_eq!(set.elements, vec![0]);
        let p = &set.points[0];
        assert_eq!(
            (p.theta_i_deg, p.phi_i_deg, p.theta_r_deg, p.phi_r_deg),
            (30.0, 0.0, 40.0, 180.0)
        );
        assert_eq!(
            (p.values.clone(), p.uncertainties.clone(), p.line),
            (vec![0.05], vec![None], 3)
        );
    }

    #[test]
    fn values_follow_the_sorted_elements_whatever_the_column_order() {
        let set = parse(
            "m22,u_m00,m00,theta_r_deg,theta_i_deg,wavelength_um\n-0.04,0.001,0.05,30,30,9.925\n",
        )
        .unwrap();
        assert_eq!(set.elements, vec![0, 10]);
        assert_eq!(set.points[0].values, vec![0.05, -0.04]);
        assert_eq!(set.points[0].uncertainties, vec![Some(0.001), None]);
        assert_eq!(set.wavelength_um, 9.925);
    }

    #[test]
    fn sha256_is_of_the_raw_bytes() {
        // SHA-256 of the 53 bytes below, computed independently with coreutils `sha256sum`.
        let text = "# wavelength_um: 1\ntheta_i_deg,theta_r_deg,m00\n0,0,1\n";
        let set = parse(text).unwrap();
        assert_eq!(
            set.sha256,
            "83cd091616bdf72952f4e76fc25a5c8ec17daa0dcccce9de5326952ac9ff886b"
        );
        let other = parse(&text.replace("0,0,1", "0,0,2")).unwrap();
        assert_ne!(set.sha256, other.sha256);
    }

    #[test]
    fn wavelengths_agree_within_one_ppm() {
        let header = "# wavelength_um: 9.925\ntheta_i_deg,theta_r_deg,m00,wavelength_um\n";
        assert!(parse(&format!("{header}0,0,1,9.92500001\n")).is_ok());
        assert_eq!(
            message(&format!("{header}0,0,1,9.926\n")),
            "mem/sample.csv:3:7: column 'wavelength_um': 9.926 disagrees with the header \
             '# wavelength_um: 9.925' (line 1)"
        );
        let no_header = "theta_i_deg,theta_r_deg,m00,wavelength_um\n0,0,1,10\n1,1,1,10.6\n";
        assert_eq!(
            message(no_header),
            "mem/sample.csv:3:7: column 'wavelength_um': 10.6 differs from 10 on line 2: the \
             file holds several wavelengths, a spectral set, which `irpol fit` reads as one \
             material but this reader of one wavelength cannot"
        );
        // The spectral reader splits the file by wavelength, ascending, rows in file order.
        let text = "theta_i_deg,theta_r_deg,m00,wavelength_um\n0,0,1,10.6\n1,1,1,10\n\
                    2,2,1,10.600001\n";
        let sets = parse_measurement_sets(Path::new("s.csv"), text.as_bytes()).unwrap();
        let split: Vec<(f64, Vec<u64>)> = sets
            .iter()
            .map(|s| (s.wavelength_um, s.points.iter().map(|p| p.line).collect()))
            .collect();
        assert_eq!(split, [(10.0, vec![3]), (10.6, vec![2, 4])]);
    }

    #[test]
    fn utf8_errors_point_at_the_byte() {
        let bytes = b"# a: b\nthe\xffta_i_deg";
        let err = parse_measurement_csv(Path::new("x.csv"), bytes).unwrap_err();
        assert_eq!(
            err.to_string(),
            "x.csv:2:4: invalid UTF-8 (byte 0xFF): a measurement CSV must be UTF-8 text"
        );
    }

    #[test]
    fn bare_carriage_returns_end_lines() {
        let set = parse("# wavelength_um: 8\rtheta_i_deg,theta_r_deg,m00\r10,20,0.5\r\r11,21,0.4")
            .unwrap();
        assert_eq!(set.points[1].line, 5);
        assert_eq!(
            message("# wavelength_um: 8\r\ntheta_i_deg,theta_r_deg,m00\r10,20,-0.5"),
            "mem/sample.csv:3:7: column 'm00': -0.5 is negative, but m00 (the unpolarized BRDF, sr⁻¹) is ≥ 0"
        );
        let err = parse_measurement_csv(Path::new("x.csv"), b"\xef\xbb\xbfab\rc\xc3").unwrap_err();
        assert_eq!((err.line, err.column), (2, 2));
    }

    #[test]
    fn bom_crlf_and_quoted_names_are_accepted() {
        let text = "\u{feff}\"theta_i_deg\",\"theta_r_deg\",\"m00\"\r\n# wavelength_um: 8\r\n10,20,0.5\r\n";
        let set = parse(text).unwrap();
        assert_eq!(set.points[0].values, vec![0.5]);
        assert_eq!(set.wavelength_um, 8.0);
    }

    /// In-plane scans are written −80…80°; θ_r < 0 is the detector across the
    /// normal, whatever the column order, with one note for the file.
    #[test]
    fn signed_detector_angles_are_read_across_the_normal() {
        let set = parse(
            "# wavelength_um: 10\nphi_r_deg,theta_r_deg,theta_i_deg,m00\n\
             180,-30,40,0.1\n90,-80,40,0.1\n180,30,40,0.1\n",
        )
        .unwrap();
        let angles: Vec<(f64, f64)> = set
            .points
            .iter()
            .map(|p| (p.theta_r_deg, p.phi_r_deg))
            .collect();
        assert_eq!(angles, [(30.0, 0.0), (80.0, 270.0), (30.0, 180.0)]);
        assert_eq!(
            set.notes,
            ["mem/sample.csv: 2 rows with θ_r < 0 read as (|θ_r|, φ_r + 180°)"]
        );
        assert!(
            parse("# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n40,30,0.1\n")
                .unwrap()
                .notes
                .is_empty()
        );
        assert_eq!(
            message("# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n40,-95,0.1\n"),
            "mem/sample.csv:3:4: column 'theta_r_deg': -95 is outside (−90°, 90°) (detector \
             zenith angles; a negative one is read as (|θ_r|, φ_r + 180°))"
        );
        assert!(
            message("# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n-1,30,0.1\n")
                .contains("column 'theta_i_deg': -1 is outside [0°, 90°)")
        );
    }

    #[test]
    fn numbers_are_finite_decimal_literals() {
        assert_eq!(parse_number("m00", "1e-3"), Ok(1e-3));
        assert_eq!(parse_number("m00", "+.5"), Ok(0.5));
        for bad in ["NaN", "inf", "-infinity", "1e999"] {
            assert!(matches!(
                parse_number("m00", bad),
                Err(MeasureErrorKind::NotFinite { .. })
            ));
        }
        for bad in ["0x10", "1,5", "1.2.3", "one", "1_000"] {
            assert!(matches!(
                parse_number("m00", bad),
                Err(MeasureErrorKind::NotANumber { .. })
            ));
        }
    }

    #[test]
    fn wavelengths_beyond_the_modelled_range_and_files_of_zeros_are_refused() {
        let message = |text: &str| parse(text).unwrap_err().to_string();
        assert_eq!(
            message("# wavelength_um: 1e-300\ntheta_i_deg,theta_r_deg,m00\n30,30,0.1\n"),
            "mem/sample.csv:1:18: header 'wavelength_um': 1e-300 µm is outside 0.1–1000 µm, \
             the wavelengths irpol models"
        );
        assert_eq!(
            message("theta_i_deg,theta_r_deg,m00,wavelength_um\n30,30,0.1,2e6\n"),
            "mem/sample.csv:2:11: column 'wavelength_um': 2e6 µm is outside 0.1–1000 µm, \
             the wavelengths irpol models"
        );
        assert_eq!(
            message("# wavelength_um: 10\ntheta_i_deg,theta_r_deg, m00\n30,30,0\n40,40,0.0\n"),
            "mem/sample.csv:2:26: column 'm00' is 0 on every row: there is no reflection to fit"
        );
        assert!(
            parse("# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n30,30,0\n40,40,1e-9\n")
                .is_ok()
        );
    }
}
