//! `irpol thermal`: a scene's temperatures over its `[thermal]` run (docs/design.md §1.8, §2.6).

use super::render::{render_solution_at, TimedRender};
use super::saved_thermal::{obtain_run, RunSource, SavedRun};
use super::thermal_instant::solve;
use super::AppError;
use crate::output::thermal::{write_thermal_outputs, ThermalSummary};
use crate::progress::Progress;
use crate::scene::{load_scene, Scene};
use crate::thermal_scene::ThermalSolution;
use std::path::Path;
use std::time::Instant;

/// Loads the scene, takes its thermal run from `saved` or solves it ([`obtain_run`]), and writes
/// `temperatures.csv`, the per-step PLYs, the plot and `summary.json` into `out_dir` as one set.
/// A bad scene writes nothing. Returns the summary and where the run came from.
pub fn run_thermal(
    scene_path: &Path,
    out_dir: &Path,
    saved: SavedRun,
    progress: &dyn Progress,
) -> Result<(ThermalSummary, RunSource), AppError> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let (solution, source) = obtain_run(&scene, scene_path, &[], saved, progress)?;
    let seconds = start.elapsed().as_secs_f64();
    let summary = write_thermal(&scene, &solution, out_dir, seconds)?;
    Ok((summary, source))
}

/// The thermal run written to `thermal_out` and rendered at `times` into `render_out`, from one
/// solve (the demo's day of the car).
pub fn run_thermal_and_render(
    scene_path: &Path,
    thermal_out: &Path,
    render_out: &Path,
    times: &[f64],
    progress: &dyn Progress,
) -> Result<(ThermalSummary, Vec<TimedRender>), AppError> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let solution = solve(&scene, scene_path, times, progress)?;
    let seconds = start.elapsed().as_secs_f64();
    let summary = write_thermal(&scene, &solution, thermal_out, seconds)?;
    let renders = render_solution_at(&scene, &solution, times, render_out, progress)?;
    Ok((summary, renders))
}

fn write_thermal(
    scene: &Scene,
    solution: &ThermalSolution,
    out_dir: &Path,
    seconds: f64,
) -> Result<ThermalSummary, AppError> {
    write_thermal_outputs(scene, solution, out_dir, seconds).map_err(|source| AppError::Write {
        path: out_dir.to_owned(),
        source,
    })
}
