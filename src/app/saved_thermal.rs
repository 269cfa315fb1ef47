//! Thermal runs solved once and saved (docs/design.md §2.7): the keys that tell which renders
//! share a run, the run solved and saved, a scene at an instant of a saved run — bit for bit the
//! scene [`scene_to_render`] builds by solving the run itself — and the run `irpol thermal` and
//! `irpol render` take from the store of saved runs (`out/thermal/<key>.bin`) or solve into it.

use super::thermal_instant::{scene_to_render, solution_instant, solve};
use super::AppError;
use crate::progress::Progress;
use crate::scene::{load_scene_text, Scene};
use crate::thermal_scene::saved::{
    load_or_solve, run_key, solution_for, solution_recording, solve_and_save, thermal_keys,
    RunOrigin,
};
use crate::thermal_scene::{SavedSolutionError, ThermalKey, ThermalSolution};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The folder where `irpol thermal` and `irpol render` writing into `out_dir` keep the thermal
/// runs they solve, each as `<key>.bin`, and look for a run before solving it: `thermal/`
/// beside `out_dir`, so the default folders `out/<stem>/` and `out/<stem>_thermal/` share
/// `out/thermal/`.
pub fn run_store_beside(out_dir: &Path) -> PathBuf {
    out_dir.parent().unwrap_or(Path::new("")).join("thermal")
}

/// Which saved thermal run a command may use.
#[derive(Clone, Copy, Debug)]
pub enum SavedRun<'a> {
    /// The run of the scene's key in this folder (`<key>.bin`) if it is there, else the run
    /// solved and saved there.
    Store(&'a Path),
    /// This file, refused unless it holds the scene's run with every instant asked for.
    File(&'a Path),
}

/// Where a command's thermal run came from: what its note tells the user.
#[derive(Debug)]
pub enum RunSource {
    /// Read from this file, solved by an earlier command.
    Reused(PathBuf),
    /// Solved here in `seconds`; saved to `saved` (`None`: the instants need separate runs, so
    /// no one key names the run); `ignored` is a file of the key that could not be used.
    Solved {
        seconds: f64,
        saved: Option<PathBuf>,
        ignored: Option<String>,
    },
}

/// The thermal run of `scene` (loaded from `scene_path`) recording `times_s` (none: the run on its
/// own grid), from `saved` or solved.
pub fn obtain_run(
    scene: &Scene,
    scene_path: &Path,
    times_s: &[f64],
    saved: SavedRun,
    progress: &dyn Progress,
) -> Result<(ThermalSolution, RunSource), AppError> {
    let start = Instant::now();
    let store = match saved {
        SavedRun::File(file) => {
            let solution =
                solution_recording(file, scene, times_s).map_err(|e| in_scene(scene_path, e))?;
            return Ok((solution, RunSource::Reused(file.to_owned())));
        }
        SavedRun::Store(store) => store,
    };
    let key = match run_key(scene, times_s) {
        Ok(key) => key,
        Err(SavedSolutionError::SeparateRuns { .. }) => {
            let solution = solve(scene, scene_path, times_s, progress)?;
            let unsaved = RunSource::Solved {
                seconds: start.elapsed().as_secs_f64(),
                saved: None,
                ignored: None,
            };
            return Ok((solution, unsaved));
        }
        Err(error) => return Err(in_scene(scene_path, error)),
    };
    let file = store.join(format!("{key}.bin"));
    let (_, solution, origin) =
        load_or_solve(scene, times_s, &file, progress).map_err(|e| in_scene(scene_path, e))?;
    let source = match origin {
        RunOrigin::Reused => RunSource::Reused(file),
        RunOrigin::Solved { ignored } => RunSource::Solved {
            seconds: start.elapsed().as_secs_f64(),
            saved: Some(file),
            ignored: ignored.map(|e| super::one_line(&e)),
        },
    };
    Ok((solution, source))
}

/// `error` with the scene's path on a failed run, as [`super::thermal_instant::solve`] words it.
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
