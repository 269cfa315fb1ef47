//! `irpol render` and `irpol thermal`: the run started with its staging folder cleared on an
//! interrupt, then what was rendered or solved and where it went.

use super::progress::TerminalProgress;
use super::terminal::{note_all, warn_once};
use irpol::app::render::{
    default_output_dir, render_scene_at_within, render_scene_within, Instants, TimedRender,
};
use irpol::app::saved_thermal::{run_store_beside, RunSource, SavedRun};
use irpol::app::thermal::run_thermal;
use irpol::atomic::staging_folder;
use irpol::output::thermal::ThermalSummary;
use std::path::{Path, PathBuf};

pub(crate) fn render_and_summarize(
    scene: &Path,
    out: Option<PathBuf>,
    max_minutes: f64,
) -> anyhow::Result<()> {
    let out = out.unwrap_or_else(|| default_output_dir(scene));
    crate::cli::signals::remove_on_interrupt(
        vec![staging_folder(&out, std::process::id())],
        vec![],
    );
    let summary = render_scene_within(scene, &out, max_minutes, &TerminalProgress::new())?;
    warn_once(&summary.warnings);
    let temperature = summary
        .apparent_temperature_k
        .as_ref()
        .map_or(String::new(), |t| {
            format!(", apparent temperature {:.1}–{:.1} K", t.min, t.max)
        });
    say!(
        "rendered {} ({}×{}, {} shading{temperature}) in {:.2} s → {}",
        scene.display(),
        summary.width,
        summary.height,
        summary.shading.describe(),
        summary.timings_s.total,
        out.display()
    );
    for file in &summary.files {
        say!("  {file}");
    }
    Ok(())
}

pub(crate) fn render_instants(
    scene: &Path,
    out: Option<PathBuf>,
    instants: &Instants,
    max_minutes: f64,
    thermal: Option<PathBuf>,
) -> anyhow::Result<()> {
    let out = out.unwrap_or_else(|| default_output_dir(scene));
    // One instant or a whole series: one output set staged beside the folder.
    crate::cli::signals::remove_on_interrupt(
        vec![staging_folder(&out, std::process::id())],
        vec![],
    );
    let progress = TerminalProgress::new();
    let store = run_store_beside(&out);
    let saved = match &thermal {
        Some(file) => SavedRun::File(file),
        None => SavedRun::Store(&store),
    };
    let (renders, source) =
        render_scene_at_within(scene, &out, instants, max_minutes, saved, &progress)?;
    note_run_source(&source);
    report_instants(scene, &out, &renders);
    Ok(())
}

/// The note (and any warning) saying whether a thermal run was solved or taken from a file.
fn note_run_source(source: &RunSource) {
    match source {
        RunSource::Reused(file) => note_all(&[format!(
            "thermal run reused from {} (solved earlier; delete the file to solve it again)",
            file.display()
        )]),
        RunSource::Solved {
            seconds,
            saved,
            ignored,
        } => {
            if let Some(why) = ignored {
                warn_once(&[format!("{why} (solving it again)")]);
            }
            let saved = match saved {
                Some(file) => format!(
                    "saved to {} (irpol thermal and render reuse it)",
                    file.display()
                ),
                None => "not saved: its instants need separate runs".to_owned(),
            };
            note_all(&[format!("thermal run solved in {seconds:.1} s, {saved}")]);
        }
    }
}

pub(crate) fn report_instants(scene: &Path, out: &Path, renders: &[TimedRender]) {
    let all: Vec<String> = renders
        .iter()
        .flat_map(|r| r.summary.warnings.iter().cloned())
        .collect();
    warn_once(&all);
    for r in renders {
        say!(
            "rendered {} at t = {} s ({}×{}) → {}",
            scene.display(),
            r.time_s,
            r.summary.width,
            r.summary.height,
            r.folder.display()
        );
    }
    if renders.len() > 1 {
        say!("  {}", out.join("preview.gif").display());
    }
}

/// `out/<stem>_thermal/`, the default output folder of `irpol thermal`.
fn thermal_output_dir(scene: &Path) -> PathBuf {
    let mut dir = default_output_dir(scene).into_os_string();
    dir.push("_thermal");
    PathBuf::from(dir)
}

pub(crate) fn thermal_and_summarize(scene: &Path, out: Option<PathBuf>) -> anyhow::Result<()> {
    let out = out.unwrap_or_else(|| thermal_output_dir(scene));
    crate::cli::signals::remove_on_interrupt(
        vec![staging_folder(&out, std::process::id())],
        vec![],
    );
    let store = run_store_beside(&out);
    let saved = SavedRun::Store(&store);
    let (summary, source) = run_thermal(scene, &out, saved, &TerminalProgress::new())?;
    note_run_source(&source);
    report_thermal(scene, &out, &summary);
    Ok(())
}

pub(crate) fn report_thermal(scene: &Path, out: &Path, summary: &ThermalSummary) {
    warn_once(&summary.warnings);
    say!(
        "thermal run of {} ({} h from {}, {} vertices, {} distinct solves) in {:.2} s → {}",
        scene.display(),
        summary.duration_s / 3600.0,
        summary.start_utc,
        summary.stats.thermal_vertices,
        summary.stats.distinct_solves,
        summary.seconds,
        out.display()
    );
    say!(
        "  temperatures.csv, temperatures.png, summary.json and {} surface PLYs",
        summary.recorded_instants
    );
}
