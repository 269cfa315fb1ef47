//! The `irpol` command line: parse, call the library, print. Errors are one clear line and a
//! non-zero exit, never a panic.

#[macro_use]
mod cli;

use clap::Parser;
use cli::args::{Cli, Command, FitArgs, SceneCommand};
use cli::demo::demo;
use cli::fit_summary::fit_and_summarize;
use cli::library::print_library;
use cli::render_summary::{render_and_summarize, render_instants, thermal_and_summarize};
use cli::terminal::{note_all, warn_once};
use irpol::app::evaluate::{
    geometry_table, write_emissivity_csv, write_mueller_csv, GeometryTable,
};
use irpol::app::export::{export_to_mitsuba, parse_grid, parse_wavelengths};
use irpol::app::fit::{FitFlags, FitOutput};
use irpol::app::render::Instants;
use irpol::app::scene_init::write_starter_scene;
use irpol::app::sun::{given_times, write_sun_csv};
use irpol::app::validate::{validate_and_report, validation_summary};
use irpol::app::{parse_sweep, AppError, MeasurementArgs};
use irpol::pbrdf::Pbrdf;
use irpol::report::fit_report::rebuild_report;
use irpol::report::index::write_library_index;
use irpol::report::paper_figures::{write_paper_figure, PaperFigure};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

fn main() -> ExitCode {
    cli::allocator::return_large_blocks_when_freed();
    let cli = Cli::parse();
    // One interrupt handler for every command that writes (validate, report, figure, scene
    // init as well as fit, render, thermal and demo): it removes what the library staged.
    cli::signals::watch_interrupts();
    let outcome = run(cli.command);
    // A run that ends (refused a write, or just finished) while the interrupt handler clears up
    // must not exit under it: the handler removes the temporaries and exits with 128 + signal.
    cli::signals::wait_for_interrupt_handler();
    match outcome {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) if is_broken_pipe(&error) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("irpol: error: {error:#}");
            ExitCode::FAILURE
        }
    }
}

/// The reader of stdout went away (`irpol eval … | head`): not a failure of ours.
fn is_broken_pipe(error: &anyhow::Error) -> bool {
    error.chain().any(|cause| {
        cause
            .downcast_ref::<std::io::Error>()
            .is_some_and(|e| e.kind() == std::io::ErrorKind::BrokenPipe)
            || cause
                .downcast_ref::<AppError>()
                .is_some_and(AppError::is_broken_pipe)
    })
}

/// Runs one subcommand.
fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Eval {
            model,
            geometry,
            theta_i,
            theta_r,
            phi_i,
            phi_r,
        } => {
            let model = model.build()?;
            let table = geometry_table(
                geometry.as_deref(),
                theta_i.as_deref(),
                theta_r.as_deref(),
                phi_i,
                &phi_r,
            )?;
            eval(&model, &table)
        }
        Command::Emissivity { model, theta } => {
            let model = model.build()?;
            emissivity(&model, &theta)
        }
        Command::Figure { which, out } => figure(&which, &out),
        Command::Fit(args) => fit(args),
        Command::Export {
            material,
            to: _,
            out,
            wavelengths_nm,
            grid,
        } => export(&material, &out, wavelengths_nm.as_deref(), grid.as_deref()),
        Command::Validate {
            material,
            data,
            measurements,
            reports,
        } => validate(&material, &data, &measurements, &reports),
        Command::Report { material, reports } => report(&material, &reports),
        Command::Render {
            scene,
            out,
            time,
            time_utc,
            times,
            thermal,
            max_minutes,
        } => match Instants::from_flags(time, time_utc, times.as_deref())? {
            Some(instants) => render_instants(&scene, out, &instants, max_minutes, thermal),
            None if thermal.is_some() => Err(AppError::invalid(
                "--thermal needs an instant to render: give --time, --time-utc or --times",
            )
            .into()),
            None => render_and_summarize(&scene, out, max_minutes),
        },
        Command::Thermal { scene, out } => thermal_and_summarize(&scene, out),
        Command::Scene {
            command: SceneCommand::Init { out },
        } => scene_init(&out),
        Command::Sun {
            latitude,
            longitude,
            time_utc,
            times_file,
            clear_sky,
        } => {
            let times = given_times(time_utc.as_deref(), times_file.as_deref())?;
            sun(latitude, longitude, &times, clear_sky)
        }
        Command::Weather {
            file,
            format,
            year,
            step,
        } => weather(&file, format.as_deref(), year, step),
        Command::Library { dir, dir_flag } => print_library(&dir_flag.unwrap_or(dir)),
        Command::Demo => demo(),
    }
}

/// `irpol eval`: the Mueller CSV on stdout, after the notes on how the rows were read.
fn eval(model: &Pbrdf, table: &GeometryTable) -> anyhow::Result<()> {
    note_all(&table.notes);
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    write_mueller_csv(model, table, &mut out)?;
    Ok(out.flush()?)
}

/// `irpol emissivity`: the table on stdout, and a warning where the model creates energy.
fn emissivity(model: &Pbrdf, theta: &str) -> anyhow::Result<()> {
    let thetas = parse_sweep(theta, "theta")?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    let excess = write_emissivity_csv(model, &thetas, &mut out)?;
    out.flush()?;
    if !excess.is_empty() {
        eprintln!(
            "irpol: warning: hemispherical reflectance exceeds 1 (ε0 < 0) at θ = {:?}°: this model \
             does not conserve energy there; values are reported unclamped (use --shadowing smith)",
            excess
        );
    }
    Ok(())
}

/// `irpol fit`: the options checked, then the fit written and summarized.
fn fit(args: FitArgs) -> anyhow::Result<()> {
    let flags = FitFlags {
        distribution: args.distribution,
        shadowing: args.shadowing,
        free: args.free,
        fix: args.fix,
        optimizer: args.optimizer,
        seed: args.seed,
        robust: args.robust,
        dispersion: args.dispersion,
        terms: args.terms,
        cv: args.cv,
        per_wavelength: args.per_wavelength,
        max_minutes: args.max_minutes,
    };
    let reading = args.measurements.read_options()?;
    let output = FitOutput {
        fits_dir: &args.out,
        reports_dir: &args.reports,
        strict: args.strict,
    };
    fit_and_summarize(&args.inputs, &reading, &flags.options()?, &output)
}

/// `irpol export --to mitsuba`: the table written, then its size, grid and wavelengths.
fn export(
    material: &Path,
    out: &Path,
    wavelengths_nm: Option<&str>,
    grid: Option<&str>,
) -> anyhow::Result<()> {
    let options = irpol::material::ExportOptions {
        wavelengths_nm: wavelengths_nm.map(parse_wavelengths).transpose()?,
        grid: grid.map(parse_grid).transpose()?,
    };
    let summary = export_to_mitsuba(material, out, &options)?;
    note_all(&summary.notes);
    let [p, d, h] = summary.grid;
    let wavelengths: Vec<String> = summary.wavelengths_nm.iter().map(u16::to_string).collect();
    say!(
        "wrote {} ({:.1} MB): grid {p} × {d} × {h} (φ_d × θ_d × θ_h), wavelengths {} nm",
        summary.path.display(),
        summary.bytes as f64 / 1e6,
        wavelengths.join(", ")
    );
    Ok(())
}

/// `irpol validate`: one line per measurement set and its report page.
fn validate(
    material: &Path,
    data: &[PathBuf],
    measurements: &MeasurementArgs,
    reports: &Path,
) -> anyhow::Result<()> {
    let reading = measurements.read_options()?;
    for result in validate_and_report(material, data, &reading, reports)? {
        say!(
            "{} on {}: {}",
            material.display(),
            result.set.source.display(),
            validation_summary(&result.validation)
        );
        say!("  {}", element_errors(&result.validation));
        say!("  report {}", result.report.display());
    }
    Ok(())
}

/// `m00 4.1 % · m01 0.0123 · …`: each element's RMS error, m00's relative and the others' of
/// m_ij/m00.
fn element_errors(validation: &irpol::fit::Validation) -> String {
    let parts: Vec<String> = validation
        .elements
        .iter()
        .enumerate()
        .map(|(i, e)| match i {
            0 => format!("{} {:.2} %", e.name, 100.0 * e.rms_normalized),
            _ => format!("{} {:.4}", e.name, e.rms_normalized),
        })
        .collect();
    parts.join(" · ")
}

/// `irpol sun`: the CSV on stdout.
fn sun(
    latitude: f64,
    longitude: f64,
    times: &[chrono::DateTime<chrono::Utc>],
    clear_sky: bool,
) -> anyhow::Result<()> {
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    write_sun_csv(latitude, longitude, times, clear_sky, &mut out)?;
    Ok(out.flush()?)
}

/// `irpol weather`: the CSV on stdout.
fn weather(
    file: &Path,
    format: Option<&str>,
    year: Option<i32>,
    step: Option<f64>,
) -> anyhow::Result<()> {
    let format = match format {
        Some("epw") => Some(irpol::weather::WeatherFormat::Epw),
        Some(_) => Some(irpol::weather::WeatherFormat::Tmy3),
        None => None,
    };
    let station = irpol::app::weather::read_station(file, format, year)?;
    let mut out = std::io::BufWriter::new(std::io::stdout().lock());
    match step {
        Some(step_s) => irpol::app::weather::write_forcing(&station, step_s, &mut out)?,
        None => irpol::app::weather::write_hourly(&station, &mut out)?,
    }
    Ok(out.flush()?)
}

fn figure(which: &str, out: &Path) -> anyhow::Result<()> {
    let figure = if which == "paper-fig2" {
        PaperFigure::Fig2
    } else {
        PaperFigure::Fig3
    };
    for path in write_paper_figure(figure, out)? {
        say!("wrote {}", path.display());
    }
    Ok(())
}

/// `irpol report`: the material's report rebuilt, and the index of its library folder.
fn report(material: &Path, reports: &Path) -> anyhow::Result<()> {
    for path in rebuild_report(material, reports)? {
        say!("wrote {}", path.display());
    }
    let library = material
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let index = write_library_index(library, reports)?;
    warn_once(&index.warnings);
    say!("wrote {}", index.path.display());
    Ok(())
}

fn scene_init(out: &Path) -> anyhow::Result<()> {
    write_starter_scene(out)?;
    say!(
        "wrote {0}: a sphere on a plane under a clear sky; render it with `irpol render {0}`",
        out.display()
    );
    Ok(())
}
