//! The pBRDF of a material evaluated at arrays of geometries: `mueller` (docs/design.md §1.3) and
//! `emissivity` (§1.4). The Python side broadcasts the angle arrays and hands over flat,
//! contiguous float64 arrays of one length; results come back flat (16 or 4 values per entry).

use crate::errors::bad_argument;
use crate::material::PyMaterial;
use irpol::optics::Direction;
use irpol::pbrdf::{GeometryColumns, HemisphereQuadrature, ModelError};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use rayon::prelude::*;

/// Geometries per parallel work unit (small enough to balance, large enough to amortize).
const CHUNK: usize = 4096;

/// Mueller BRDF elements (sr⁻¹, psps frames, row-major m00…m33) at each geometry (degrees).
#[pyfunction]
pub fn mueller_flat<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    wavelength_um: Option<f64>,
    theta_i: PyReadonlyArray1<'py, f64>,
    phi_i: PyReadonlyArray1<'py, f64>,
    theta_r: PyReadonlyArray1<'py, f64>,
    phi_r: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let model = material.pbrdf(wavelength_um)?;
    let (ti, pi, tr, pr) = (
        theta_i.as_slice()?,
        phi_i.as_slice()?,
        theta_r.as_slice()?,
        phi_r.as_slice()?,
    );
    let columns = GeometryColumns {
        theta_i: ti,
        phi_i: pi,
        theta_r: tr,
        phi_r: pr,
    };
    let count = columns
        .count()
        .ok_or_else(|| bad_argument("the angle arrays must have one length"))?;
    // Allocated by numpy, which asks the kernel for huge pages for large arrays: the page faults
    // of a fresh 128 MB output (1e6 geometries) otherwise cost about a third of the time.
    // SAFETY: every element is written below before the array is returned; on an error the
    // array is dropped unread.
    let array = unsafe { PyArray1::<f64>::new(py, [16 * count], false) };
    let out = unsafe { array.as_slice_mut() }.expect("a new array is contiguous");
    py.detach(|| {
        out.par_chunks_mut(16 * CHUNK)
            .enumerate()
            .try_for_each(|(chunk, values)| model.mueller_columns(&columns, chunk * CHUNK, values))
            .map_err(|_: ModelError| first_invalid(&columns))
    })
    .map_err(|e| bad_argument(e.to_string()))?;
    Ok(array)
}

/// The error of the first invalid geometry (parallel chunks fail in no particular order).
fn first_invalid(columns: &GeometryColumns<'_>) -> ModelError {
    (0..columns.theta_i.len())
        .find_map(|row| columns.directions(row).err())
        .expect("some geometry was invalid")
}

/// Polarized emissivity ε0…ε3 (dimensionless) at each emission zenith (degrees), as
/// `irpol emissivity` computes it; flat, 4 per angle.
#[pyfunction]
pub fn emissivity_flat<'py>(
    py: Python<'py>,
    material: &PyMaterial,
    wavelength_um: Option<f64>,
    theta: PyReadonlyArray1<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let model = material.pbrdf(wavelength_um)?;
    let thetas = theta.as_slice()?;
    for &t in thetas {
        Direction::from_degrees_checked("theta", t, 0.0)
            .map_err(|e| bad_argument(e.to_string()))?;
    }
    let radians: Vec<f64> = thetas.iter().map(|t| t.to_radians()).collect();
    let table = py.detach(|| model.emissivity_table(&radians, &HemisphereQuadrature::default()));
    let flat: Vec<f64> = table
        .iter()
        .flat_map(|e| [e[0], e[1], e[2], e[3]])
        .collect();
    Ok(PyArray1::from_vec(py, flat))
}
