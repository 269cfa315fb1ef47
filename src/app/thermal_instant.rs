//! A thermal scene at an instant of its run: the run solved (its failure naming the scene
//! file) and the scene given the temperatures of one recorded instant. Both the renders
//! ([`super::render`]) and the saved runs ([`super::saved_thermal`]) build on it.

use super::error::single_line;
use super::AppError;
use crate::progress::Progress;
use crate::scene::{load_scene_text, Scene};
use crate::thermal_scene::{scene_at, solve_scene, ThermalSolution};
use std::path::Path;

/// The thermal scene with the temperatures of `solution` at `time_s` (an instant of the run).
pub(super) fn solution_instant(
    scene: &Scene,
    solution: &ThermalSolution,
    time_s: f64,
) -> Result<Scene, AppError> {
    let index = solution
        .times_s
        .iter()
        .position(|&t| (t - time_s).abs() < 1e-6)
        .ok_or(AppError::NotAnInstant(time_s))?;
    scene_at(scene, solution, index).map_err(|e| AppError::SceneAt {
        path: scene.path.clone(),
        message: single_line(&e.to_string()),
    })
}

/// The scene of `path` read from `text` (the file's own, or changed by a caller such as the
/// Python bindings), as it is rendered: itself, or for a scene with `[thermal]` its thermal
/// solution at `time_s` seconds from `thermal.start_utc`. Refused as `irpol render` refuses a
/// thermal scene without an instant, or an instant without `[thermal]`.
pub fn scene_to_render(
    path: &Path,
    text: &str,
    time_s: Option<f64>,
    progress: &dyn Progress,
) -> Result<Scene, AppError> {
    let scene = load_scene_text(path, text)?;
    match (time_s, scene.thermal.is_some()) {
        (None, false) => Ok(scene),
        (None, true) => Err(AppError::ThermalNeedsInstant(path.to_owned())),
        (Some(_), false) => Err(AppError::InstantNeedsThermal(path.to_owned())),
        (Some(time_s), true) => {
            let solution = solve(&scene, path, &[time_s], progress)?;
            solution_instant(&scene, &solution, time_s)
        }
    }
}

/// The scene's thermal run (recording `times` too), its failure naming the scene file.
pub(crate) fn solve(
    scene: &Scene,
    scene_path: &Path,
    times: &[f64],
    progress: &dyn Progress,
) -> Result<ThermalSolution, AppError> {
    solve_scene(scene, times, progress).map_err(|source| AppError::ThermalRun {
        path: scene_path.to_owned(),
        source: Box::new(source),
    })
}
