//! Measurement CSVs (docs/design.md §2.1) read and validated by the library's reader, as numpy arrays.

use crate::errors::raised;
use irpol::app::{MeasurementArgs, SelectionArgs};
use irpol::measure::{MeasurementSet, MUELLER_ELEMENT_NAMES};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;

/// Every set of one measurement file, one per wavelength (ascending), each as a dict of arrays
/// (angles in degrees, Mueller elements and their 1-σ uncertainties in sr⁻¹, NaN where the file
/// gives no uncertainty) and metadata. `layout` (an instrument layout TOML), `wavelength_um` and
/// `theta_i_deg` are `irpol fit`'s `--layout`, `--wavelength` and `--theta-i`.
#[pyfunction]
#[pyo3(signature = (path, *, layout = None, wavelength_um = None, theta_i_deg = None))]
pub fn read_measurement_sets(
    py: Python<'_>,
    path: PathBuf,
    layout: Option<PathBuf>,
    wavelength_um: Option<f64>,
    theta_i_deg: Option<Vec<f64>>,
) -> PyResult<Vec<Bound<'_, PyDict>>> {
    let sets = read_sets(py, &path, layout, wavelength_um, theta_i_deg)?;
    sets.iter().map(|set| set_dict(py, set)).collect()
}

/// The sets of `path` as the command line's reading flags of the same meaning read them, with
/// the GIL released.
pub fn read_sets(
    py: Python<'_>,
    path: &std::path::Path,
    layout: Option<PathBuf>,
    wavelength_um: Option<f64>,
    theta_i_deg: Option<Vec<f64>>,
) -> PyResult<Vec<MeasurementSet>> {
    let reading = measurement_args(layout, wavelength_um, theta_i_deg)
        .read_options()
        .map_err(raised)?;
    py.detach(|| reading.read(path)).map_err(raised)
}

/// The command line's reading flags from the Python arguments of the same meaning.
pub fn measurement_args(
    layout: Option<PathBuf>,
    wavelength_um: Option<f64>,
    theta_i_deg: Option<Vec<f64>>,
) -> MeasurementArgs {
    MeasurementArgs {
        layout,
        selection: SelectionArgs {
            wavelength_um,
            theta_i_deg: theta_i_deg.unwrap_or_default(),
        },
        angles: None,
    }
}

pub fn set_dict<'py>(py: Python<'py>, set: &MeasurementSet) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    let rows = &set.points;
    let angle = |k: usize| PyArray1::from_iter(py, rows.angles().iter().map(|a| a[k]));
    d.set_item("material", &set.material)?;
    d.set_item("wavelength_um", set.wavelength_um)?;
    d.set_item("source", &set.source)?;
    d.set_item("sha256", &set.sha256)?;
    d.set_item("metadata", set.metadata.clone())?;
    let names: Vec<&str> = set
        .elements
        .iter()
        .map(|&e| MUELLER_ELEMENT_NAMES[e])
        .collect();
    d.set_item("elements", names)?;
    d.set_item("theta_i_deg", angle(0))?;
    d.set_item("phi_i_deg", angle(1))?;
    d.set_item("theta_r_deg", angle(2))?;
    d.set_item("phi_r_deg", angle(3))?;
    // The values block is point-major already: one copy, viewed as rows × elements.
    let shape = [rows.len(), rows.width()];
    let values = PyArray1::from_slice(py, rows.values()).reshape(shape)?;
    let uncertainties = rows
        .iter()
        .flat_map(|p| p.uncertainties().map(|u| u.unwrap_or(f64::NAN)));
    let uncertainties = PyArray1::from_iter(py, uncertainties).reshape(shape)?;
    d.set_item("values", values)?;
    d.set_item("uncertainties", uncertainties)?;
    d.set_item("line", PyArray1::from_slice(py, rows.lines()))?;
    let merged: Vec<PathBuf> = set.merged.iter().map(|m| m.path.clone()).collect();
    d.set_item("merged", merged)?;
    d.set_item("notes", set.notes.clone())?;
    Ok(d)
}
