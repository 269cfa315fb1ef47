//! `irpol fit` without writing: the library's fit of each material among the inputs, returned
//! with its library entry, the uncertainties and correlations, χ² and the per-point residuals.

use crate::errors::raised;
use crate::material::PyMaterial;
use crate::measurements::{measurement_args, set_dict};
use irpol::app::fit::FitFlags;
use irpol::fit::{fit_inputs_with, MaterialFit};
use irpol::measure::MeasurementSet;
use irpol::optics::Mueller;
use numpy::{PyArray1, PyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Fits every material among `inputs` (CSV files or folders) with the options `irpol fit` takes
/// as flags (same names, same defaults, same messages; `layout`, `wavelength_um`, `theta_i_deg`
/// are `--layout`, `--wavelength`, `--theta-i`; `terms` is `--terms`, `auto` by default); one
/// dict per material, in the order `irpol fit`
/// reports them.
#[pyfunction]
#[pyo3(signature = (inputs, *, distribution = None, shadowing = "smith".to_owned(), free = None,
    fix = None, optimizer = "ga+lm".to_owned(), seed = None, robust = None,
    dispersion = "auto".to_owned(), layout = None, wavelength_um = None, theta_i_deg = None,
    terms = irpol::app::fit::AUTO_TERMS.to_owned()))]
#[allow(clippy::too_many_arguments)]
pub fn fit_materials(
    py: Python<'_>,
    inputs: Vec<PathBuf>,
    distribution: Option<String>,
    shadowing: String,
    free: Option<String>,
    fix: Option<String>,
    optimizer: String,
    seed: Option<u64>,
    robust: Option<String>,
    dispersion: String,
    layout: Option<PathBuf>,
    wavelength_um: Option<f64>,
    theta_i_deg: Option<Vec<f64>>,
    terms: String,
) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let flags = FitFlags {
        distribution,
        shadowing,
        free,
        fix,
        optimizer,
        seed: seed.unwrap_or(FitFlags::default().seed),
        robust,
        dispersion,
        terms,
        cv: None,
        ..FitFlags::default()
    };
    let options = flags.options().map_err(raised)?;
    let reading = measurement_args(layout, wavelength_um, theta_i_deg)
        .read_options()
        .map_err(raised)?;
    let outcomes = py
        .detach(|| fit_inputs_with(&inputs, &reading, &options, &irpol::progress::Silent))
        .map_err(raised)?;
    outcomes.iter().map(|o| outcome_dict(py, o)).collect()
}

/// Mueller matrices as rows of 16 (row-major m00…m33).
fn mueller_rows<'py>(py: Python<'py>, muellers: &[Mueller]) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows: Vec<Vec<f64>> = muellers
        .iter()
        .map(|m| m.transpose().iter().copied().collect())
        .collect();
    Ok(PyArray2::from_vec2(py, &rows)?)
}

/// Normalized residuals as a (points, measured elements) array in the set's column order.
fn residual_rows<'py>(
    py: Python<'py>,
    residuals: &[f64],
    set: &MeasurementSet,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows: Vec<Vec<f64>> = residuals
        .chunks(set.elements.len())
        .map(<[f64]>::to_vec)
        .collect();
    Ok(PyArray2::from_vec2(py, &rows)?)
}

fn outcome_dict<'py>(py: Python<'py>, outcome: &MaterialFit) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let material = outcome.material();
    d.set_item("name", &material.name)?;
    d.set_item("material", PyMaterial::wrapping(material.clone()))?;
    let entry = PathBuf::from(format!("{}.toml", material.name));
    let toml = material.to_toml(&entry).map_err(raised)?;
    d.set_item("toml", toml)?;
    d.set_item("notes", outcome.notes())?;
    match outcome {
        MaterialFit::Grey(o) => {
            let fit = &o.chosen;
            d.set_item("kind", "grey")?;
            d.set_item("chi2", fit.chi2)?;
            d.set_item("observations", fit.observations)?;
            d.set_item("measurements", vec![set_dict(py, &o.measurement)?])?;
            let muellers = o.model_muellers().map_err(raised)?;
            d.set_item("model_mueller", vec![mueller_rows(py, &muellers)?])?;
            let residuals = o.normalized_residuals().map_err(raised)?;
            d.set_item(
                "normalized_residuals",
                vec![residual_rows(py, &residuals, &o.measurement)?],
            )?;
        }
        MaterialFit::Spectral(o) => {
            let fit = &o.chosen;
            d.set_item("kind", "spectral")?;
            d.set_item("chi2", fit.chi2)?;
            d.set_item("observations", fit.observations)?;
            let sets: PyResult<Vec<_>> = o.measurements.iter().map(|s| set_dict(py, s)).collect();
            d.set_item("measurements", sets?)?;
            let models: PyResult<Vec<_>> = fit
                .model_muellers
                .iter()
                .map(|m| mueller_rows(py, m))
                .collect();
            d.set_item("model_mueller", models?)?;
            let residuals: PyResult<Vec<_>> = fit
                .normalized_residuals
                .iter()
                .zip(&o.measurements)
                .map(|(r, set)| residual_rows(py, r, set))
                .collect();
            d.set_item("normalized_residuals", residuals?)?;
            d.set_item("n_errors", PyArray1::from_slice(py, &fit.n_errors))?;
            d.set_item("k_errors", PyArray1::from_slice(py, &fit.k_errors))?;
            d.set_item("rho_d_errors", PyArray1::from_slice(py, &fit.rho_d_errors))?;
        }
    }
    Ok(d)
}
