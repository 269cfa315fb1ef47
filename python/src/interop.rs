//! Mitsuba 3 `.pbsdf` tables (docs/design.md §2.10): a material exported as one, and a table's
//! fields as numpy arrays.

use crate::errors::{bad_argument, raised};
use crate::material::PyMaterial;
use irpol::app::export::export_loaded;
use irpol::interop::PbsdfFile;
use irpol::material::ExportOptions;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Writes `material` as the table Mitsuba's `measured_polarized` loads (`irpol export --to
/// mitsuba`); returns what was written: path, bytes, grid (N_φd, N_θd, N_θh), wavelengths_nm,
/// notes.
#[pyfunction]
#[pyo3(signature = (material, path, *, wavelengths_nm = None, grid = None))]
pub fn export_pbsdf<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    path: PathBuf,
    wavelengths_nm: Option<Vec<u16>>,
    grid: Option<Vec<usize>>,
) -> PyResult<Bound<'py, PyDict>> {
    let grid = grid
        .map(|g| {
            <[usize; 3]>::try_from(g).map_err(|_| {
                bad_argument("grid: give three node counts (N_phi_d, N_theta_d, N_theta_h)")
            })
        })
        .transpose()?;
    let options = ExportOptions {
        wavelengths_nm,
        grid,
    };
    let summary = py
        .detach(|| export_loaded(&material.inner, &path, &options))
        .map_err(raised)?;
    let d = PyDict::new(py);
    d.set_item("path", summary.path)?;
    d.set_item("bytes", summary.bytes)?;
    d.set_item("grid", summary.grid.to_vec())?;
    d.set_item("wavelengths_nm", summary.wavelengths_nm)?;
    d.set_item("notes", summary.notes)?;
    Ok(d)
}

/// A table's fields: phi_d, theta_d, theta_h (radians), wvls (nm) and M (float32,
/// (N_φd, N_θd, N_θh, N_λ, 4, 4), the table's own frames and S3 sign).
#[pyfunction]
pub fn read_pbsdf(py: Python<'_>, path: PathBuf) -> PyResult<Bound<'_, PyDict>> {
    let table = py
        .detach(|| PbsdfFile::open(&path).and_then(PbsdfFile::read_table))
        .map_err(|e| bad_argument(format!("{}: {e}", irpol::text::path(&path))))?;
    let [p, t, h] = table.grid.counts();
    let shape = [p, t, h, table.wavelengths_nm.len(), 4, 4];
    let d = PyDict::new(py);
    d.set_item("phi_d", PyArray1::from_slice(py, &table.grid.phi_d))?;
    d.set_item("theta_d", PyArray1::from_slice(py, &table.grid.theta_d))?;
    d.set_item("theta_h", PyArray1::from_slice(py, &table.grid.theta_h))?;
    d.set_item("wvls", PyArray1::from_slice(py, &table.wavelengths_nm))?;
    d.set_item("M", PyArray1::from_vec(py, table.values).reshape(shape)?)?;
    Ok(d)
}
