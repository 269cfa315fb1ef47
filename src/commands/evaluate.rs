//! `irpol eval` and `irpol emissivity`: the model evaluated on a geometry CSV, an angle sweep or
//! an emission-angle table, written as CSV.

use crate::pbrdf::{Direction, HemisphereQuadrature, Pbrdf};
use anyhow::Context;
use std::io::Write;
use std::path::Path;

const MUELLER_HEADER: &str = "m00,m01,m02,m03,m10,m11,m12,m13,m20,m21,m22,m23,m30,m31,m32,m33";

/// One evaluation geometry in degrees.
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
            Direction::from_degrees_checked("theta_r_deg", self.theta_r_deg, self.phi_r_deg)?,
        ))
    }
}

/// The rows of a geometry CSV (columns theta_i_deg, theta_r_deg, optional phi_i_deg (0) and
/// phi_r_deg (180), other columns passed through) with the raw records for echoing.
pub struct GeometryTable {
    pub headers: Vec<String>,
    pub rows: Vec<(Vec<String>, Geometry)>,
}

pub fn read_geometry_csv(path: &Path) -> anyhow::Result<GeometryTable> {
    let file =
        std::fs::File::open(path).with_context(|| format!("{}: cannot open", path.display()))?;
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .trim(csv::Trim::All)
        .from_reader(file);
    let headers: Vec<String> = reader
        .headers()
        .with_context(|| format!("{}:1:1: cannot read the header", path.display()))?
        .iter()
        .map(str::to_owned)
        .collect();
    let column = |name: &str| headers.iter().position(|h| h == name);
    let required = |name: &str| {
        column(name).ok_or_else(|| {
            anyhow::anyhow!(
                "{}:1:1: missing column '{name}' (have: {})",
                path.display(),
                headers.join(",")
            )
        })
    };
    let (ti, tr) = (required("theta_i_deg")?, required("theta_r_deg")?);
    let (pi, pr) = (column("phi_i_deg"), column("phi_r_deg"));
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
        let line = record.position().map_or(0, |p| p.line());
        let field = |index: usize| -> anyhow::Result<f64> {
            let text = &record[index];
            text.parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    anyhow::anyhow!(
                        "{}:{line}:{}: {} = '{text}' is not a finite number",
                        path.display(),
                        index + 1,
                        headers[index]
                    )
                })
        };
        let geometry = Geometry {
            theta_i_deg: field(ti)?,
            phi_i_deg: pi.map(field).transpose()?.unwrap_or(0.0),
            theta_r_deg: field(tr)?,
            phi_r_deg: pr.map(field).transpose()?.unwrap_or(180.0),
        };
        geometry
            .directions()
            .map_err(|e| anyhow::anyhow!("{}:{line}: {e}", path.display()))?;
        rows.push((record.iter().map(str::to_owned).collect(), geometry));
    }
    if rows.is_empty() {
        anyhow::bail!("{}: no geometry rows", path.display());
    }
    Ok(GeometryTable { headers, rows })
}

/// Writes the table's rows with the 16 Mueller elements (sr⁻¹, psps) appended.
pub fn write_mueller_csv(
    model: &Pbrdf,
    table: &GeometryTable,
    out: &mut impl Write,
) -> anyhow::Result<()> {
    writeln!(out, "{},{MUELLER_HEADER}", table.headers.join(","))?;
    for (fields, geometry) in &table.rows {
        let (incident, scattered) = geometry.directions()?;
        let m = model.mueller(&incident, &scattered);
        let values: Vec<String> = m.transpose().iter().map(|v| format!("{v:e}")).collect();
        writeln!(out, "{},{}", fields.join(","), values.join(","))?;
    }
    Ok(())
}

/// A sweep as a geometry table (every combination of the given angles).
pub fn sweep_table(
    theta_i: &[f64],
    phi_i: f64,
    theta_r: &[f64],
    phi_r: f64,
) -> anyhow::Result<GeometryTable> {
    let headers = ["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"]
        .map(str::to_owned)
        .to_vec();
    let mut rows = Vec::new();
    for &ti in theta_i {
        for &tr in theta_r {
            let geometry = Geometry {
                theta_i_deg: ti,
                phi_i_deg: phi_i,
                theta_r_deg: tr,
                phi_r_deg: phi_r,
            };
            geometry.directions()?;
            rows.push((
                vec![
                    ti.to_string(),
                    phi_i.to_string(),
                    tr.to_string(),
                    phi_r.to_string(),
                ],
                geometry,
            ));
        }
    }
    Ok(GeometryTable { headers, rows })
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
