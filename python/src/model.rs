//! The pBRDF of a material evaluated at arrays of geometries: `mueller` (docs/design.md §1.3) and
//! `emissivity` (§1.4). The Python side broadcasts the angle arrays and hands over flat,
//! contiguous float64 arrays of one length; results come back flat (16 or 4 values per entry).

use crate::errors::{bad_argument, raised};
use crate::material::PyMaterial;
use irpol::app::material_pbrdf;
use irpol::optics::{Direction, Mueller};
use irpol::pbrdf::{HemisphereQuadrature, ModelError, Pbrdf, ScatteringGeometry};
use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use rayon::prelude::*;

/// Geometries per parallel work unit (small enough to balance, large enough to amortize).
const CHUNK: usize = 4096;

/// The material's pBRDF as `irpol eval --material` builds it (at `wavelength_um` for a spectral
/// material).
fn pbrdf(material: &PyMaterial, wavelength_um: Option<f64>) -> PyResult<Pbrdf> {
    material_pbrdf(&material.inner, wavelength_um, None).map_err(raised)
}

/// One geometry's directions, checked as `irpol eval` checks a row (θ_r signed).
fn directions(ti: f64, pi: f64, tr: f64, pr: f64) -> Result<(Direction, Direction), ModelError> {
    Ok((
        Direction::from_degrees_checked("theta_i_deg", ti, pi)?,
        Direction::from_signed_degrees_checked("theta_r_deg", tr, pr)?,
    ))
}

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
    let model = pbrdf(material, wavelength_um)?;
    let (ti, pi, tr, pr) = (
        theta_i.as_slice()?,
        phi_i.as_slice()?,
        theta_r.as_slice()?,
        phi_r.as_slice()?,
    );
    let count = ti.len();
    if [pi.len(), tr.len(), pr.len()] != [count; 3] {
        return Err(bad_argument("the angle arrays must have one length"));
    }
    let angles = Angles { ti, pi, tr, pr };
    // Allocated by numpy, which asks the kernel for huge pages for large arrays: the page faults
    // of a fresh 128 MB output (1e6 geometries) otherwise cost about a third of the time.
    // SAFETY: every element is written below before the array is returned; on an error the
    // array is dropped unread.
    let array = unsafe { PyArray1::<f64>::new(py, [16 * count], false) };
    let out = unsafe { array.as_slice_mut() }.expect("a new array is contiguous");
    py.detach(|| {
        out.par_chunks_mut(16 * CHUNK)
            .enumerate()
            .try_for_each(|(chunk, values)| mueller_chunk(&model, &angles, chunk * CHUNK, values))
            .map_err(|_: ModelError| first_invalid(ti, pi, tr, pr))
    })
    .map_err(|e| bad_argument(e.to_string()))?;
    Ok(array)
}

/// The four flat angle arrays (degrees) of a `mueller` call.
struct Angles<'a> {
    ti: &'a [f64],
    pi: &'a [f64],
    tr: &'a [f64],
    pr: &'a [f64],
}

/// The value computed for the previous key, reused while the key repeats: in a broadcast grid
/// the outer angles repeat over the inner ones, so a direction and its Smith masking factor (an
/// incomplete beta function for the Cauchy distribution) are computed once per run of equal
/// keys. The same function of the same input: the results are bit for bit those of
/// [`Pbrdf::mueller`].
struct Repeated<K, V> {
    last: Option<(K, V)>,
}

impl<K: PartialEq + Copy, V: Copy> Repeated<K, V> {
    fn new() -> Self {
        Repeated { last: None }
    }

    fn get<E>(&mut self, key: K, compute: impl FnOnce() -> Result<V, E>) -> Result<V, E> {
        match self.last {
            Some((k, v)) if k == key => Ok(v),
            _ => {
                let v = compute()?;
                self.last = Some((key, v));
                Ok(v)
            }
        }
    }
}

/// Fills `values` (16 per geometry, row-major) from geometry `first` on.
fn mueller_chunk(
    model: &Pbrdf,
    a: &Angles<'_>,
    first: usize,
    values: &mut [f64],
) -> Result<(), ModelError> {
    let (mut incident, mut scattered) = (Repeated::new(), Repeated::new());
    let (mut masking_i, mut masking_r) = (Repeated::new(), Repeated::new());
    let masking = |cos: f64| Ok::<f64, ModelError>(model.masking(cos));
    for (j, m_out) in values.chunks_exact_mut(16).enumerate() {
        let i = first + j;
        let (ti, pi, tr, pr) = (a.ti[i], a.pi[i], a.tr[i], a.pr[i]);
        let w_i = incident.get((ti.to_bits(), pi.to_bits()), || {
            Direction::from_degrees_checked("theta_i_deg", ti, pi)
        })?;
        let w_r = scattered.get((tr.to_bits(), pr.to_bits()), || {
            Direction::from_signed_degrees_checked("theta_r_deg", tr, pr)
        })?;
        let m = match ScatteringGeometry::new(&w_i, &w_r) {
            Some(g) => {
                let (ci, cr) = (g.cos_incident(), g.cos_scattered());
                let mi = masking_i.get(ci.to_bits(), || masking(ci))?;
                let mr = masking_r.get(cr.to_bits(), || masking(cr))?;
                model.mueller_for_geometry(&g, mi, mr)
            }
            None => Mueller::zeros(),
        };
        for (slot, value) in m_out.iter_mut().zip(m.transpose().iter()) {
            *slot = *value;
        }
    }
    Ok(())
}

/// The error of the first invalid geometry (parallel chunks fail in no particular order).
fn first_invalid(ti: &[f64], pi: &[f64], tr: &[f64], pr: &[f64]) -> ModelError {
    (0..ti.len())
        .find_map(|i| directions(ti[i], pi[i], tr[i], pr[i]).err())
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
    let model = pbrdf(material, wavelength_um)?;
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
