//! `irpol render` in memory: a scene file (optionally with values replaced, and at an instant of
//! its thermal run, solved here or read from a saved run) rendered to numpy images; with `out`,
//! also every file the command writes.

use crate::errors::{bad_argument, raised};
use crate::scene_patch::{patched, scene_text, toml_value, Missing};
use irpol::app::saved_thermal::scene_to_render_from;
use irpol::app::AppError;
use irpol::output::{write_outputs, Channel};
use irpol::progress::Silent;
use irpol::render::render;
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::time::Instant;

/// What a render returns before it becomes numpy arrays.
struct Images {
    width: usize,
    height: usize,
    channels: Vec<(&'static str, Vec<f32>)>,
    summary_json: Option<String>,
}

fn render_images(
    scene: &std::path::Path,
    text: &str,
    time_s: Option<f64>,
    thermal_solution: Option<&std::path::Path>,
    out: Option<&std::path::Path>,
) -> Result<Images, AppError> {
    let start = Instant::now();
    let loaded = scene_to_render_from(scene, text, time_s, thermal_solution, &Silent)?;
    let rendered = render(&loaded, &Silent)?;
    let image = &rendered.image;
    let mut channels: Vec<(&'static str, Vec<f32>)> = Channel::ALL
        .iter()
        .map(|&c| (c.name(), image.channel(c)))
        .collect();
    let stderr: Vec<f32> = image.standard_error.iter().map(|e| e[0] as f32).collect();
    channels.push(("stderr_S0", stderr));
    let summary_json = match out {
        Some(dir) => {
            let summary = write_outputs(&loaded, &rendered, dir, start)?;
            let json =
                serde_json::to_string(&summary).map_err(|e| AppError::invalid(e.to_string()))?;
            Some(json)
        }
        None => None,
    };
    Ok(Images {
        width: image.width,
        height: image.height,
        channels,
        summary_json,
    })
}

/// `error` raised as [`raised`] does, except that the refusals naming the command line's
/// `--time` flags name the keyword `time_s` of `irpol.render` instead.
pub(crate) fn in_python_terms(error: AppError) -> PyErr {
    match error {
        AppError::ThermalNeedsInstant(path) => bad_argument(format!(
            "{}: has a [thermal] section: say when to render it with time_s=SECONDS \
             (seconds from thermal.start_utc)",
            path.display()
        )),
        AppError::InstantNeedsThermal(path) => bad_argument(format!(
            "{}: time_s needs temperatures from the thermal model, but the scene has no \
             [thermal] section",
            path.display()
        )),
        other => raised(other),
    }
}

/// Dotted scene keys and the values to give them.
pub(crate) type Patch<'py> = Vec<(String, Bound<'py, PyAny>)>;

pub(crate) fn apply(
    scene: &std::path::Path,
    text: String,
    patch: Option<Patch<'_>>,
    missing: Missing,
) -> PyResult<String> {
    let Some(patch) = patch.filter(|p| !p.is_empty()) else {
        return Ok(text);
    };
    let values: PyResult<Vec<(String, toml_edit::Value)>> = patch
        .iter()
        .map(|(k, v)| Ok((k.clone(), toml_value(v)?)))
        .collect();
    patched(scene, &text, &values?, missing).map_err(|e| bad_argument(e.to_string()))
}

/// Renders `scene` with `patch` (dotted scene keys, which must exist, → values) and then
/// `overrides` (the same, a missing last key added) applied to its text; `time_s` is the instant
/// (s from thermal.start_utc) of a scene with [thermal], its temperatures from the run saved in
/// `thermal_solution` (by `solve_thermal`) when given. Returns channel name → float32 image
/// (rows from the top), plus "summary" (JSON text) when `out` is given.
#[pyfunction]
#[pyo3(signature = (scene, patch = None, overrides = None, time_s = None, out = None,
                    thermal_solution = None))]
pub fn render_scene<'py>(
    py: Python<'py>,
    scene: PathBuf,
    patch: Option<Patch<'py>>,
    overrides: Option<Patch<'py>>,
    time_s: Option<f64>,
    out: Option<PathBuf>,
    thermal_solution: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    let text = apply(&scene, scene_text(&scene)?, patch, Missing::Refuse)?;
    let text = apply(&scene, text, overrides, Missing::Create)?;
    let solution = thermal_solution.as_deref();
    let images = py
        .detach(|| render_images(&scene, &text, time_s, solution, out.as_deref()))
        .map_err(in_python_terms)?;
    let d = PyDict::new(py);
    for (name, data) in images.channels {
        let array = PyArray1::from_vec(py, data).reshape([images.height, images.width])?;
        d.set_item(name, array)?;
    }
    if let Some(json) = images.summary_json {
        d.set_item("summary", json)?;
    }
    Ok(d)
}
