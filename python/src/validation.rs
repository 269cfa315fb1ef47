//! `irpol validate` without its report: how a material predicts measurements it was not fitted
//! to (docs/design.md §1.10, §4), as numbers and arrays.

use crate::errors::raised;
use crate::material::PyMaterial;
use crate::measurements::{read_sets, set_dict};
use irpol::app::material_pbrdf;
use irpol::fit::validate_model;
use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Scores `material` on every set of the measurement file `path` (read as `read_measurement_sets`
/// reads it): one dict per set with the figures `irpol validate` prints — m00's relative RMS,
/// the RMS of m_ij/m00, χ² per observation, the largest |r| — the per-element RMS (sr⁻¹ and
/// normalized), the model's matrices at every row and the set itself.
#[pyfunction]
#[pyo3(signature = (material, path, *, layout = None, wavelength_um = None, theta_i_deg = None))]
pub fn validate_material<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    path: PathBuf,
    layout: Option<PathBuf>,
    wavelength_um: Option<f64>,
    theta_i_deg: Option<Vec<f64>>,
) -> PyResult<Vec<Bound<'py, PyDict>>> {
    let sets = read_sets(py, &path, layout, wavelength_um, theta_i_deg)?;
    let material = &material.inner;
    let mut out = Vec::new();
    for set in &sets {
        let wavelength = material.model.spectral().map(|_| set.wavelength_um);
        let model = material_pbrdf(material, wavelength, None).map_err(raised)?;
        let v = py.detach(|| validate_model(&model, set)).map_err(raised)?;
        let d = PyDict::new(py);
        d.set_item("measurements", set_dict(py, set)?)?;
        d.set_item("rows", v.rows)?;
        d.set_item("m00_relative_rms", v.m00_relative_rms())?;
        d.set_item("normalized_rms", v.rms_normalized_elements)?;
        d.set_item("chi2_per_observation", v.chi2_per_observation)?;
        d.set_item("max_abs_residual", v.max_abs_residual)?;
        d.set_item("uncertainties_from_file", v.uncertainties_from_file)?;
        let per_element = PyDict::new(py);
        for e in &v.elements {
            per_element.set_item(e.name, (e.rms, e.rms_normalized))?;
        }
        d.set_item("elements", per_element)?;
        let rows: Vec<Vec<f64>> = v
            .model_muellers
            .iter()
            .map(|m| m.transpose().iter().copied().collect())
            .collect();
        d.set_item("model_mueller", PyArray2::from_vec2(py, &rows)?)?;
        out.push(d);
    }
    Ok(out)
}
