//! Thermal runs solved once and saved, for sweeps (docs/design.md §2.7): the keys that tell which
//! renders share a run, the run solved and saved, and a scene at an instant of a saved run —
//! bit for bit the scene [`scene_to_render`] builds by solving the run itself.

use super::render::{scene_to_render, solution_instant};
use super::AppError;
use crate::progress::Progress;
use crate::scene::{load_scene_text, Scene};
use crate::thermal_scene::saved::{solution_for, solve_and_save, thermal_keys};
use crate::thermal_scene::{SavedSolutionError, ThermalKey};
use std::path::Path;

/// `error` with the scene's path on a failed run, as [`super::render::solve`] words it.
fn in_scene(scene_path: &Path, error: SavedSolutionError) -> AppError {
    match error {
        SavedSolutionError::Run(source) => AppError::ThermalRun {
            path: scene_path.to_owned(),
            source: Box::new(source),
        },
        other => AppError::SavedSolution(Box::new(other)),
    }
}

/// The loaded scene of `path` (from `text`), which must have `[thermal]`.
fn thermal_scene(path: &Path, text: &str) -> Result<Scene, AppError> {
    let scene = load_scene_text(path, text)?;
    if scene.thermal.is_none() {
        return Err(AppError::InstantNeedsThermal(path.to_owned()));
    }
    Ok(scene)
}

/// The run key of the scene of `path` (read from `text`) at each of `times_s`
/// ([`crate::thermal_scene::saved`]): renders with equal keys can share one saved run.
pub fn scene_thermal_keys(
    path: &Path,
    text: &str,
    times_s: &[f64],
) -> Result<Vec<ThermalKey>, AppError> {
    let scene = thermal_scene(path, text)?;
    thermal_keys(&scene, times_s).map_err(|e| in_scene(path, e.into()))
}

/// Solves the thermal run of the scene of `path` (read from `text`) recording `times_s`, which
/// must share one key, and saves it to `file` (kept if it already holds that run with those
/// instants). Returns the key.
pub fn solve_and_save_scene(
    path: &Path,
    text: &str,
    times_s: &[f64],
    file: &Path,
    progress: &dyn Progress,
) -> Result<ThermalKey, AppError> {
    let scene = thermal_scene(path, text)?;
    solve_and_save(&scene, times_s, file, progress).map_err(|e| in_scene(path, e))
}

/// [`scene_to_render`] with the temperatures of the run saved in `file` (by
/// [`solve_and_save_scene`]) when `file` is given: the same scene bit for bit, or refused if
/// `file` is missing, damaged, or the run of other inputs.
pub fn scene_to_render_from(
    path: &Path,
    text: &str,
    time_s: Option<f64>,
    file: Option<&Path>,
    progress: &dyn Progress,
) -> Result<Scene, AppError> {
    let Some(file) = file else {
        return scene_to_render(path, text, time_s, progress);
    };
    let scene = load_scene_text(path, text)?;
    let time_s = match (time_s, scene.thermal.is_some()) {
        (Some(t), true) => t,
        (None, true) => return Err(AppError::ThermalNeedsInstant(path.to_owned())),
        (_, false) => return Err(AppError::InstantNeedsThermal(path.to_owned())),
    };
    let solution = solution_for(file, &scene, time_s).map_err(|e| in_scene(path, e))?;
    solution_instant(&scene, &solution, time_s)
}
