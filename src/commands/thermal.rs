//! `irpol thermal`: a scene's temperatures over its `[thermal]` run (DESIGN §1.8, §2.6).

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
