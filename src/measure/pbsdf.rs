//! A `.pbsdf` table read as measurements (docs/design.md §2.10): each node whose directions
//! both have cosines > 0 is one psps row per wavelength (the inverse of the export's
//! conversion, [`psps_from_table`]), so `irpol fit`, `validate` and `read_measurements` take a
//! Mitsuba table like a measurement file. Nodes whose m00 is ≤ 0 or whose elements are not
//! finite are skipped and counted in a note. `M` is read one φ_d slab at a time.
//!
//! A table holds its model far more densely than a fit's few parameters need (a KAIST table of
//! 240 MB has ~750 000 nodes). Beyond
//! [`MAX_TABLE_ROWS_PER_WAVELENGTH`] nodes, a fixed hash of each node's index picks an even share
//! of them, the same nodes at every wavelength, and a note says how many were read: so the rows'
//! memory and the fit's time are bounded whatever the table's size (a 1 GB table is read in a
//! few hundred MB), and a node's choice does not follow the grid's structure as a stride would.
//!
//! A row's `line` is 1 + the index of its matrix in `M` (node-major, wavelength innermost), so
//! a message about a row points into the table.

use crate::interop::convention::{node_directions, psps_from_table};
use crate::interop::{PbsdfFile, TensorError};
use crate::measure::{
    MeasureError, MeasureErrorKind, MeasurementRows, MeasurementSet, MAX_MUELLER_SR,
};
use crate::optics::Mueller;
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

/// The most rows a table gives per wavelength: far more than its parameters need (the shipped
/// materials fit back within 2e-7 from 2 431 nodes), few enough that five wavelengths fit in
/// well under a minute on two cores.
pub const MAX_TABLE_ROWS_PER_WAVELENGTH: usize = 10_000;

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
    let selection = NodeSelection::of(&file.grid);
    let (rows, skipped, nodes_read) = table_rows(&mut file, &selection).map_err(table_error)?;
    if rows.iter().all(MeasurementRows::is_empty) {
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
    if selection.share < 1.0 {
        notes.push(format!(
            "{}: {} of its {} nodes above the horizon read per wavelength (an even share picked \
             by a fixed hash of the node index; a fit needs far fewer than a table holds)",
            crate::text::path(path),
            nodes_read,
            selection.above
        ));
    }
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

/// Which of a table's nodes are read: every node above the horizon, or beyond
/// [`MAX_TABLE_ROWS_PER_WAVELENGTH`] of them an even share picked by a hash of the node index.
struct NodeSelection {
    /// Nodes whose directions both have cosines > 0.
    above: usize,
    /// The share of them read (1 for all).
    share: f64,
}

impl NodeSelection {
    fn of(grid: &crate::interop::PbsdfGrid) -> NodeSelection {
        let mut above = 0;
        for &phi_d in &grid.phi_d {
            for &theta_d in &grid.theta_d {
                for &theta_h in &grid.theta_h {
                    let (light, view) = node_directions(theta_h, theta_d, phi_d);
                    above += usize::from(light.z > 0.0 && view.z > 0.0);
                }
            }
        }
        let share = (MAX_TABLE_ROWS_PER_WAVELENGTH as f64 / above.max(1) as f64).min(1.0);
        NodeSelection { above, share }
    }

    /// Whether node `node` (its index in φ_d-major order) is read.
    fn reads(&self, node: u64) -> bool {
        self.share >= 1.0 || (splitmix64(node) as f64) < self.share * 2f64.powi(64)
    }
}

/// SplitMix64's output function: a fixed, well-mixed hash of a node index, so that the nodes
/// picked are spread over the table independently of its grid (written here: one expression, no
/// crate offers it alone).
fn splitmix64(x: u64) -> u64 {
    let mut z = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The rows of every wavelength at the nodes `selection` reads, how many node values were
/// skipped, and how many nodes were read.
fn table_rows<R: std::io::Read + std::io::Seek>(
    file: &mut PbsdfFile<R>,
    selection: &NodeSelection,
) -> Result<(Vec<MeasurementRows>, usize, usize), TensorError> {
    let n_l = file.wavelengths_nm.len();
    // All 16 elements, none with an uncertainty.
    let mut rows = vec![MeasurementRows::with_capacity(&[false; 16], 0); n_l];
    let mut skipped = 0;
    let grid = file.grid.clone();
    let mut index = 0u64;
    let (mut node, mut nodes_read) = (0u64, 0);
    for (p, &phi_d) in grid.phi_d.iter().enumerate() {
        let slab = file.slab(p)?;
        let mut matrices = slab.chunks_exact(16);
        for &theta_d in &grid.theta_d {
            for &theta_h in &grid.theta_h {
                let (light, view) = node_directions(theta_h, theta_d, phi_d);
                let above = light.z > 0.0 && view.z > 0.0 && selection.reads(node);
                node += 1;
                nodes_read += usize::from(above);
                for row in rows.iter_mut() {
                    let values = matrices.next().expect("the slab holds every node");
                    index += 1;
                    if !above {
                        continue;
                    }
                    let table = Mueller::from_fn(|i, j| values[i * 4 + j]);
                    match point(&psps_from_table(&table, &light, &view), &light, &view) {
                        Some((angles, values)) => row.push(angles, &values, &[None; 16], index),
                        None => skipped += 1,
                    }
                }
            }
        }
    }
    debug_assert_eq!(index as usize, grid.nodes() * n_l);
    Ok((rows, skipped, nodes_read))
}

/// A measurement row of a psps matrix, its angles (θ_i, φ_i, θ_r, φ_r) in degrees and its 16
/// values, or `None` when it cannot be one (m00 ≤ 0, a value not finite or beyond
/// [`MAX_MUELLER_SR`]).
fn point(
    m: &Mueller,
    light: &nalgebra::Vector3<f64>,
    view: &nalgebra::Vector3<f64>,
) -> Option<([f64; 4], [f64; 16])> {
    let values: [f64; 16] = std::array::from_fn(|k| m[(k / 4, k % 4)]);
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
    Some(([theta_i_deg, phi_i_deg, theta_r_deg, phi_r_deg], values))
}
