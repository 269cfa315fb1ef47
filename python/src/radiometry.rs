//! Band radiance of a blackbody and its inverse, the brightness temperature (docs/design.md §1.5), over
//! a sensor band with a flat response.

use crate::errors::bad_argument;
use irpol::optics::{valid_temperature, Band, MAX_TEMPERATURE_K};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use rayon::prelude::*;

fn band(band_um: (f64, f64)) -> PyResult<Band> {
    Band::new(band_um.0, band_um.1, None).map_err(|e| bad_argument(e.to_string()))
}

/// L_bb(T) = ∫ B_λ(T) dλ over the band, W·m⁻²·sr⁻¹, at each temperature (K).
#[pyfunction]
pub fn band_radiance_flat<'py>(
    py: Python<'py>,
    temperature_k: PyReadonlyArray1<'py, f64>,
    band_um: (f64, f64),
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let band = band(band_um)?;
    let temperatures = temperature_k.as_slice()?;
    if let Some(&t) = temperatures.iter().find(|&&t| !valid_temperature(t)) {
        return Err(bad_argument(format!(
            "temperature {t} K is invalid: it must be finite and within [0, {MAX_TEMPERATURE_K}] K"
        )));
    }
    let radiance: Vec<f64> =
        py.detach(|| temperatures.par_iter().map(|&t| band.radiance(t)).collect());
    Ok(PyArray1::from_vec(py, radiance))
}

/// The brightness temperature (K) of each band radiance (W·m⁻²·sr⁻¹): L_bb(T) = L.
#[pyfunction]
pub fn brightness_temperature_flat<'py>(
    py: Python<'py>,
    radiance: PyReadonlyArray1<'py, f64>,
    band_um: (f64, f64),
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let band = band(band_um)?;
    let radiances = radiance.as_slice()?;
    let temperatures: Result<Vec<f64>, _> = py.detach(|| {
        radiances
            .par_iter()
            .map(|&l| band.brightness_temperature(l))
            .collect()
    });
    let temperatures = temperatures.map_err(|e| bad_argument(e.to_string()))?;
    Ok(PyArray1::from_vec(py, temperatures))
}
