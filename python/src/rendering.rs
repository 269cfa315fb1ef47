//! `irpol render` in memory: a scene file (optionally with values replaced, and at an instant of
//! its thermal run, solved here or read from a saved run) rendered to numpy images; with `out`,
//! also every file the command writes.

use crate::errors::{bad_argument, raised};
use crate::pools::detached_on;
use crate::scene_patch::{patched, scene_text, toml_value, Missing};
use irpol::app::saved_thermal::scene_to_render_from;
use irpol::app::AppError;
use irpol::output::{write_outputs, Channel};
use irpol::progress::Silent;
use irpol::render::{render_with_tables, RenderError, SceneTables};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, OnceLock};
use std::time::Instant;

/// How many tables a process keeps: a worker of a sweep gets items in no fixed order, and the
/// tables of a few scenes (a few MB each for the shipped ones) cost little memory.
const KEPT_TABLES: usize = 4;

/// The tables of the process's last renders, the most recently used last: a sweep's renders of
/// one scene from several viewpoints (or with other camera, sensor noise or sample settings)
/// build them once per worker process instead of once per item (docs/python.md).
fn kept_tables() -> &'static Mutex<Vec<Arc<SceneTables>>> {
    static KEPT: OnceLock<Mutex<Vec<Arc<SceneTables>>>> = OnceLock::new();
    KEPT.get_or_init(|| Mutex::new(Vec::new()))
}

/// The tables of `scene` and the seconds spent building them here: kept ones if built for the
/// same inputs (0 s), else built (outside the lock: renders in other threads go on) and kept.
fn shared_tables(scene: &irpol::scene::Scene) -> Result<(Arc<SceneTables>, f64), RenderError> {
    let kept = kept_tables();
    let candidates = kept.lock().unwrap_or_else(|p| p.into_inner()).clone();
    if let Some(tables) = candidates.into_iter().rev().find(|t| t.built_for(scene)) {
        let mut kept = kept.lock().unwrap_or_else(|p| p.into_inner());
        kept.retain(|t| !Arc::ptr_eq(t, &tables));
        kept.push(Arc::clone(&tables));
        return Ok((tables, 0.0));
    }
    let start = Instant::now();
    let tables = Arc::new(SceneTables::build(scene)?);
    let mut kept = kept.lock().unwrap_or_else(|p| p.into_inner());
    if kept.len() == KEPT_TABLES {
        kept.remove(0);
    }
    kept.push(Arc::clone(&tables));
    Ok((tables, start.elapsed().as_secs_f64()))
}

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
    let (tables, build_s) = shared_tables(&loaded)?;
    let mut rendered = render_with_tables(&loaded, &tables, &Silent)?;
    // The summary's stage timings, as `irpol render` counts them: a build here is part of this
    // render's tables and total, a shared build of neither.
    rendered.timings.tables += build_s;
    rendered.timings.total += build_s;
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
/// (rows from the top), plus "summary" (JSON text) when `out` is given. `threads`: render on a
/// pool of that many threads instead of rayon's global pool (the same images).
// The arguments are the keywords of `irpol.render` (python/irpol/_render.py).
#[allow(clippy::too_many_arguments)]
#[pyfunction]
#[pyo3(signature = (scene, patch = None, overrides = None, time_s = None, out = None,
                    thermal_solution = None, threads = None))]
pub fn render_scene<'py>(
    py: Python<'py>,
    scene: PathBuf,
    patch: Option<Patch<'py>>,
    overrides: Option<Patch<'py>>,
    time_s: Option<f64>,
    out: Option<PathBuf>,
    thermal_solution: Option<PathBuf>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyDict>> {
    let text = apply(&scene, scene_text(&scene)?, patch, Missing::Refuse)?;
    let text = apply(&scene, text, overrides, Missing::Create)?;
    let solution = thermal_solution.as_deref();
    let images = detached_on(py, threads, || {
        render_images(&scene, &text, time_s, solution, out.as_deref())
    })?
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
