//! `irpol eval` and `irpol emissivity`: the model evaluated on a geometry CSV, an angle sweep or
//! an emission-angle table, written as CSV.
//!
//! A detector zenith θ_r < 0 (in-plane scans are written −80…80°) is the detector across the
//! normal, (|θ_r|, φ_r + 180°): the Mueller values are those of that geometry, the row is echoed
//! as given, and the table carries one note saying how many rows were so read.
//!
//! Rows are produced one at a time, never held all at once: a geometry file is read into memory
//! as bytes and parsed twice (once to validate every row, so that a bad row refuses the file
//! before anything is printed, once to evaluate), and a sweep generates its rows from its angle
//! lists. Output goes through the csv crate's writer, so a passed-through field such as "a,b"
//! stays quoted and the CSV stays rectangular.

use crate::measure::MUELLER_ELEMENT_NAMES;
use crate::pbrdf::{signed_zenith_note, Direction, HemisphereQuadrature, Pbrdf};
use crate::text::{shown, shown_at_most};
use anyhow::Context;
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
        bytes: Vec<u8>,
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

fn geometry_reader(bytes: &[u8]) -> csv::Reader<&[u8]> {
    csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(bytes)
}

/// Reads and validates a geometry CSV: every row must hold valid angles.
pub fn read_geometry_csv(path: &Path) -> anyhow::Result<GeometryTable> {
    let bytes = std::fs::read(path).with_context(|| format!("{}: cannot open", path.display()))?;
    parse_geometry_csv(path, bytes)
}

/// [`read_geometry_csv`] of a file's bytes; `path` names it in messages.
pub fn parse_geometry_csv(path: &Path, bytes: Vec<u8>) -> anyhow::Result<GeometryTable> {
    let headers: Vec<String> = geometry_reader(&bytes)
        .headers()
        .map_err(|e| {
            anyhow::anyhow!(
                "{}:1:1: cannot read the header: {}",
                path.display(),
                shown_at_most(&e.to_string(), HEADER_EXCERPT_CHARS)
            )
        })?
        .iter()
        .map(str::to_owned)
        .collect();
    let columns = geometry_columns(path, &headers)?;
    let mut table = GeometryTable {
        headers,
        rows: Rows::File {
            path: path.to_owned(),
            bytes,
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
        anyhow::bail!("{}: no geometry rows", path.display());
    }
    table
        .notes
        .extend(signed_zenith_note(&path.display().to_string(), signed));
    Ok(table)
}

/// The angle columns of a header row, refusing duplicate names (which value would be meant?) and
/// names of the Mueller elements that eval appends (the output would hold two m00 columns).
fn geometry_columns(path: &Path, headers: &[String]) -> anyhow::Result<GeometryColumns> {
    for (index, name) in headers.iter().enumerate() {
        if let Some(first) = headers[..index].iter().position(|h| h == name) {
            anyhow::bail!(
                "{}:1:{}: duplicate column '{}' (already column {})",
                path.display(),
                index + 1,
                shown(name),
                first + 1
            );
        }
        if MUELLER_ELEMENT_NAMES.contains(&name.as_str()) {
            anyhow::bail!(
                "{}:1:{}: column '{name}' clashes with the Mueller elements eval appends; rename it",
                path.display(),
                index + 1
            );
        }
    }
    let column = |name: &str| headers.iter().position(|h| h == name);
    let required = |name: &str| {
        column(name).ok_or_else(|| {
            anyhow::anyhow!(
                "{}:1:1: missing column '{name}' (have: {})",
                path.display(),
                shown_at_most(&headers.join(","), HEADER_EXCERPT_CHARS)
            )
        })
    };
    Ok(GeometryColumns {
        theta_i: required("theta_i_deg")?,
        theta_r: required("theta_r_deg")?,
        phi_i: column("phi_i_deg"),
        phi_r: column("phi_r_deg"),
    })
}

/// The geometry of one record, its angles checked.
fn record_geometry(
    path: &Path,
    headers: &[String],
    columns: GeometryColumns,
    record: &csv::StringRecord,
) -> anyhow::Result<Geometry> {
    let line = record.position().map_or(0, |p| p.line());
    let field = |index: usize| -> anyhow::Result<f64> {
        let text = &record[index];
        text.parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "{}:{line}:{}: {} = '{}' is not a finite number",
                    path.display(),
                    index + 1,
                    shown(&headers[index]),
                    shown(text)
                )
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
        .map_err(|e| anyhow::anyhow!("{}:{line}: {e}", path.display()))?;
    Ok(geometry)
}

impl GeometryTable {
    /// Calls `visit` with each row's fields (as they are echoed) and its geometry, in order.
    fn for_each_row(
        &self,
        mut visit: impl FnMut(&[&str], &Geometry) -> anyhow::Result<()>,
    ) -> anyhow::Result<()> {
        match &self.rows {
            Rows::File {
                path,
                bytes,
                columns,
            } => {
                let mut reader = geometry_reader(bytes);
                let mut record = csv::StringRecord::new();
                loop {
                    let more = reader.read_record(&mut record).map_err(|e| {
                        anyhow::anyhow!(
                            "{}: {}",
                            path.display(),
                            shown_at_most(&e.to_string(), HEADER_EXCERPT_CHARS)
                        )
                    })?;
                    if !more {
                        return Ok(());
                    }
                    let geometry = record_geometry(path, &self.headers, *columns, &record)?;
                    let fields: Vec<&str> = record.iter().collect();
                    visit(&fields, &geometry)?;
                }
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
fn write_error(error: csv::Error) -> anyhow::Error {
    match error.into_kind() {
        csv::ErrorKind::Io(io) => io.into(),
        other => anyhow::anyhow!("cannot write the CSV: {other:?}"),
    }
}

/// Writes the table's rows with the 16 Mueller elements (sr⁻¹, psps) appended.
pub fn write_mueller_csv(
    model: &Pbrdf,
    table: &GeometryTable,
    out: &mut impl Write,
) -> anyhow::Result<()> {
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
) -> anyhow::Result<GeometryTable> {
    let rows = theta_i
        .len()
        .saturating_mul(theta_r.len())
        .saturating_mul(phi_r.len());
    if rows > MAX_SWEEP_ROWS {
        anyhow::bail!(
            "the sweep asks for {} × {} × {} = {rows} rows (θ_i × θ_r × φ_r); at most \
             {MAX_SWEEP_ROWS}",
            theta_i.len(),
            theta_r.len(),
            phi_r.len()
        );
    }
    if rows == 0 {
        anyhow::bail!("the sweep has no rows");
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

/// Writes theta_deg,e0,e1,e2,e3 and returns the angles where the hemispherical reflectance
/// exceeds 1 (ε0 < 0), which the caller must report.
pub fn write_emissivity_csv(
    model: &Pbrdf,
    thetas_deg: &[f64],
    out: &mut impl Write,
) -> anyhow::Result<Vec<f64>> {
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

    fn eval_file(text: &str) -> anyhow::Result<String> {
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
        assert!(err
            .to_string()
            .contains(":1:3: duplicate column 'theta_i_deg' (already column 1)"));
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
