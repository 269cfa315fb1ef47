//! `irpol.Material`: one entry of the material library (docs/design.md §2.2), grey or spectral, read,
//! built from parameters or written exactly as the library does it.

use crate::errors::{bad_argument, raised};
use irpol::app::material_pbrdf;
use irpol::material::{Material, MaterialModel};
use irpol::pbrdf::Pbrdf;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyTuple;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

/// A pBRDF material: slope distribution and σ, q (shared across wavelengths), shadowing, and
/// N = n + ik and ρ_d, one value (grey) or one per table wavelength (spectral, µm, ascending).
#[pyclass(name = "Material", module = "irpol", frozen)]
pub struct PyMaterial {
    pub inner: Material,
    /// The pBRDF last evaluated, by wavelength (its bits; `None` for a grey material's own), kept
    /// with the tables it builds on its first evaluation (the Cauchy Smith factor's), so that a
    /// second `mueller` or `emissivity` call does not build them again.
    model: Mutex<Option<(Option<u64>, Arc<Pbrdf>)>>,
}

impl Clone for PyMaterial {
    fn clone(&self) -> Self {
        PyMaterial::wrapping(self.inner.clone())
    }
}

/// A number or a list of numbers as a TOML value of `[model]`.
fn one_or_many(value: &Bound<'_, PyAny>, name: &str) -> PyResult<toml::Value> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok(toml::Value::Float(x));
    }
    let many: Vec<f64> = value
        .extract()
        .map_err(|_| bad_argument(format!("{name} must be a number or a sequence of numbers")))?;
    Ok(toml::Value::Array(
        many.into_iter().map(toml::Value::Float).collect(),
    ))
}

fn floats<'py>(py: Python<'py>, values: &[f64]) -> Bound<'py, PyAny> {
    PyArray1::from_slice(py, values).into_any()
}

#[pymethods]
impl PyMaterial {
    /// Builds a material from its parameters, checked as a material file's `[model]` is.
    /// σ and q are dimensionless; n, k, ρ_d numbers (grey) or arrays over `wavelength_um` (µm).
    #[new]
    #[pyo3(signature = (*, sigma, n, k, distribution = "cauchy", q = None, shadowing = "smith",
        rho_d = None, wavelength_um = None, name = "material"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        sigma: f64,
        n: &Bound<'_, PyAny>,
        k: &Bound<'_, PyAny>,
        distribution: &str,
        q: Option<f64>,
        shadowing: &str,
        rho_d: Option<&Bound<'_, PyAny>>,
        wavelength_um: Option<&Bound<'_, PyAny>>,
        name: &str,
    ) -> PyResult<PyMaterial> {
        let mut table = toml::map::Map::new();
        table.insert("distribution".into(), distribution.into());
        table.insert("sigma".into(), sigma.into());
        if let Some(q) = q {
            table.insert("q".into(), q.into());
        }
        table.insert("shadowing".into(), shadowing.into());
        table.insert("n".into(), one_or_many(n, "n")?);
        table.insert("k".into(), one_or_many(k, "k")?);
        if let Some(rho_d) = rho_d {
            table.insert("rho_d".into(), one_or_many(rho_d, "rho_d")?);
        }
        let wavelength = match wavelength_um {
            Some(w) => one_or_many(w, "wavelength_um")?,
            None if table["n"].is_array() => {
                return Err(bad_argument(
                    "a spectral material (n, k arrays) needs wavelength_um, one per value",
                ))
            }
            // A grey material is the same at every wavelength; this only records one.
            None => toml::Value::Float(DEFAULT_GREY_WAVELENGTH_UM),
        };
        table.insert("wavelength_um".into(), wavelength);
        let model: MaterialModel =
            toml::Value::Table(table)
                .try_into()
                .map_err(|e: toml::de::Error| {
                    bad_argument(format!("invalid material: {}", e.message()))
                })?;
        model
            .validate()
            .map_err(|e| bad_argument(format!("the model is invalid: {e}")))?;
        Ok(PyMaterial::wrapping(Material {
            name: name.to_owned(),
            tool_version: format!("irpol {}", irpol::VERSION),
            model,
            fit: None,
        }))
    }

    /// Reads a material TOML (as `irpol fit` writes them). Raises OSError or ValueError.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<PyMaterial> {
        Material::load(&path)
            .map(PyMaterial::wrapping)
            .map_err(raised)
    }

    /// A material from the text of a material TOML.
    #[staticmethod]
    fn from_toml(text: &str) -> PyResult<PyMaterial> {
        Material::from_toml(text, std::path::Path::new("<text>"))
            .map(PyMaterial::wrapping)
            .map_err(raised)
    }

    /// The material TOML text, with its explanatory comments, as `save` writes it.
    fn to_toml(&self) -> PyResult<String> {
        let path = PathBuf::from(format!("{}.toml", self.inner.name));
        self.inner.to_toml(&path).map_err(raised)
    }

    /// Writes the material TOML atomically (temporary file + rename).
    fn save(&self, path: PathBuf) -> PyResult<()> {
        self.inner.save(&path).map_err(raised)
    }

    /// The grey material at `wavelength_um` (µm): a spectral table interpolated linearly, a grey
    /// material itself. Raises ValueError outside a spectral table.
    fn at(&self, wavelength_um: f64) -> PyResult<PyMaterial> {
        let spec = self.inner.at(wavelength_um).map_err(raised)?;
        Ok(PyMaterial::wrapping(Material {
            model: MaterialModel::Grey(spec),
            fit: None,
            ..self.inner.clone()
        }))
    }

    #[getter]
    fn name(&self) -> &str {
        &self.inner.name
    }

    #[getter]
    fn distribution(&self) -> &'static str {
        self.inner.model.distribution().name()
    }

    #[getter]
    fn shadowing(&self) -> &'static str {
        self.inner.model.shadowing().name()
    }

    /// Slope parameter σ (dimensionless).
    #[getter]
    fn sigma(&self) -> f64 {
        self.inner.model.distribution().sigma()
    }

    /// Cauchy exponent q, or None for the Gaussian distribution.
    #[getter]
    fn q(&self) -> Option<f64> {
        self.inner
            .model
            .distribution()
            .parameter(irpol::pbrdf::Parameter::Q)
    }

    #[getter]
    fn is_spectral(&self) -> bool {
        self.inner.model.spectral().is_some()
    }

    /// Real part of the refractive index: a float (grey) or an array over `wavelength_um`.
    #[getter]
    fn n<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.per_wavelength(py, |m| m.n, |s| &s.n)
    }

    /// Extinction coefficient k: a float (grey) or an array over `wavelength_um`.
    #[getter]
    fn k<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.per_wavelength(py, |m| m.k, |s| &s.k)
    }

    /// Diffuse reflectance ρ_d: a float (grey) or an array over `wavelength_um`.
    #[getter]
    fn rho_d<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.per_wavelength(py, |m| m.rho_d, |s| &s.rho_d)
    }

    /// µm: where a grey material was measured, or a spectral material's table wavelengths.
    #[getter]
    fn wavelength_um<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.per_wavelength(py, |m| m.wavelength_um, |s| &s.wavelength_um)
    }

    /// The fit record (`[fit]` of the TOML) as JSON text, or None for a material not fitted.
    #[getter]
    fn fit_json(&self) -> PyResult<Option<String>> {
        self.inner
            .fit
            .as_ref()
            .map(serde_json::to_string)
            .transpose()
            .map_err(|e| bad_argument(e.to_string()))
    }

    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let rebuild = py.get_type::<PyMaterial>().getattr("from_toml")?;
        Ok((rebuild, PyTuple::new(py, [self.to_toml()?])?))
    }

    /// Every model parameter: `Material(name='paper_paint', distribution='cauchy', sigma=0.1,
    /// q=1.8, n=1.2, k=0.2, rho_d=0.0, shadowing='smith', wavelength_um=9.925)`; a spectral
    /// material gives the range of n, k and ρ_d over its table.
    fn __repr__(&self) -> String {
        let m = &self.inner.model;
        let q = self
            .q()
            .map_or(String::new(), |q| format!(", q={}", py_float(q)));
        let optics = match m {
            MaterialModel::Grey(g) => format!(
                "n={}, k={}, rho_d={}, shadowing={}{}, wavelength_um={}",
                py_float(g.n),
                py_float(g.k),
                py_float(g.rho_d),
                py_str(m.shadowing().name()),
                volume_terms(g),
                py_float(g.wavelength_um)
            ),
            MaterialModel::Spectral(s) => {
                let (a, b) = s.range_um();
                format!(
                    "n={}, k={}, rho_d={}, shadowing={}, wavelength_um={}–{} ({} wavelengths)",
                    span(&s.n),
                    span(&s.k),
                    span(&s.rho_d),
                    py_str(m.shadowing().name()),
                    py_float(a),
                    py_float(b),
                    s.wavelength_um.len()
                )
            }
        };
        format!(
            "Material(name={}, distribution={}, sigma={}{q}, {optics})",
            py_str(&self.inner.name),
            py_str(m.distribution().name()),
            py_float(m.distribution().sigma()),
        )
    }
}

/// The volume-scattering terms of docs/design.md §1.10 as a repr lists them (nothing for a
/// model without them): `, facet='internal', rho_s=0.96, d=0.027, n_sub=1.04, d_c=-0.019`.
fn volume_terms(model: &irpol::material::ModelSpec) -> String {
    let mut text = String::new();
    if !model.facet.is_external() {
        text.push_str(&format!(", facet={}", py_str(model.facet.name())));
    }
    for (parameter, value) in model.subsurface_lobes().iter().flat_map(|s| s.keys()) {
        text.push_str(&format!(", {parameter}={}", py_float(value)));
    }
    text
}

/// A string as Python's repr writes it (in single quotes, control characters escaped).
fn py_str(text: &str) -> String {
    let mut out = String::from("'");
    for c in text.chars() {
        match c {
            '\\' => out.push_str("\\\\"),
            '\'' => out.push_str("\\'"),
            c if c.is_control() => out.extend(c.escape_default()),
            c => out.push(c),
        }
    }
    out.push('\'');
    out
}

/// A float as Python's repr writes it: shortest round-trip digits, an exponent below 1e-4 and
/// from 1e16 (Rust's `{}` never uses one, so 3.2e-6 would read "0.0000032").
fn py_float(x: f64) -> String {
    if x == 0.0 || (1e-4..1e16).contains(&x.abs()) || !x.is_finite() {
        let text = format!("{x}");
        if x.is_finite() && !text.contains('.') {
            text + ".0"
        } else {
            text
        }
    } else {
        let text = format!("{x:e}");
        let (mantissa, exponent) = text.split_once('e').unwrap_or((&text, "0"));
        let exponent: i32 = exponent.parse().unwrap_or(0);
        let sign = if exponent < 0 { '-' } else { '+' };
        format!("{mantissa}e{sign}{:02}", exponent.abs())
    }
}

/// "min–max" of a spectral table's values to four significant digits ("0.5178–2.873"), or the
/// one value they all share.
fn span(values: &[f64]) -> String {
    let four = |x: f64| py_float(format!("{x:.3e}").parse().unwrap_or(x));
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo == hi {
        four(lo)
    } else {
        format!("{}–{}", four(lo), four(hi))
    }
}

/// Where a grey material built from parameters says it was measured (µm): the middle of the LWIR
/// band. It changes no value: a grey material is the same at every wavelength.
const DEFAULT_GREY_WAVELENGTH_UM: f64 = 10.0;

impl PyMaterial {
    pub(crate) fn wrapping(inner: Material) -> Self {
        PyMaterial {
            inner,
            model: Mutex::new(None),
        }
    }

    /// The material's pBRDF as `irpol eval --material` builds it (at `wavelength_um` for a
    /// spectral material), built once per wavelength in a row of calls.
    pub(crate) fn pbrdf(&self, wavelength_um: Option<f64>) -> PyResult<Arc<Pbrdf>> {
        let key = wavelength_um.map(f64::to_bits);
        let mut kept = self.model.lock().unwrap_or_else(|p| p.into_inner());
        if let Some((k, model)) = kept.as_ref() {
            if *k == key {
                return Ok(Arc::clone(model));
            }
        }
        let model = Arc::new(material_pbrdf(&self.inner, wavelength_um, None).map_err(raised)?);
        *kept = Some((key, Arc::clone(&model)));
        Ok(model)
    }

    fn per_wavelength<'py>(
        &self,
        py: Python<'py>,
        grey: impl Fn(&irpol::material::ModelSpec) -> f64,
        spectral: impl Fn(&irpol::material::SpectralModel) -> &Vec<f64>,
    ) -> Bound<'py, PyAny> {
        match &self.inner.model {
            MaterialModel::Grey(m) => grey(m).into_pyobject(py).expect("a float").into_any(),
            MaterialModel::Spectral(s) => floats(py, spectral(s)),
        }
    }
}
