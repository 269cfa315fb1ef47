//! Thermal runs solved once and saved, for sweeps (docs/design.md §2.7): the run keys of a scene's
//! instants, and the run solved and saved to a file that `render_scene(thermal_solution=…)` reads.

use crate::pools::detached_on;
use crate::rendering::{apply, in_python_terms, Patch};
use crate::scene_patch::{scene_text, Missing};
use irpol::app::saved_thermal::{scene_thermal_keys, solve_and_save_scene};
use irpol::progress::Silent;
use pyo3::prelude::*;
use std::path::PathBuf;

/// The run key of the scene (with `patch` applied, as `render_scene` applies it) at each of
/// `times` (s from thermal.start_utc): renders whose keys are equal share one saved run.
#[pyfunction]
#[pyo3(signature = (scene, times, patch = None))]
pub fn thermal_keys<'py>(
    py: Python<'py>,
    scene: PathBuf,
    times: Vec<f64>,
    patch: Option<Patch<'py>>,
) -> PyResult<Vec<String>> {
    let text = apply(&scene, scene_text(&scene)?, patch, Missing::Refuse)?;
    let keys = py
        .detach(|| scene_thermal_keys(&scene, &text, &times))
        .map_err(in_python_terms)?;
    Ok(keys.into_iter().map(|k| k.as_str().to_owned()).collect())
}

/// Solves the scene's thermal run (with `patch` applied) recording `times`, which must share one
/// key, and saves it to `out` atomically (kept when `out` already holds that run with those
/// instants). Returns the key. `threads`: solve on a pool of that many threads instead of
/// rayon's global pool.
#[pyfunction]
#[pyo3(signature = (scene, times, out, patch = None, threads = None))]
pub fn solve_thermal<'py>(
    py: Python<'py>,
    scene: PathBuf,
    times: Vec<f64>,
    out: PathBuf,
    patch: Option<Patch<'py>>,
    threads: Option<usize>,
) -> PyResult<String> {
    let text = apply(&scene, scene_text(&scene)?, patch, Missing::Refuse)?;
    let key = detached_on(py, threads, || {
        solve_and_save_scene(&scene, &text, &times, &out, &Silent)
    })?
    .map_err(in_python_terms)?;
    Ok(key.as_str().to_owned())
}
