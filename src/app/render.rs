//! `irpol render`: scene file in, output files out; for a scene with `[thermal]`, at instants of
//! its thermal run (docs/design.md §2.6).

use super::render_cost::{check_estimate, DEFAULT_MAX_MINUTES};
use super::saved_thermal::{obtain_run, RunSource, SavedRun};
pub use super::thermal_instant::scene_to_render;
use super::thermal_instant::solution_instant;
use super::AppError;
use crate::atomic::StagedFolder;
use crate::output::earlier_outputs::{EarlierOutputs, SERIES_MANIFEST};
use crate::output::figure::{animated_preview, SeriesPreview};
use crate::output::summary::RenderSummary;
use crate::output::{stage_outputs, write_outputs};
use crate::progress::Progress;
use crate::render::render;
use crate::scene::{load_scene, Scene};
use crate::thermal_scene::ThermalSolution;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The default output folder `out/<scene stem>/` (docs/design.md §4).
pub fn default_output_dir(scene_path: &Path) -> PathBuf {
    let stem = scene_path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    Path::new("out").join(stem)
}

/// Loads the scene, renders it and writes every output into `out_dir`. A bad scene (or a
/// failed render) writes nothing. A scene with `[thermal]` needs an instant
/// ([`render_scene_at`]).
pub fn render_scene(
    scene_path: &Path,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<RenderSummary, AppError> {
    render_scene_within(scene_path, out_dir, DEFAULT_MAX_MINUTES, progress)
}

/// [`render_scene`], refused before any work when its estimate ([`check_estimate`]) is over
/// `max_minutes`.
pub fn render_scene_within(
    scene_path: &Path,
    out_dir: &Path,
    max_minutes: f64,
    progress: &dyn Progress,
) -> Result<RenderSummary, AppError> {
    let start = Instant::now();
    let scene = load_scene(scene_path)?;
    if scene.thermal.is_some() {
        return Err(AppError::ThermalNeedsInstant(scene_path.to_owned()));
    }
    let estimate = check_estimate(&scene, 1, max_minutes)?;
    let mut summary = render_loaded(&scene, out_dir, progress, start)?;
    summary.warnings.extend(estimate.advice());
    Ok(summary)
}

fn render_loaded(
    scene: &Scene,
    out_dir: &Path,
    progress: &dyn Progress,
    start: Instant,
) -> Result<RenderSummary, AppError> {
    let load = start.elapsed().as_secs_f64();
    let mut rendered = render(scene, progress)?;
    rendered.timings.load = load;
    Ok(write_outputs(scene, &rendered, out_dir, start)?)
}

/// When to render a thermal scene.
#[derive(Clone, Debug)]
pub enum Instants {
    /// Seconds from `thermal.start_utc`; one instant renders into the output folder itself,
    /// several into numbered folders inside it plus an animated preview.
    Seconds(Vec<f64>),
    /// One RFC 3339 instant.
    Utc(String),
}

impl Instants {
    /// The instants `--time`, `--time-utc` or `--times` (`START:STOP:STEP`) give, if any.
    pub fn from_flags(
        time: Option<f64>,
        time_utc: Option<String>,
        times: Option<&str>,
    ) -> Result<Option<Instants>, AppError> {
        Ok(match (time, time_utc, times) {
            (Some(t), _, _) => Some(Instants::Seconds(vec![t])),
            (_, Some(text), _) => Some(Instants::Utc(text)),
            (_, _, Some(sweep)) => Some(Instants::Seconds(super::parse_sweep(sweep, "times")?)),
            _ => None,
        })
    }
}

/// One rendered instant.
pub struct TimedRender {
    pub time_s: f64,
    pub folder: PathBuf,
    pub summary: RenderSummary,
}

/// Takes the scene's thermal run recording the instants asked for from `saved` or solves it
/// ([`obtain_run`]), then renders the scene at each instant ([`render_solution_at`]). Returns
/// the renders and where the run came from.
pub fn render_scene_at(
    scene_path: &Path,
    out_dir: &Path,
    instants: &Instants,
    saved: SavedRun,
    progress: &dyn Progress,
) -> Result<(Vec<TimedRender>, RunSource), AppError> {
    render_scene_at_within(
        scene_path,
        out_dir,
        instants,
        DEFAULT_MAX_MINUTES,
        saved,
        progress,
    )
}

/// [`render_scene_at`], refused before the thermal run when the frames' estimate
/// ([`check_estimate`]) is over `max_minutes`.
pub fn render_scene_at_within(
    scene_path: &Path,
    out_dir: &Path,
    instants: &Instants,
    max_minutes: f64,
    saved: SavedRun,
    progress: &dyn Progress,
) -> Result<(Vec<TimedRender>, RunSource), AppError> {
    let scene = load_scene(scene_path)?;
    let setup = scene
        .thermal
        .as_deref()
        .ok_or_else(|| AppError::InstantNeedsThermal(scene_path.to_owned()))?;
    let times = match instants {
        Instants::Seconds(times) => times.clone(),
        Instants::Utc(text) => {
            let at = crate::emitter::parse_time_utc(text).map_err(AppError::TimeFlag)?;
            vec![(at - setup.site.start_utc).num_milliseconds() as f64 / 1000.0]
        }
    };
    let estimate = check_estimate(&scene, times.len(), max_minutes)?;
    let (solution, source) = obtain_run(&scene, scene_path, &times, saved, progress)?;
    let mut renders = render_solution_at(&scene, &solution, &times, out_dir, progress)?;
    if let Some(first) = renders.first_mut() {
        first.summary.warnings.extend(estimate.advice());
    }
    Ok((renders, source))
}

/// Renders a thermal scene at each of `times` (recorded in `solution`). One instant renders into
/// `out_dir` itself; several into numbered folders inside it, plus `preview.gif` animating S0
/// beside DoLP and the manifest `series.json` ([`render_series`]).
pub fn render_solution_at(
    scene: &Scene,
    solution: &ThermalSolution,
    times: &[f64],
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<Vec<TimedRender>, AppError> {
    if times.len() > 1 {
        return render_series(scene, solution, times, out_dir, progress);
    }
    let mut renders = Vec::with_capacity(times.len());
    for &time_s in times {
        let start = Instant::now();
        let at = solution_instant(scene, solution, time_s)?;
        let summary = render_loaded(&at, out_dir, progress, start)?;
        renders.push(TimedRender {
            time_s,
            folder: out_dir.to_owned(),
            summary,
        });
    }
    Ok(renders)
}

/// A series is one output set: every frame folder, the preview and the manifest are staged
/// together and replace an earlier series' (its frame folders included) in one step, so an
/// interrupted or failed series leaves the old set whole and a shorter series leaves no frames of
/// a longer one behind. A single instant rendered into the folder is another set, and is kept.
fn render_series(
    scene: &Scene,
    solution: &ThermalSolution,
    times: &[f64],
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<Vec<TimedRender>, AppError> {
    let write_error = |source| AppError::Write {
        path: out_dir.to_owned(),
        source,
    };
    let staged = StagedFolder::begin(out_dir).map_err(write_error)?;
    let mut renders = Vec::with_capacity(times.len());
    let mut previews = SeriesPreview::new();
    for (i, &time_s) in times.iter().enumerate() {
        let start = Instant::now();
        let at = solution_instant(scene, solution, time_s)?;
        let load = start.elapsed().as_secs_f64();
        let mut rendered = render(&at, progress)?;
        rendered.timings.load = load;
        let name = frame_name(i, time_s);
        let folder = out_dir.join(&name);
        let dir = staged.subfolder(&name).map_err(write_error)?;
        let summary = stage_outputs(&at, &rendered, &dir, &folder, start)?;
        previews.push(&at, &rendered.image);
        renders.push(TimedRender {
            time_s,
            folder,
            summary,
        });
    }
    let gif = animated_preview(&frame_labels(&renders), previews)?;
    staged.write("preview.gif", &gif).map_err(write_error)?;
    let manifest = serde_json::to_vec_pretty(&series_manifest(scene, &renders))
        .map_err(|e| write_error(std::io::Error::other(e)))?;
    staged
        .write(SERIES_MANIFEST, &manifest)
        .map_err(write_error)?;
    let earlier = EarlierOutputs::series(out_dir);
    staged
        .commit(&|name| earlier.contains(name))
        .map_err(write_error)?;
    Ok(renders)
}

/// `series.json`: the scene, each frame's instant and folder, and every entry the series wrote
/// (what the next render into the folder replaces).
fn series_manifest(scene: &Scene, renders: &[TimedRender]) -> serde_json::Value {
    let folder_name = |r: &TimedRender| {
        r.folder
            .file_name()
            .map_or(String::new(), |n| n.to_string_lossy().into_owned())
    };
    let frames: Vec<serde_json::Value> = renders
        .iter()
        .map(|r| {
            serde_json::json!({
                "time_s": r.time_s,
                "time_utc": r.summary.thermal_instant.as_ref().map(|i| &i.time_utc),
                "folder": folder_name(r),
            })
        })
        .collect();
    let mut files: Vec<String> = renders.iter().map(folder_name).collect();
    files.extend(["preview.gif".to_owned(), SERIES_MANIFEST.to_owned()]);
    serde_json::json!({
        "scene": scene.path.display().to_string(),
        "frames": frames,
        "files": files,
    })
}

/// The folder of instant `i` at `time_s` in a series, `NNN_<t>s`.
fn frame_name(i: usize, time_s: f64) -> String {
    format!("{i:03}_{}s", time_s.round())
}

/// Each frame's caption in the animated preview: its instant.
fn frame_labels(renders: &[TimedRender]) -> Vec<String> {
    renders
        .iter()
        .map(|r| match &r.summary.thermal_instant {
            Some(i) => format!("{}   (t = {} s)", i.time_utc, i.time_s),
            None => format!("t = {} s", r.time_s),
        })
        .collect()
}
