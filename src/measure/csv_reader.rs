//! Reading a measurement CSV into a [`MeasurementSet`] (docs/design.md §2.1), refusing anything that is
//! not unambiguous with a `file:line:column` message. The reader never writes.
//!
//! Order of checks: UTF-8, then all `# key: value` metadata (wherever it stands), then the
//! header row (the first line that is neither blank nor `#`), then the data rows top to bottom,
//! fields left to right. The first problem found is reported.

use std::borrow::Cow;
use std::io::BufRead;
use std::path::Path;

use super::columns::{HeaderRow, NativeColumns, Quantity};
use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::metadata::{HeaderWavelength, Metadata};
use super::streaming::{
    line_text, next_line, open_table, same_file, scan_file, scan_table, stream_lines,
    StreamedLines, TableScan,
};
use super::table_file::{
    check_width, element_value_refusal, fields_of, material_of, parse_number, row_wavelength,
    wavelength_refusal, FileFacts, WavelengthGroups,
};
use super::units::{check_degrees, converted_note, AngleReading};
use super::{MeasurementSet, MAX_MUELLER_SR, MIN_UNCERTAINTY_SR};
use crate::pbrdf::{fold_signed_zenith, signed_zenith_note};
use crate::table_text::{is_comment, wrong_delimiter};
use crate::text::shown;

/// Default azimuths when the columns are absent: the plane of incidence, with the receiver on
/// the specular side (φ_r = φ_i + 180°, docs/design.md §1.1).
const DEFAULT_PHI_I_DEG: f64 = 0.0;
const DEFAULT_PHI_R_DEG: f64 = 180.0;

/// Reads and validates one measurement CSV. `path` is quoted as given in every message.
pub fn read_measurement_csv(path: &Path) -> Result<MeasurementSet, MeasureError> {
    let scan = scan_file(path)?;
    let mut sets = sets_of(path, scan, open_table(path)?, false, AngleReading::Auto)?;
    Ok(sets.remove(0))
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
    read_scanned_sets(path, scan_file(path)?, AngleReading::Auto)
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

/// [`read_measurement_sets`] of the file at `path` whose first pass is `scan`, with the angles
/// read as `angles` says; the file is reopened for the second pass.
pub(crate) fn read_scanned_sets(
    path: &Path,
    scan: TableScan,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    sets_of(path, scan, open_table(path)?, true, angles)
}

fn parse_sets(
    source: &Path,
    bytes: &[u8],
    spectral: bool,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    let scan = scan_table(bytes).map_err(|r| r.in_file(source))?;
    sets_of(source, scan, bytes, spectral, angles)
}

/// The sets of a table read a second time from `reader`, after its first pass `scan`.
fn sets_of(
    source: &Path,
    mut scan: TableScan,
    reader: impl BufRead,
    spectral: bool,
    angles: AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    let metadata = scan.metadata().map_err(|r| r.in_file(source))?;
    let radians = angles == AngleReading::Radians;
    let mut lines = stream_lines(reader);
    let parsed = parse_text(&mut lines, metadata, scan.rows, radians, spectral);
    let parsed = same_file(lines, &scan.fingerprint, parsed).map_err(|r| r.in_file(source))?;
    let file = source.display().to_string();
    let angle_note = if radians {
        Some(converted_note(&file))
    } else {
        check_degrees(&file, parsed.groups.rows(), angles, PLAIN_FIX)
            .map_err(|r| r.in_file(source))?
    };
    let groups = parsed.groups.finish().map_err(|r| r.in_file(source))?;
    let facts = FileFacts {
        sha256: scan.sha256(),
        material: material_of(parsed.metadata.material.as_ref(), source),
        metadata: parsed.metadata.entries,
        elements: parsed.columns.elements,
    };
    let notes: Vec<String> = angle_note
        .into_iter()
        .chain(signed_zenith_note(&file, parsed.signed_rows))
        .collect();
    // The file's notes go with every set (a set chosen by wavelength keeps them); the fit says
    // each note once.
    Ok(groups
        .into_iter()
        .map(|(wavelength_um, points)| facts.set(source, wavelength_um, points, notes.clone()))
        .collect())
}

struct ParsedText {
    metadata: Metadata,
    columns: NativeColumns,
    /// The rows by wavelength: the file's (the header's), or each row's for a wavelength_um
    /// column without a header (which may hold several wavelengths).
    groups: WavelengthGroups,
    /// Rows whose θ_r was negative.
    signed_rows: usize,
}

/// How to fix a §2.1 file whose angles look like radians.
const PLAIN_FIX: &str = "convert them to degrees, or pass --angles radians to convert them as \
     the file is read (--angles degrees if they are degrees)";

/// The header row and the `rows` data rows (as the first pass counted them) of `lines`, read
/// top to bottom with `metadata` (all of the file's, checked by the first pass), each row pushed
/// into its wavelength's columns.
fn parse_text<R: BufRead>(
    lines: &mut StreamedLines<R>,
    metadata: Metadata,
    rows: usize,
    radians: bool,
    spectral: bool,
) -> Result<ParsedText, Refusal> {
    let mut table: Option<(HeaderRow, WavelengthGroups, RowValues)> = None;
    let mut signed_rows = 0;
    while next_line(lines)? {
        let number = lines.number();
        let line = line_text(lines)?;
        if line.trim().is_empty() || is_comment(line) {
            continue;
        }
        let Some((header, groups, row)) = &mut table else {
            let header = HeaderRow::parse(number, line, metadata.wavelength.is_some())?;
            let columns = &header.columns;
            let has_uncertainty = (columns.elements.iter())
                .map(|&e| columns.has(Quantity::Uncertainty(e)))
                .collect();
            let header_wavelength = metadata.wavelength.as_ref();
            let groups = WavelengthGroups::new(header_wavelength, spectral, has_uncertainty, rows);
            // One row's values, reused for every row: each is copied into its group's columns.
            let row = RowValues::new(columns.elements.len());
            table = Some((header, groups, row));
            continue;
        };
        let read = parse_row(number, line, &header.columns, &metadata, radians, row)?;
        signed_rows += usize::from(read.signed);
        let (values, uncertainties) = (&row.values, &row.uncertainties);
        groups.push(read.wavelength, read.angles, values, uncertainties, number);
    }
    // The first pass found a header row: only a file changed since lacks one, and is refused
    // as such.
    let (header, groups, _) =
        table.ok_or_else(|| Refusal::new(1, 1, MeasureErrorKind::NoHeader))?;
    if groups.len() == 0 {
        return Err(Refusal::new(header.line, 1, MeasureErrorKind::NoDataRows));
    }
    // A file of zeros has no lobe: every model with ρ_d = 0 and σ anywhere fits it perfectly, so
    // a "fit" would report arbitrary parameters with χ² = 0.
    if groups.rows().all(|p| p.values[0] == 0.0) {
        return Err(Refusal::new(
            header.line,
            header.m00_column,
            MeasureErrorKind::AllM00Zero,
        ));
    }
    Ok(ParsedText {
        metadata,
        columns: header.columns,
        groups,
        signed_rows,
    })
}

/// One data row read, besides its values (in [`RowValues`]): its angles (θ_r < 0 read as the
/// detector across the normal, (|θ_r|, φ_r + 180°), once all of the row's columns are known),
/// its own wavelength if the file has no header one, and whether θ_r was negative.
struct Row {
    angles: [f64; 4],
    wavelength: Option<(HeaderWavelength, u64)>,
    signed: bool,
}

/// A row's values as read, aligned with the file's elements; one buffer serves every row.
struct RowValues {
    angles: [f64; 4],
    values: Vec<f64>,
    uncertainties: Vec<Option<f64>>,
}

impl RowValues {
    fn new(elements: usize) -> RowValues {
        RowValues {
            angles: [f64::NAN; 4],
            values: vec![f64::NAN; elements],
            uncertainties: vec![None; elements],
        }
    }

    /// Back to a row with nothing read: the azimuths at their defaults.
    fn clear(&mut self) {
        self.angles = [f64::NAN, DEFAULT_PHI_I_DEG, f64::NAN, DEFAULT_PHI_R_DEG];
        self.values.fill(f64::NAN);
        self.uncertainties.fill(None);
    }
}

/// Reads the row `line` (line `line_number`) into `row`.
fn parse_row(
    line_number: u64,
    line: &str,
    columns: &NativeColumns,
    metadata: &Metadata,
    radians: bool,
    row: &mut RowValues,
) -> Result<Row, Refusal> {
    let fields = fields_of(line_number, line)?;
    if let Some(refusal) = wrong_delimiter(line_number, &fields) {
        return Err(refusal.map(MeasureErrorKind::Token));
    }
    check_width(line_number, line, &fields, columns.quantities.len())?;
    row.clear();
    let mut wavelength = None;
    for ((field, &quantity), name) in fields.iter().zip(&columns.quantities).zip(&columns.names) {
        let refuse = |kind| Refusal::new(line_number, field.column, kind);
        let text = field.text.as_ref();
        let mut value = parse_number(name, text).map_err(refuse)?;
        let is_angle = matches!(
            quantity,
            Quantity::ThetaI | Quantity::ThetaR | Quantity::PhiI | Quantity::PhiR
        );
        // Quoted as read, with the unit the flag gave it.
        let text = if radians && is_angle {
            value = value.to_degrees();
            Cow::Owned(format!("{text} rad"))
        } else {
            Cow::Borrowed(text)
        };
        let text = text.as_ref();
        if quantity == Quantity::Wavelength {
            if let Some(kind) = wavelength_refusal(value, text) {
                return Err(refuse(kind));
            }
            let header = metadata.wavelength.as_ref();
            wavelength = row_wavelength(header, line_number, field.column, value, text)?;
        } else {
            store_value(row, columns, quantity, name, value, text).map_err(refuse)?;
        }
    }
    let [theta_i, phi_i, theta_r, phi_r] = row.angles;
    let signed = theta_r < 0.0;
    let (theta_r, phi_r) = match signed {
        true => fold_signed_zenith(theta_r, phi_r),
        false => (theta_r, phi_r),
    };
    Ok(Row {
        angles: [theta_i, phi_i, theta_r, phi_r],
        wavelength,
        signed,
    })
}

/// Stores `value` (written `text`) of column `name`, holding `quantity` (not the wavelength),
/// in `point`, or says why it is refused.
fn store_value(
    row: &mut RowValues,
    columns: &NativeColumns,
    quantity: Quantity,
    name: &str,
    value: f64,
    text: &str,
) -> Result<(), MeasureErrorKind> {
    match quantity {
        // Zenith angles of directions above the surface; 90° is grazing and leaves the
        // BRDF's 1/cosθ undefined (docs/design.md §1.3). The detector's may be signed (in-plane
        // scans are written −80…80°); parse_row folds the negative ones.
        Quantity::ThetaI => {
            if !(0.0..90.0).contains(&value) {
                return Err(MeasureErrorKind::ThetaOutOfRange {
                    column: name.to_owned(),
                    value: shown(text),
                });
            }
            row.angles[0] = value;
        }
        Quantity::ThetaR => {
            if !(value > -90.0 && value < 90.0) {
                return Err(MeasureErrorKind::DetectorThetaOutOfRange { value: shown(text) });
            }
            row.angles[2] = value;
        }
        Quantity::PhiI => row.angles[1] = value,
        Quantity::PhiR => row.angles[3] = value,
        // Checked against the header's or kept as the row's own by parse_row.
        Quantity::Wavelength => {}
        Quantity::Element(index) => {
            if index == 0 && value < 0.0 {
                return Err(MeasureErrorKind::NegativeM00 { value: shown(text) });
            }
            if let Some(kind) = element_value_refusal(name, value, text) {
                return Err(kind);
            }
            if let Some(slot) = columns.slot(index) {
                row.values[slot] = value;
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
            if let Some(slot) = columns.slot(index) {
                row.uncertainties[slot] = Some(value);
            }
        }
    }
    Ok(())
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
        let p = set.points.row(0);
        assert_eq!(
            (p.theta_i_deg, p.phi_i_deg, p.theta_r_deg, p.phi_r_deg),
            (30.0, 0.0, 40.0, 180.0)
        );
        assert_eq!(
            (
                p.values.to_vec(),
                p.uncertainties().collect::<Vec<_>>(),
                p.line
            ),
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
        assert_eq!(set.points.row(0).values, vec![0.05, -0.04]);
        assert_eq!(
            set.points.row(0).uncertainties().collect::<Vec<_>>(),
            vec![Some(0.001), None]
        );
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
        assert_eq!(set.points.row(1).line, 5);
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
        assert_eq!(set.points.row(0).values, vec![0.5]);
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

    /// Bytes that change between the two passes are refused as such, whatever the second pass
    /// would have found in them: never a set mixing two versions of a file.
    #[test]
    fn a_file_changed_between_the_passes_is_refused() {
        let first = "# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n30,40,0.5\n";
        for second in [
            first.replace("0.5", "0.6"),
            first.replace("0.5", "-0.5"),
            first.replace("30,40,0.5\n", ""),
            format!("{first}31,41,0.4\n"),
        ] {
            let scan = scan_table(first.as_bytes()).unwrap();
            let err = sets_of(
                Path::new("x.csv"),
                scan,
                second.as_bytes(),
                true,
                AngleReading::Auto,
            )
            .unwrap_err();
            assert_eq!(
                err.to_string(),
                "x.csv: the file changed while it was read (its bytes differ between the \
                 reader's two passes): read it again once it is no longer being written"
            );
        }
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
