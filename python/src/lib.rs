//! `irpol._irpol`, the compiled half of the `irpol` Python package: numpy arrays in, the irpol
//! library's results out. Nothing here computes physics; every function converts its arguments,
//! calls the library (with the GIL released for the heavy part) and converts the result back.
//! The Python half (`python/irpol/`) broadcasts arrays and wraps results in dataclasses.

mod errors;
mod fitting;
mod interop;
mod material;
mod measurements;
mod model;
mod pools;
mod radiometry;
mod rendering;
mod scene_patch;
mod thermal;
mod validation;

use pyo3::prelude::*;

#[pymodule]
fn _irpol(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_class::<material::PyMaterial>()?;
    m.add_function(wrap_pyfunction!(model::mueller_flat, m)?)?;
    m.add_function(wrap_pyfunction!(model::emissivity_flat, m)?)?;
    m.add_function(wrap_pyfunction!(radiometry::band_radiance_flat, m)?)?;
    m.add_function(wrap_pyfunction!(
        radiometry::brightness_temperature_flat,
        m
    )?)?;
    m.add_function(wrap_pyfunction!(measurements::read_measurement_sets, m)?)?;
    m.add_function(wrap_pyfunction!(fitting::fit_materials, m)?)?;
    m.add_function(wrap_pyfunction!(rendering::render_scene, m)?)?;
    m.add_function(wrap_pyfunction!(scene_patch::check_scene_keys, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::thermal_keys, m)?)?;
    m.add_function(wrap_pyfunction!(thermal::solve_thermal, m)?)?;
    m.add_function(wrap_pyfunction!(validation::validate_material, m)?)?;
    m.add_function(wrap_pyfunction!(interop::export_pbsdf, m)?)?;
    m.add_function(wrap_pyfunction!(interop::read_pbsdf, m)?)?;
    Ok(())
}
