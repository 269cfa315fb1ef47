//! `irpol demo`: the main job on the shipped files, into its own folder.

use super::fit_summary::fit_and_summarize;
use super::progress::TerminalProgress;
use super::render_summary::{render_and_summarize, report_instants, report_thermal};
use irpol::app::fit::{FitFlags, FitOutput};
use irpol::app::parse_sweep;
use irpol::app::thermal::run_thermal_and_render;
use irpol::atomic::staging_folder;
use irpol::measure::ReadOptions;
use irpol::report::paper_figures::{write_paper_figure, PaperFigure};
use std::path::{Path, PathBuf};

/// The demo's own folder: everything it writes goes here (ignored by git), so a fresh clone stays
/// clean and the shipped library `fits/` is never rewritten (a fit's last digits differ between
/// CPUs, through the system math library's CPU-specific exp/log).
const DEMO_OUT: &str = "out/demo";

pub(crate) fn demo() -> anyhow::Result<()> {
    let out = PathBuf::from(DEMO_OUT);
    let (measurements, fits, reports) = (
        PathBuf::from("measurements"),
        out.join("fits"),
        out.join("reports"),
    );
    // The demo works on the repository's shipped files; anywhere else say what it needs.
    let needed = [
        "measurements",
        "fits",
        "scenes/car.toml",
        "scenes/car.obj",
        "scenes/car_day.toml",
    ];
    let missing: Vec<&str> = needed
        .into_iter()
        .filter(|p| !Path::new(p).exists())
        .collect();
    if !missing.is_empty() {
        anyhow::bail!(
            "irpol demo runs on the files shipped in the irpol repository and must be started from \
             its root folder (the one holding Cargo.toml); missing here: {}",
            missing.join(", ")
        );
    }
    say!(
        "irpol demo: fit the shipped measurements in {} (into {})",
        measurements.display(),
        fits.display()
    );
    // The product's default, as `irpol fit` with no flag runs it (terms chosen, docs/design.md
    // §1.10).
    fit_and_summarize(
        &[measurements],
        &ReadOptions::default(),
        &FitFlags::default().options()?,
        &FitOutput {
            fits_dir: &fits,
            reports_dir: &reports,
            strict: false,
        },
    )?;
    say!("the paper's model figures:");
    for figure in [PaperFigure::Fig2, PaperFigure::Fig3] {
        for path in write_paper_figure(figure, &reports)? {
            say!("  wrote {}", path.display());
        }
    }
    say!("the car scene, with the shipped library (fits/):");
    render_and_summarize(
        Path::new("scenes/car.toml"),
        Some(out.join("car")),
        irpol::app::render_cost::DEFAULT_MAX_MINUTES,
    )?;
    demo_day(&out)?;
    say!(
        "open {0}/reports/index.html for the fits, {0}/car/composite.png for the imagery, \
         {0}/car_day_thermal/temperatures.png and {0}/car_day/preview.gif for the day",
        out.display()
    );
    Ok(())
}

/// The demo's thermal day: the car's temperatures through a clear summer day, rendered every 3 h.
fn demo_day(out: &Path) -> anyhow::Result<()> {
    let day = Path::new("scenes/car_day.toml");
    say!("the car through a clear summer day, temperatures from the thermal model:");
    let (thermal_out, render_out) = (out.join("car_day_thermal"), out.join("car_day"));
    let pid = std::process::id();
    crate::cli::signals::remove_on_interrupt(
        vec![
            staging_folder(&thermal_out, pid),
            staging_folder(&render_out, pid),
        ],
        vec![],
    );
    let (summary, renders) = run_thermal_and_render(
        day,
        &thermal_out,
        &render_out,
        &parse_sweep("0:86400:10800", "times")?,
        &TerminalProgress::new(),
    )?;
    report_thermal(day, &thermal_out, &summary);
    report_instants(day, &render_out, &renders);
    Ok(())
}
