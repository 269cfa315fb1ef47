//! `irpol eval` and `irpol emissivity`: the model evaluated on a geometry CSV, an angle sweep or
//! an emission-angle table, written as CSV.
//!
//! A detector zenith θ_r < 0 (in-plane scans are written −80…80°) is the detector across the
//! normal, (|θ_r|, φ_r + 180°): the Mueller values are those of that geometry, the row is echoed
//! as given, and the table carries one note saying how many rows were so read.
//!
//! Rows are produced one at a time, never held all at once: a geometry file is read into memory
//! as text and parsed twice by the text tables' reader (`table_text`: once to validate every
//! row, so that a bad row refuses the file at its line and column before anything is printed,
//! once to evaluate), and a sweep generates its rows from its angle lists. Output goes through
//! the csv crate's writer, so a passed-through field such as "a,b" stays quoted and the CSV
//! stays rectangular.

use super::AppError;
use crate::measure::MUELLER_ELEMENT_NAMES;
use crate::pbrdf::{signed_zenith_note, Direction, HemisphereQuadrature, Pbrdf};
use crate::table_text::{
    content_lines, decode_utf8, parse_finite, split_fields, wrong_delimiter, Field, InvalidUtf8,
    Problem, Refusal,
};
use crate::text::{shown, shown_at_most};
use std::io::Write;
use std::path::{Path, PathBuf};

/// Most rows an angle sweep may produce (θ_i values × θ_r values × φ_r values): about 3 GB of CSV, and minutes
/// of evaluation. A larger table is almost certainly a mistyped step.
pub const MAX_SWEEP_ROWS: usize = 10_000_000;

/// Characters of a header row quoted in a message.
const HEADER_EXCERPT_CHARS: usize = 120;

/// One evaluation geometry in degrees, θ_r signed as given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Geometry {
    pub theta_i_deg: f64,
    pub phi_i_deg: f64,
    pub theta_r_deg: f64,
    pub phi_r_deg: f64,
}

impl Geometry {
    fn directions(&self) -> Result<(Direction, Direction), crate::pbrdf::ModelError> {
        Ok((
            Direction::from_degrees_checked("theta_i_deg", self.theta_i_deg, self.phi_i_deg)?,
            Direction::from_signed_degrees_checked(
                "theta_r_deg",
                self.theta_r_deg,
                self.phi_r_deg,
            )?,
        ))
    }
}

/// The geometries to evaluate: the rows of a geometry CSV (columns theta_i_deg, theta_r_deg,
/// optional phi_i_deg (0) and phi_r_deg (180), other columns passed through), or a sweep.
pub struct GeometryTable {
    pub headers: Vec<String>,
    rows: Rows,
    /// What the user should know about how the rows were read (θ_r < 0), for the caller to
    /// print; the library never prints.
    pub notes: Vec<String>,
}

enum Rows {
    File {
        path: PathBuf,
        text: String,
        columns: GeometryColumns,
    },
    /// Every θ_i, then every θ_r, then every φ_r (innermost: a ring of the detector per θ_r).
    Sweep {
        theta_i: Vec<f64>,
        phi_i: f64,
        theta_r: Vec<f64>,
        phi_r: Vec<f64>,
    },
}

/// Where the angles are in a geometry CSV's records.
#[derive(Clone, Copy)]
struct GeometryColumns {
    theta_i: usize,
    theta_r: usize,
    phi_i: Option<usize>,
    phi_r: Option<usize>,
}

/// The fields of line `number`, refused at the column of a malformed quote.
fn fields_of<'a>(path: &Path, number: u64, line: &'a str) -> Result<Vec<Field<'a>>, AppError> {
    split_fields(number, line)
        .map_err(|refusal| geometry_error(path, refusal.map(|k| k.to_string())))
}

/// Reads and validates a geometry CSV: every row must hold valid angles.
pub fn read_geometry_csv(path: &Path) -> Result<GeometryTable, AppError> {
    let bytes = std::fs::read(path).map_err(|source| AppError::Open {
        path: path.to_owned(),
        source,
    })?;
    parse_geometry_csv(path, bytes)
}

/// A refused geometry CSV: the text tables' one refusal (`path:line:column: message`; line 0
/// is the whole file, column 0 the whole line).
fn geometry_error(path: &Path, refusal: Refusal<String>) -> AppError {
    AppError::Geometry(refusal.map(Problem).in_file(path))
}

/// [`read_geometry_csv`] of a file's bytes; `path` names it in messages.
pub fn parse_geometry_csv(path: &Path, bytes: Vec<u8>) -> Result<GeometryTable, AppError> {
    // Checked (and its byte-order mark found) in place, then kept without a copy.
    let bom = match decode_utf8(&bytes) {
        Ok(text) => bytes.len() - text.len(),
        Err(refusal) => {
            let problem = |k: InvalidUtf8| {
                format!(
                    "invalid UTF-8 (byte 0x{:02X}): a geometry CSV must be UTF-8 text",
                    k.byte
                )
            };
            return Err(geometry_error(path, refusal.map(problem)));
        }
    };
    let mut text = String::from_utf8(bytes).expect("checked above");
    text.drain(..bom);
    let (header_line, header) = match content_lines(&text).next() {
        Some((number, line)) => (number, fields_of(path, number, line)?),
        None => (1, Vec::new()),
    };
    // A header of one field holding ';' or tabs is a file separated by them (rows may pass
    // such characters through in their own columns).
    if let (Some(refusal), 1) = (wrong_delimiter(header_line, &header), header.len()) {
        return Err(geometry_error(path, refusal.map(|k| k.to_string())));
    }
    let columns = geometry_columns(path, header_line, &header)?;
    let headers: Vec<String> = header.into_iter().map(|f| f.text.into_owned()).collect();
    let mut table = GeometryTable {
        headers,
        rows: Rows::File {
            path: path.to_owned(),
            text,
            columns,
        },
        notes: Vec::new(),
    };
    let (mut count, mut signed) = (0usize, 0usize);
    table.for_each_row(|_, geometry| {
        count += 1;
        signed += usize::from(geometry.theta_r_deg < 0.0);
        Ok(())
    })?;
    if count == 0 {
        return Err(geometry_error(
            path,
            Refusal::at_line(0, "no geometry rows".into()),
        ));
    }
    table
        .notes
        .extend(signed_zenith_note(&path.display().to_string(), signed));
    Ok(table)
}

/// The angle columns of a header row, refusing duplicate names (which value would be meant?) and
/// names of the Mueller elements that eval appends (the output would hold two m00 columns).
fn geometry_columns(
    path: &Path,
    line: u64,
    header: &[Field<'_>],
) -> Result<GeometryColumns, AppError> {
    let headers: Vec<&str> = header.iter().map(|f| f.text.as_ref()).collect();
    for (index, (&name, field)) in headers.iter().zip(header).enumerate() {
        let refused =
            |message: String| geometry_error(path, Refusal::new(line, field.column, message));
        if let Some(first) = headers[..index].iter().position(|h| *h == name) {
            return Err(refused(format!(
                "duplicate column '{}' (already column {})",
                shown(name),
                first + 1
            )));
        }
        if MUELLER_ELEMENT_NAMES.contains(&name) {
            return Err(refused(format!(
                "column '{}' clashes with the Mueller elements eval appends; rename it",
                shown(name)
            )));
        }
    }
    let column = |name: &str| headers.iter().position(|h| *h == name);
    let required = |name: &str| {
        column(name).ok_or_else(|| {
            let message = format!(
                "missing column '{name}' (have: {})",
                shown_at_most(&headers.join(","), HEADER_EXCERPT_CHARS)
            );
            geometry_error(path, Refusal::new(line, 1, message))
        })
    };
    Ok(GeometryColumns {
        theta_i: required("theta_i_deg")?,
        theta_r: required("theta_r_deg")?,
        phi_i: column("phi_i_deg"),
        phi_r: column("phi_r_deg"),
    })
}

/// The geometry of one row (line `line`, its `fields`), its angles checked.
fn record_geometry(
    path: &Path,
    headers: &[String],
    columns: GeometryColumns,
    (line, fields): (u64, &[Field<'_>]),
) -> Result<Geometry, AppError> {
    if fields.len() != headers.len() {
        let message = format!(
            "the row has {} fields, the header row has {}",
            fields.len(),
            headers.len()
        );
        return Err(geometry_error(path, Refusal::at_line(line, message)));
    }
    let field = |index: usize| -> Result<f64, AppError> {
        let text = fields[index].text.as_ref();
        parse_finite(text).map_err(|_| {
            let message = format!(
                "{} = '{}' is not a finite number",
                shown(&headers[index]),
                shown(text)
            );
            geometry_error(path, Refusal::new(line, fields[index].column, message))
        })
    };
    let geometry = Geometry {
        theta_i_deg: field(columns.theta_i)?,
        phi_i_deg: columns.phi_i.map(field).transpose()?.unwrap_or(0.0),
        theta_r_deg: field(columns.theta_r)?,
        phi_r_deg: columns.phi_r.map(field).transpose()?.unwrap_or(180.0),
    };
    geometry
        .directions()
        .map_err(|e| geometry_error(path, Refusal::at_line(line, e.to_string())))?;
    Ok(geometry)
}

impl GeometryTable {
    /// Calls `visit` with each row's fields (as they are echoed) and its geometry, in order.
    fn for_each_row(
        &self,
        mut visit: impl FnMut(&[&str], &Geometry) -> Result<(), AppError>,
    ) -> Result<(), AppError> {
        match &self.rows {
            Rows::File {
                path,
                text,
                columns,
            } => {
                // The header is the first line; every other one is a row.
                for (number, line) in content_lines(text).skip(1) {
                    let fields = fields_of(path, number, line)?;
                    let geometry =
                        record_geometry(path, &self.headers, *columns, (number, &fields))?;
                    let texts: Vec<&str> = fields.iter().map(|f| f.text.as_ref()).collect();
                    visit(&texts, &geometry)?;
                }
                Ok(())
            }
            Rows::Sweep {
                theta_i,
                phi_i,
                theta_r,
                phi_r,
            } => {
                let phi_i_text = phi_i.to_string();
                let phi_r_texts: Vec<String> = phi_r.iter().map(f64::to_string).collect();
                for &ti in theta_i {
                    let ti_text = ti.to_string();
                    for &tr in theta_r {
                        let tr_text = tr.to_string();
                        for (&pr, pr_text) in phi_r.iter().zip(&phi_r_texts) {
                            let geometry = Geometry {
                                theta_i_deg: ti,
                                phi_i_deg: *phi_i,
                                theta_r_deg: tr,
                                phi_r_deg: pr,
                            };
                            visit(&[&ti_text, &phi_i_text, &tr_text, pr_text], &geometry)?;
                        }
                    }
                }
                Ok(())
            }
        }
    }
}

/// The csv writer's error, with an I/O error kept as one so that `main` can tell a closed pipe
/// (`irpol eval … | head`) from a failure.
fn write_error(error: csv::Error) -> AppError {
    match error.into_kind() {
        csv::ErrorKind::Io(io) => AppError::Stream(io),
        other => AppError::Csv(format!("{other:?}")),
    }
}

/// Writes the table's rows with the 16 Mueller elements (sr⁻¹, psps) appended.
pub fn write_mueller_csv(
    model: &Pbrdf,
    table: &GeometryTable,
    out: &mut impl Write,
) -> Result<(), AppError> {
    out.write_all(super::model_header(model).as_bytes())?;
    // Readers skip the `#` model lines as comments, so a data field starting with '#' is quoted.
    let mut writer = csv::WriterBuilder::new()
        .comment(Some(b'#'))
        .from_writer(out);
    writer
        .write_record(
            table
                .headers
                .iter()
                .map(String::as_str)
                .chain(MUELLER_ELEMENT_NAMES),
        )
        .map_err(write_error)?;
    table.for_each_row(|fields, geometry| {
        let (incident, scattered) = geometry.directions()?;
        let m = model.mueller(&incident, &scattered);
        for field in fields {
            writer.write_field(field).map_err(write_error)?;
        }
        for value in m.transpose().iter() {
            writer
                .write_field(format!("{value:e}"))
                .map_err(write_error)?;
        }
        writer.write_record(None::<&[u8]>).map_err(write_error)
    })?;
    writer.flush()?;
    Ok(())
}

/// A sweep as a geometry table (every combination of the given angles, θ_r outer and φ_r
/// inner), refused when it would exceed [`MAX_SWEEP_ROWS`] or holds an invalid angle.
pub fn sweep_table(
    theta_i: &[f64],
    phi_i: f64,
    theta_r: &[f64],
    phi_r: &[f64],
) -> Result<GeometryTable, AppError> {
    let rows = theta_i
        .len()
        .saturating_mul(theta_r.len())
        .saturating_mul(phi_r.len());
    if rows > MAX_SWEEP_ROWS {
        return Err(AppError::invalid(format!(
            "the sweep asks for {} × {} × {} = {rows} rows (θ_i × θ_r × φ_r); at most \
             {MAX_SWEEP_ROWS}",
            theta_i.len(),
            theta_r.len(),
            phi_r.len()
        )));
    }
    if rows == 0 {
        return Err(AppError::invalid("the sweep has no rows"));
    }
    // Every angle on its own: a sweep is valid when each of its θ_i, θ_r and φ_r values is.
    for &ti in theta_i {
        Direction::from_degrees_checked("theta_i_deg", ti, phi_i)?;
    }
    // (A zenith's validity does not depend on the azimuth, nor an azimuth's on the zenith.)
    for &tr in theta_r {
        Direction::from_signed_degrees_checked("theta_r_deg", tr, phi_r[0])?;
    }
    for &pr in phi_r {
        Direction::from_signed_degrees_checked("theta_r_deg", theta_r[0], pr)?;
    }
    let headers = ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"]
        .map(str::to_owned)
        .to_vec();
    let signed = theta_r.iter().filter(|&&tr| tr < 0.0).count() * theta_i.len() * phi_r.len();
    Ok(GeometryTable {
        headers,
        rows: Rows::Sweep {
            theta_i: theta_i.to_vec(),
            phi_i,
            theta_r: theta_r.to_vec(),
            phi_r: phi_r.to_vec(),
        },
        notes: signed_zenith_note("--theta-r", signed)
            .into_iter()
            .collect(),
    })
}

/// The geometries `irpol eval` is given: a geometry CSV, or the sweep of `--theta-i`,
/// `--theta-r` and `--phi-r` (each a value or `START:STOP:STEP`) at azimuth `phi_i`.
pub fn geometry_table(
    geometry: Option<&Path>,
    theta_i: Option<&str>,
    theta_r: Option<&str>,
    phi_i: f64,
    phi_r: &str,
) -> Result<GeometryTable, AppError> {
    match (geometry, theta_i, theta_r) {
        (Some(path), _, _) => read_geometry_csv(path),
        (None, Some(ti), Some(tr)) => sweep_table(
            &super::parse_sweep(ti, "theta-i")?,
            phi_i,
            &super::parse_sweep(tr, "theta-r")?,
            &super::parse_sweep(phi_r, "phi-r")?,
        ),
        _ => Err(AppError::invalid(
            "give --geometry FILE.csv, or --theta-i and --theta-r",
        )),
    }
}

/// Writes theta_deg,e0,e1,e2,e3 and returns the angles where the hemispherical reflectance
/// exceeds 1 (ε0 < 0), which the caller must report.
pub fn write_emissivity_csv(
    model: &Pbrdf,
    thetas_deg: &[f64],
    out: &mut impl Write,
) -> Result<Vec<f64>, AppError> {
    for &theta in thetas_deg {
        Direction::from_degrees_checked("theta", theta, 0.0)?;
    }
    let radians: Vec<f64> = thetas_deg.iter().map(|t| t.to_radians()).collect();
    let table = model.emissivity_table(&radians, &HemisphereQuadrature::default());
    out.write_all(super::model_header(model).as_bytes())?;
    writeln!(out, "theta_deg,e0,e1,e2,e3")?;
    let mut excess = Vec::new();
    for (&theta, e) in thetas_deg.iter().zip(&table) {
        writeln!(out, "{theta},{:e},{:e},{:e},{:e}", e[0], e[1], e[2], e[3])?;
        if e[0] < -1e-9 {
            excess.push(theta);
        }
    }
    Ok(excess)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::RefractiveIndex;
    use crate::pbrdf::{Shadowing, SlopeDistribution};

    fn model() -> Pbrdf {
        Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.2, q: 2.0 },
            Shadowing::Smith,
            RefractiveIndex::new(1.5, 0.1),
            0.0,
        )
        .unwrap()
    }

    fn eval_file(text: &str) -> Result<String, AppError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("g.csv");
        std::fs::write(&path, text).unwrap();
        let table = read_geometry_csv(&path)?;
        let mut out = Vec::new();
        write_mueller_csv(&model(), &table, &mut out)?;
        Ok(String::from_utf8(out).unwrap())
    }

    #[test]
    fn quoted_fields_stay_quoted_and_rows_rectangular() {
        let out =
            eval_file("label,theta_i_deg,theta_r_deg\n\"a,b\",30,30\nplain,10,20\n\"#3\",5,5\n")
                .unwrap();
        // After the two `#` lines that state the model.
        let lines: Vec<&str> = out.lines().skip(2).collect();
        let out = lines.join("\n");
        assert!(lines[0].starts_with("label,theta_i_deg,theta_r_deg,m00,m01,"));
        assert!(lines[1].starts_with("\"a,b\",30,30,"), "{out}");
        assert!(lines[2].starts_with("plain,10,20,"), "{out}");
        // A label starting with '#' is quoted, so comment-aware readers keep the row.
        assert!(lines[3].starts_with("\"#3\",5,5,"), "{out}");
        let mut reader = csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .from_reader(out.as_bytes());
        for record in reader.records() {
            assert_eq!(record.unwrap().len(), 19);
        }
    }

    #[test]
    fn duplicate_and_clashing_columns_and_bad_text_are_refused() {
        let err = eval_file("theta_i_deg,theta_r_deg,theta_i_deg\n30,30,40\n").unwrap_err();
        // The place is the text tables' one: line and character column of the field.
        assert!(err
            .to_string()
            .contains("g.csv:1:25: duplicate column 'theta_i_deg' (already column 1)"));
        let err = eval_file("# a comment\ntheta_i_deg,theta_r_deg\n30, 3x0\n").unwrap_err();
        assert!(
            err.to_string()
                .contains("g.csv:3:5: theta_r_deg = '3x0' is not a finite number"),
            "{err}"
        );
        let err = eval_file("theta_i_deg,theta_r_deg\n30,30\n\n30\n").unwrap_err();
        assert!(
            err.to_string()
                .contains("g.csv:4: the row has 1 fields, the header row has 2"),
            "{err}"
        );
        let err = eval_file("theta_i_deg,theta_r_deg\n30,\"30\n").unwrap_err();
        assert!(err.to_string().contains("g.csv:2:4: quoted field"), "{err}");
        let err = eval_file("theta_i_deg;theta_r_deg\n30;30\n").unwrap_err();
        assert!(
            err.to_string()
                .contains("g.csv:1:12: fields are separated by ';'"),
            "{err}"
        );
        let err = eval_file("theta_i_deg,theta_r_deg,m00\n30,30,1\n").unwrap_err();
        assert!(err.to_string().contains("'m00' clashes"), "{err}");
        let junk = format!(
            "theta_i_deg,theta_r_deg\n\u{1b}[31m{},30\n",
            "7".repeat(100_000)
        );
        let err = eval_file(&junk).unwrap_err().to_string();
        assert!(!err.contains('\u{1b}') && err.len() < 300, "{err}");
    }

    #[test]
    fn sweeps_are_bounded_and_checked_before_any_row() {
        let many: Vec<f64> = (0..4000).map(|i| i as f64 * 0.01).collect();
        let err = sweep_table(&many, 0.0, &many, &[180.0]).err().unwrap();
        assert!(err.to_string().contains("at most 10000000"), "{err}");
        // The bound holds for the product with the φ_r sweep too.
        let err = sweep_table(&many[..100], 0.0, &many[..1000], &many[..101])
            .err()
            .unwrap();
        assert!(err.to_string().contains("100 × 1000 × 101"), "{err}");
        assert!(sweep_table(&[10.0], 0.0, &[10.0, 95.0], &[180.0]).is_err());
        assert!(sweep_table(&[10.0], 0.0, &[10.0], &[180.0, f64::NAN]).is_err());
        let table = sweep_table(&[10.0, 20.0], 0.0, &[30.0], &[180.0]).unwrap();
        let mut out = Vec::new();
        write_mueller_csv(&model(), &table, &mut out).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert_eq!(text.lines().count(), 5);
        assert!(text.lines().nth(4).unwrap().starts_with("20,0,30,180,"));
    }
}
