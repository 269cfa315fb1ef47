//! `irpol thermal`: a scene's temperatures over its `[thermal]` run (docs/design.md §1.8, §2.6).

use super::render::{render_solution_at, TimedRender};
use crate::output::thermal::{write_thermal_outputs, ThermalSummary};
use crate::progress::Progress;
use crate::scene::load_scene;
use crate::thermal_scene::solve_scene;
use anyhow::Context;
use std::path::Path;
use std::time::Instant;

/// Loads the scene, runs its thermal model and writes `temperatures.csv`, the per-step PLYs, the
/// plot and `summary.json` into `out_dir` as one set. A bad scene writes nothing.
pub fn run_thermal(
    scene_path: &Path,
    out_dir: &Path,
    progress: &dyn Progress,
) -> anyhow::Result<ThermalSummary> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let solution = solve_scene(&scene, &[], progress)
        .with_context(|| format!("{}: thermal run", scene_path.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    write_thermal_outputs(&scene, &solution, out_dir, seconds)
        .with_context(|| format!("{}: cannot write", out_dir.display()))
}

/// The thermal run written to `thermal_out` and rendered at `times` into `render_out`, from one
/// solve (the demo's day of the car).
pub fn run_thermal_and_render(
    scene_path: &Path,
    thermal_out: &Path,
    render_out: &Path,
    times: &[f64],
    progress: &dyn Progress,
) -> anyhow::Result<(ThermalSummary, Vec<TimedRender>)> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let solution = solve_scene(&scene, times, progress)
        .with_context(|| format!("{}: thermal run", scene_path.display()))?;
    let seconds = start.elapsed().as_secs_f64();
    let summary = write_thermal_outputs(&scene, &solution, thermal_out, seconds)
        .with_context(|| format!("{}: cannot write", thermal_out.display()))?;
    let renders = render_solution_at(&scene, &solution, times, render_out, progress)?;
    Ok((summary, renders))
}
