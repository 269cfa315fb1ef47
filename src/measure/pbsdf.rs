//! A `.pbsdf` table read as measurements (docs/design.md §2.10): each node whose directions
//! both have cosines > 0 is one psps row per wavelength (the inverse of the export's
//! conversion, [`psps_from_table`]), so `irpol fit`, `validate` and `read_measurements` take a
//! Mitsuba table like a measurement file. Nodes whose m00 is ≤ 0 or whose elements are not
//! finite are skipped and counted in a note. `M` is read one φ_d slab at a time.
//!
//! A row's `line` is 1 + the index of its matrix in `M` (node-major, wavelength innermost), so
//! a message about a row points into the table.

use crate::interop::convention::{node_directions, psps_from_table};
use crate::interop::{PbsdfFile, TensorError};
use crate::measure::{
    MeasureError, MeasureErrorKind, MeasurementPoint, MeasurementSet, MAX_MUELLER_SR,
};
use crate::optics::Mueller;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

/// The table at `path` as one measurement set per wavelength, ascending.
pub fn read_table_measurements(path: &Path) -> Result<Vec<MeasurementSet>, MeasureError> {
    let refuse = |kind| MeasureError {
        file: path.to_path_buf(),
        line: 1,
        column: 1,
        kind,
    };
    let table_error = |e: TensorError| refuse(MeasureErrorKind::Table(e));
    let mut file = PbsdfFile::open(path).map_err(table_error)?;
    let wavelengths_um = wavelengths_um(&file.wavelengths_nm).map_err(table_error)?;
    let sha256 = file_sha256(path).map_err(table_error)?;
    let (rows, skipped) = table_rows(&mut file).map_err(table_error)?;
    if rows.iter().all(Vec::is_empty) {
        return Err(refuse(MeasureErrorKind::NoTableRows { skipped }));
    }
    let material = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "table".into());
    let mut notes = vec![format!(
        "{}: read as a Mitsuba measured_polarized table ({} × {} × {} nodes, {} wavelengths)",
        crate::text::path(path),
        file.grid.phi_d.len(),
        file.grid.theta_d.len(),
        file.grid.theta_h.len(),
        wavelengths_um.len()
    )];
    if skipped > 0 {
        notes.push(format!(
            "{}: {skipped} node values with m00 ≤ 0 or not finite skipped",
            crate::text::path(path)
        ));
    }
    let mut sets: Vec<MeasurementSet> = rows
        .into_iter()
        .zip(&wavelengths_um)
        .filter(|(points, _)| !points.is_empty())
        .map(|(points, &wavelength_um)| MeasurementSet {
            source: path.to_path_buf(),
            sha256: sha256.clone(),
            material: material.clone(),
            wavelength_um,
            metadata: BTreeMap::from([
                ("mueller_convention".to_string(), "psps".to_string()),
                ("wavelength_um".to_string(), wavelength_um.to_string()),
            ]),
            elements: (0..16).collect(),
            points,
            merged: Vec::new(),
            notes: notes.clone(),
        })
        .collect();
    sets.sort_by(|a, b| a.wavelength_um.total_cmp(&b.wavelength_um));
    Ok(sets)
}

/// The table's wavelengths in µm, each within irpol's range and none given twice.
fn wavelengths_um(nm: &[f64]) -> Result<Vec<f64>, TensorError> {
    let um: Vec<f64> = nm.iter().map(|w| w * 1e-3).collect();
    let (lo, hi) = (
        crate::optics::MIN_WAVELENGTH_UM,
        crate::optics::MAX_WAVELENGTH_UM,
    );
    if let Some(w) = um.iter().find(|w| !(lo..=hi).contains(*w)) {
        return Err(TensorError::field(
            "wvls",
            format!(
                "{} nm is outside {lo}–{hi} µm, the wavelengths irpol models",
                w * 1e3
            ),
        ));
    }
    for (i, a) in um.iter().enumerate() {
        if um[..i]
            .iter()
            .any(|b| (a - b).abs() <= crate::measure::SAME_WAVELENGTH_UM)
        {
            return Err(TensorError::field(
                "wvls",
                format!("{} nm is given twice", a * 1e3),
            ));
        }
    }
    Ok(um)
}

/// SHA-256 of the file's bytes, streamed (fit provenance, docs/design.md §2.2).
fn file_sha256(path: &Path) -> Result<String, TensorError> {
    let mut file =
        std::fs::File::open(path).map_err(|e| TensorError::file(format!("cannot open: {e}")))?;
    let mut hasher = Sha256::new();
    let mut buffer = vec![0u8; 1 << 20];
    loop {
        let n = file
            .read(&mut buffer)
            .map_err(|e| TensorError::file(format!("cannot read: {e}")))?;
        if n == 0 {
            break;
        }
        hasher.update(&buffer[..n]);
    }
    Ok(crate::measure::hex(&hasher.finalize()))
}

/// The rows of every wavelength, and how many node values were skipped.
fn table_rows<R: std::io::Read + std::io::Seek>(
    file: &mut PbsdfFile<R>,
) -> Result<(Vec<Vec<MeasurementPoint>>, usize), TensorError> {
    let n_l = file.wavelengths_nm.len();
    let mut rows: Vec<Vec<MeasurementPoint>> = vec![Vec::new(); n_l];
    let mut skipped = 0;
    let grid = file.grid.clone();
    let mut index = 0u64;
    for (p, &phi_d) in grid.phi_d.iter().enumerate() {
        let slab = file.slab(p)?;
        let mut matrices = slab.chunks_exact(16);
        for &theta_d in &grid.theta_d {
            for &theta_h in &grid.theta_h {
                let (light, view) = node_directions(theta_h, theta_d, phi_d);
                let above = light.z > 0.0 && view.z > 0.0;
                for row in rows.iter_mut() {
                    let values = matrices.next().expect("the slab holds every node");
                    index += 1;
                    if !above {
                        continue;
                    }
                    let table = Mueller::from_fn(|i, j| values[i * 4 + j]);
                    match point(
                        &psps_from_table(&table, &light, &view),
                        &light,
                        &view,
                        index,
                    ) {
                        Some(point) => row.push(point),
                        None => skipped += 1,
                    }
                }
            }
        }
    }
    debug_assert_eq!(index as usize, grid.nodes() * n_l);
    Ok((rows, skipped))
}

/// A measurement row of a psps matrix, or `None` when it cannot be one (m00 ≤ 0, a value not
/// finite or beyond [`MAX_MUELLER_SR`]).
fn point(
    m: &Mueller,
    light: &nalgebra::Vector3<f64>,
    view: &nalgebra::Vector3<f64>,
    line: u64,
) -> Option<MeasurementPoint> {
    let values: Vec<f64> = (0..16).map(|k| m[(k / 4, k % 4)]).collect();
    let usable = |v: &f64| v.is_finite() && v.abs() <= MAX_MUELLER_SR;
    if values[0].is_nan() || values[0] <= 0.0 || !values.iter().all(usable) {
        return None;
    }
    let angles = |d: &nalgebra::Vector3<f64>| {
        (
            d.z.clamp(-1.0, 1.0).acos().to_degrees(),
            d.y.atan2(d.x).to_degrees(),
        )
    };
    let ((theta_i_deg, phi_i_deg), (theta_r_deg, phi_r_deg)) = (angles(light), angles(view));
    Some(MeasurementPoint {
        theta_i_deg,
        phi_i_deg,
        theta_r_deg,
        phi_r_deg,
        values,
        uncertainties: vec![None; 16],
        line,
    })
}
