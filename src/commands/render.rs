//! `irpol render`: scene file in, output files out.

use crate::output::{write_outputs, RenderSummary};
use crate::progress::Progress;
use crate::render::{render, RenderError};
use crate::scene::load_scene;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The default output folder `out/<scene stem>/` (DESIGN §4).
pub fn default_output_dir(scene_path: &Path) -> PathBuf {
    let stem = scene_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    Path::new("out").join(stem)
}

/// Loads the scene, renders it and writes every output into `out_dir`. A bad scene (or a
/// failed render) writes nothing.
pub fn render_scene(
    scene_path: &Path,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<RenderSummary, RenderError> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    let load = start.elapsed().as_secs_f64();
    let mut rendered = render(&scene, progress)?;
    rendered.timings.load = load;
    write_outputs(&scene, &rendered, out_dir, start)
}
