//! The `irpol` command line: parse, call the library, print. Errors are one clear line and a
//! non-zero exit, never a panic.

mod cli;

use clap::{Args, Parser, Subcommand};
use cli::progress::TerminalProgress;
use irpol::app::evaluate::{
    geometry_table, write_emissivity_csv, write_mueller_csv, GeometryTable,
};
use irpol::app::export::{export_to_mitsuba, parse_grid, parse_wavelengths};
use irpol::app::fit::{fit_and_write, FitFlags, FitOutput};
use irpol::app::render::{
    default_output_dir, render_scene_at_within, render_scene_within, Instants, TimedRender,
};
use irpol::app::saved_thermal::{run_store_beside, RunSource, SavedRun};
use irpol::app::scene_init::write_starter_scene;
use irpol::app::sun::{given_times, write_sun_csv};
use irpol::app::thermal::{run_thermal, run_thermal_and_render};
use irpol::app::validate::{validate_and_report, validation_summary};
use irpol::app::{parse_sweep, AppError, MeasurementArgs, ModelArgs};
use irpol::atomic::staging_folder;
use irpol::fit::{FitInputs, FitOptions, MaterialFit};
use irpol::material::MaterialModel;
use irpol::measure::ReadOptions;
use irpol::output::thermal::ThermalSummary;
use irpol::pbrdf::Pbrdf;
use irpol::report::fit_report::rebuild_report;
use irpol::report::index::write_library_index;
use irpol::report::paper_figures::{write_paper_figure, PaperFigure};
use irpol::text::significant;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "irpol",
    version,
    about = "Infrared polarimetry: fit polarimetric BRDFs and simulate LWIR Stokes imagery"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Mueller BRDF (m00…m33, sr⁻¹, psps frames) of a model at given geometries, as CSV on stdout.
    Eval {
        #[command(flatten)]
        model: ModelArgs,
        /// CSV with theta_i_deg, theta_r_deg [, phi_i_deg (0), phi_r_deg (180), other columns kept].
        #[arg(long, conflicts_with_all = ["theta_i", "theta_r"])]
        geometry: Option<PathBuf>,
        /// Incidence zenith (°), a value or START:STOP:STEP.
        #[arg(long)]
        theta_i: Option<String>,
        /// Detector zenith (°), a value or START:STOP:STEP; θ_r < 0 is read as (|θ_r|, φ_r + 180°).
        #[arg(long, allow_hyphen_values = true)]
        theta_r: Option<String>,
        /// Incidence azimuth (°).
        #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
        phi_i: f64,
        /// Detector azimuth (°), a value or START:STOP:STEP (inner to --theta-r: rows run over
        /// φ_r for each θ_r); 180 is the specular side.
        #[arg(long, default_value = "180", allow_hyphen_values = true)]
        phi_r: String,
    },
    /// Polarized emissivity ε0…ε3 against emission angle, as CSV on stdout.
    Emissivity {
        #[command(flatten)]
        model: ModelArgs,
        /// Emission zenith (°), a value or START:STOP:STEP.
        #[arg(long, default_value = "0:89:1")]
        theta: String,
    },
    /// The paper's figures (Ma et al. 2009 Figs. 2 and 3) as PNG and SVG.
    Figure {
        #[arg(value_parser = ["paper-fig2", "paper-fig3"])]
        which: String,
        #[arg(long, default_value = "reports")]
        out: PathBuf,
    },
    /// Fits pBRDF models to measurement CSVs (or Mitsuba .pbsdf tables) and writes the
    /// material library.
    Fit(FitArgs),
    /// Writes a material as a table another renderer loads: Mitsuba 3's measured_polarized
    /// .pbsdf (docs/mitsuba.md). Prints the file's size and grid.
    Export {
        /// The material TOML.
        material: PathBuf,
        /// The target format.
        #[arg(long, value_parser = ["mitsuba"])]
        to: String,
        /// The table file to write (replaced atomically if it exists; a folder is refused).
        #[arg(long)]
        out: PathBuf,
        /// Exactly five increasing wavelengths in whole nm (stock Mitsuba reads five); default
        /// 8000,9000,10000,11000,12000 for a grey material, five across a spectral one's table.
        #[arg(long)]
        wavelengths_nm: Option<String>,
        /// Node counts NPHI,NTD,NTH (each 2..=1024) instead of the sizes chosen for the
        /// material; the spacing still follows it.
        #[arg(long)]
        grid: Option<String>,
    },
    /// How a material's model predicts measurements it was not fitted to: per-element RMS
    /// errors (absolute and of m_ij/m00), normalized residuals, and a report page per file.
    Validate {
        /// The material TOML.
        material: PathBuf,
        /// Measurement CSVs or folders of them.
        #[arg(required = true)]
        data: Vec<PathBuf>,
        #[command(flatten)]
        measurements: MeasurementArgs,
        /// Folder for the validation report pages.
        #[arg(long, default_value = "reports")]
        reports: PathBuf,
    },
    /// Rebuilds a material's fit report from its library entry and source CSV.
    Report {
        /// The material TOML.
        material: PathBuf,
        #[arg(long, default_value = "reports")]
        reports: PathBuf,
    },
    /// Renders a scene's LWIR Stokes images (TIFF, EXR, PNG previews, composite, JSON summary).
    Render {
        /// The scene TOML.
        scene: PathBuf,
        /// Output folder (default out/<scene stem>/).
        #[arg(long)]
        out: Option<PathBuf>,
        /// A scene with [thermal]: render its thermal solution at this many seconds from
        /// thermal.start_utc.
        #[arg(long, conflicts_with_all = ["time_utc", "times"])]
        time: Option<f64>,
        /// A scene with [thermal]: render it at this RFC 3339 instant.
        #[arg(long, conflicts_with = "times")]
        time_utc: Option<String>,
        /// A scene with [thermal]: render START:STOP:STEP (seconds) into numbered folders, plus
        /// preview.gif animating S0 and DoLP.
        #[arg(long)]
        times: Option<String>,
        /// A scene with [thermal]: take its thermal run from this file (a <key>.bin saved by
        /// `irpol thermal` or an earlier render) instead of looking it up by its key in
        /// thermal/ beside the output folder; refused unless it is this scene's run.
        #[arg(long, value_name = "FILE")]
        thermal: Option<PathBuf>,
        /// Refuse, before any work, a render estimated to take longer (frames × pixels × path
        /// vertices × wavelength nodes; docs/commands.md, `irpol render`).
        #[arg(long, default_value_t = irpol::app::render_cost::DEFAULT_MAX_MINUTES)]
        max_minutes: f64,
    },
    /// Temperatures from a scene's [thermal] model: temperatures.csv (min/mean/max per part),
    /// a PLY per recorded step, temperatures.png and summary.json (docs/scenes.md, "Thermal").
    Thermal {
        /// The scene TOML (with a [thermal] section).
        scene: PathBuf,
        /// Output folder (default out/<scene stem>_thermal/).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Scene files (docs/scenes.md describes the format).
    Scene {
        #[command(subcommand)]
        command: SceneCommand,
    },
    /// Apparent sun position (NREL SPA, standard atmosphere, sea level) at a site, as CSV on stdout:
    /// time_utc,elevation_deg,azimuth_deg (azimuth clockwise from north); with --clear-sky also
    /// dni_w_m2,dhi_w_m2,ghi_w_m2.
    Sun {
        /// Latitude (°, north positive).
        #[arg(long, allow_negative_numbers = true)]
        latitude: f64,
        /// Longitude (°, east positive).
        #[arg(long, allow_negative_numbers = true)]
        longitude: f64,
        /// An RFC 3339 instant, e.g. 2026-06-21T10:00:00Z.
        #[arg(
            long,
            required_unless_present = "times_file",
            conflicts_with = "times_file"
        )]
        time_utc: Option<String>,
        /// A file of RFC 3339 instants, one per line (blank lines and # comments skipped).
        #[arg(long)]
        times_file: Option<PathBuf>,
        /// Also the clear-sky irradiance at that elevation (W/m²): direct normal, diffuse and global
        /// horizontal from the simplified Solis model (Ineichen 2008, as pvlib defines it) with
        /// aod700 = 0.1, 1 cm precipitable water, 101325 Pa, 1364 W/m² extraterrestrial; 0 with
        /// the sun below the horizon. The same model as the thermal clear day.
        #[arg(long)]
        clear_sky: bool,
    },
    /// An EPW or TMY3 weather file as irpol reads it, as CSV on stdout: a row per hour (the label
    /// in UTC, the fields in SI units, empty where missing, the sun at the file's site), or with
    /// --step the thermal model's forcing every STEP seconds.
    Weather {
        /// The weather file (.epw, or a TMY3 CSV).
        file: PathBuf,
        /// The format, when the file name and header do not tell: epw or tmy3.
        #[arg(long, value_parser = ["epw", "tmy3"])]
        format: Option<String>,
        /// Read every row in this year (a typical-year file mixes years).
        #[arg(long)]
        year: Option<i32>,
        /// Print the forcing (air, wind, DNI, DHI, long-wave, sun) every STEP seconds instead.
        #[arg(long)]
        step: Option<f64>,
    },
    /// A table of the materials in a library folder.
    Library {
        /// The library folder (`irpol fit --out`'s folder).
        #[arg(default_value = "fits")]
        dir: PathBuf,
        /// The library folder, as a flag (the same as DIR; earlier versions took only this).
        #[arg(long = "dir", conflicts_with = "dir", hide = true)]
        dir_flag: Option<PathBuf>,
    },
    /// Runs the main job on shipped defaults (fit the shipped measurements, render the car and
    /// its day) into out/demo/, and prints where everything went.
    Demo,
}

// The flags of `irpol fit` (the variant's doc comment is the subcommand's help).
#[derive(Args)]
struct FitArgs {
    /// Measurement CSVs or folders of them (or Mitsuba .pbsdf tables, docs/mitsuba.md).
    #[arg(required = true)]
    inputs: Vec<PathBuf>,
    #[command(flatten)]
    measurements: MeasurementArgs,
    /// Fit only this distribution (cauchy or gaussian); default: both, keep the preferred.
    #[arg(long)]
    distribution: Option<String>,
    /// Shadowing of the fitted model: none, torrance-sparrow or smith.
    #[arg(long, default_value = "smith")]
    shadowing: String,
    /// Free parameters, e.g. sigma,q,n,k,rho (default: all of the terms' parameters that are not
    /// fixed, except k behind internal facets, held at 0).
    #[arg(long)]
    free: Option<String>,
    /// Fixed parameter values, e.g. k=0.1,rho=0.
    #[arg(long)]
    fix: Option<String>,
    /// Optimizer stages joined by +: ga, nm, lm (default ga+lm).
    #[arg(long, default_value = "ga+lm")]
    optimizer: String,
    /// Seed of the genetic stage.
    #[arg(long, default_value_t = FitOptions::default().seed)]
    seed: u64,
    /// Robust loss on normalized residuals: huber or cauchy, optionally with a scale (huber:2).
    #[arg(long)]
    robust: Option<String>,
    /// For a material measured at several wavelengths (a spectral set): n, k free at each
    /// wavelength (table), n from Cauchy's normal dispersion A + B/λ² with B ≥ 0 (cauchy), or
    /// n, k from a Lorentz law of N oscillators (lorentz:N); auto (default): cauchy for a model
    /// with the subsurface term (a transparent dielectric), else table.
    #[arg(long, default_value = "auto")]
    dispersion: String,
    /// Model terms (docs/design.md §1.10): auto (default: external+depolarizer,
    /// external+subsurface and internal+subsurface each fitted, the admissible one that predicts
    /// best by 5-fold cross-validation kept), or one of those and internal+depolarizer; several
    /// comma-separated (or `all`) are compared by AIC (and by --cv).
    #[arg(long, default_value = irpol::app::fit::AUTO_TERMS)]
    terms: String,
    /// Score each set of terms by K-fold cross-validation (2–20 folds) and keep the one that
    /// predicts best.
    #[arg(long, value_name = "K")]
    cv: Option<usize>,
    /// A spectral fit's subsurface parameters to free at each wavelength instead of sharing
    /// them, e.g. d,n_sub (of d, n_sub, d_c, d1).
    #[arg(long, value_name = "LIST")]
    per_wavelength: Option<String>,
    /// Refuse up front a fit estimated to take longer than this (the estimate names its
    /// factors: rows, candidate models, folds, a spectral set's joint coordinates).
    #[arg(long, value_name = "MINUTES", default_value_t = irpol::fit::cost::DEFAULT_MAX_MINUTES)]
    max_minutes: f64,
    /// Library folder for the material TOMLs.
    #[arg(long, default_value = "fits")]
    out: PathBuf,
    /// Folder for the fit reports (PNG, SVG) and index.html.
    #[arg(long, default_value = "reports")]
    reports: PathBuf,
    /// Refuse a fit that does not describe its data (χ²_red above 10, or a parameter pinned at
    /// a bound of its search interval other than zero): an error, and nothing written.
    #[arg(long)]
    strict: bool,
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Writes a commented starter scene (a sphere on a plane, no other file needed) to render
    /// and edit; an existing file is never overwritten.
    Init {
        /// The scene file to write (by default under out/, which git ignores, so a checkout
        /// stays clean).
        #[arg(long, default_value = "out/scene.toml")]
        out: PathBuf,
    },
}

/// `println!` that treats a closed stdout (`irpol … | head`) as the reader being done, not as a
/// panic.
macro_rules! say {
    ($($arg:tt)*) => {
        print_line(format_args!($($arg)*))
    };
}

fn print_line(line: std::fmt::Arguments) {
    if let Err(error) = writeln!(std::io::stdout(), "{line}") {
        if error.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("irpol: error: cannot write to stdout: {error}");
        std::process::exit(1);
    }
}

fn main() -> ExitCode {
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

/// Fits, writes the library entries, reports and index (all or nothing) and prints one line per
/// material and where the reports went.
fn fit_and_summarize(
    inputs: &[PathBuf],
    reading: &ReadOptions,
    options: &FitOptions,
    output: &FitOutput,
) -> anyhow::Result<()> {
    let folders = vec![output.fits_dir.to_owned(), output.reports_dir.to_owned()];
    cli::signals::remove_on_interrupt(vec![], folders);
    // The readers' notes are said before the fit starts.
    let read = FitInputs::read(inputs, reading)?;
    note_all(&read.notes());
    let written = fit_and_write(
        read,
        reading,
        options,
        output,
        &TerminalProgress::counting(),
    )?;
    warn_once(&written.warnings);
    warn_once(&written.misfits);
    for (outcome, entry) in written.outcomes.iter().zip(&written.entries) {
        let line = match outcome {
            MaterialFit::Grey(outcome) => fit_summary_line(outcome, entry),
            MaterialFit::Spectral(outcome) => spectral_summary_line(outcome, entry),
        };
        say!("{line}");
        let choice = match outcome {
            MaterialFit::Grey(grey) => &grey.terms_choice,
            MaterialFit::Spectral(spectral) => &spectral.terms_choice,
        };
        if let Some(choice) = choice {
            say!("{}", choice.table());
        }
    }
    for report in &written.reports {
        say!("  report {}", report.display());
    }
    say!("  index  {}", written.index.display());
    Ok(())
}

/// `name: family, N wavelengths a–b µm, dispersion: σ=…±… q=…±… [law …] n a–b, k a–b
/// χ²_red=… → entry`: the shared parameters with their errors and the table's range.
fn spectral_summary_line(outcome: &irpol::fit::SpectralFitOutcome, entry: &Path) -> String {
    let chosen = &outcome.chosen;
    let model = &chosen.model;
    let shared: Vec<String> = chosen
        .names
        .iter()
        .zip(chosen.values.iter().zip(&chosen.errors))
        .filter(|(name, _)| !name.contains('('))
        .map(|(name, (v, e))| format!("{name}={}±{e:.1e}", significant(*v, 6)))
        .collect();
    let range = |values: &[f64]| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        format!("{}–{}", significant(lo, 3), significant(hi, 3))
    };
    let (first, last) = model.range_um();
    let terms = match model.terms() {
        t if t == irpol::pbrdf::ModelTerms::default() => String::new(),
        t => format!(" {t}"),
    };
    format!(
        "{}: {}{terms} {}, {} wavelengths {first}–{last} µm: {} n {} k {} χ²_red={}{}{} → {}",
        outcome.material.name,
        chosen.distribution.name(),
        match chosen.dispersion {
            irpol::fit::Dispersion::Cauchy => "normal dispersion (Cauchy)".to_owned(),
            other => other.to_string(),
        },
        model.wavelength_um.len(),
        shared.join(" "),
        range(&model.n),
        range(&model.k),
        chi2(chosen.reduced_chi2),
        realizability_clause(&outcome.measurements),
        identification_clause(outcome.material.fit.as_ref()),
        entry.display()
    )
}

/// `name: family σ=…±… … [bounded only: …] (fixed: …) χ²_red=…; comparison → entry`: the
/// parameters with their errors, except where the ± means nothing (undetermined, or bounded
/// from one side only) and the record's profile bound is listed instead; the parameters held
/// fixed as the record states them.
fn fit_summary_line(outcome: &irpol::fit::FitOutcome, entry: &Path) -> String {
    let chosen = &outcome.chosen;
    let record = outcome.material.fit.as_ref();
    let bound = |p: &irpol::fit::Parameter| record.and_then(|r| r.profile_bounds.get(p.name()));
    let parameters: Vec<String> = chosen
        .free
        .iter()
        .zip(&chosen.values)
        .filter(|(p, _)| bound(p).is_none())
        .map(|(p, v)| match chosen.error(*p) {
            Some(e) => format!("{}={}±{e:.1e}", p.name(), significant(*v, 6)),
            None => format!("{}={}", p.name(), significant(*v, 6)),
        })
        .collect();
    let bounded: Vec<String> = chosen
        .free
        .iter()
        .filter_map(|p| bound(p).map(|b| b.describe(p.name())))
        .collect();
    let fixed: Vec<String> = record
        .map(|r| &r.fixed_parameters)
        .into_iter()
        .flatten()
        .map(|(name, v)| format!("{name}={}", significant(*v, 6)))
        .collect();
    let comparison = outcome
        .comparison
        .as_ref()
        .map_or(String::new(), |c| format!("; {}", c.summary()));
    format!(
        "{}: {}{} {}{}{} χ²_red={}{}{}{comparison} → {}",
        outcome.material.name,
        chosen.distribution.name(),
        if chosen.terms == irpol::pbrdf::ModelTerms::default() {
            String::new()
        } else {
            format!(" {}", chosen.terms)
        },
        parameters.join(" "),
        listed(" [bounded only: ", &bounded, ", ", "]"),
        listed(" (fixed: ", &fixed, " ", ")"),
        chi2(chosen.reduced_chi2),
        realizability_clause(std::slice::from_ref(&outcome.measurement)),
        identification_clause(record),
        entry.display()
    )
}

/// `; NOT DETERMINED by the data: d (at a bound of its search interval), …` (docs/design.md
/// §1.10 "Identification"): a number the data do not determine must not read as a measurement.
/// A spectral fit's per-wavelength coordinates (`rho_d(8.5um)`, …) that share a reason are named
/// once with their count and range, so 50 wavelengths at a bound make one clause, not 50.
fn identification_clause(record: Option<&irpol::material::FitRecord>) -> String {
    let mut groups: Vec<(String, String, Vec<String>)> = Vec::new();
    for (name, why) in record.map(|r| r.identification()).unwrap_or_default() {
        let (base, at) = match name.split_once('(') {
            Some((base, rest)) => (base.to_owned(), Some(rest.trim_end_matches(')').to_owned())),
            None => (name.clone(), None),
        };
        match groups.last_mut() {
            Some((b, w, ats)) if at.is_some() && *b == base && *w == why && !ats.is_empty() => {
                ats.extend(at)
            }
            _ => groups.push((base, why, at.into_iter().collect())),
        }
    }
    let notes: Vec<String> = groups
        .into_iter()
        .map(|(base, why, ats)| match ats.as_slice() {
            [] => format!("{base} {why}"),
            [at] => format!("{base}({at}) {why}"),
            [first, .., last] => {
                format!("{base} at {} wavelengths ({first}–{last}) {why}", ats.len())
            }
        })
        .collect();
    listed("; NOT DETERMINED by the data: ", &notes, ", ", "")
}

/// `; k of N rows not realizable beyond 2σ` (Cloude's test against each row's uncertainty), or
/// nothing when no row has all sixteen elements to test.
fn realizability_clause(sets: &[irpol::measure::MeasurementSet]) -> String {
    let (mut failed, mut checked) = (0, 0);
    for set in sets {
        let outcome = irpol::measure::unrealizable_rows(set, REALIZABILITY_SIGMAS);
        failed += outcome.unrealizable.len();
        checked += outcome.checked;
    }
    if checked == 0 {
        return String::new();
    }
    format!("; {failed} of {checked} rows not realizable beyond {REALIZABILITY_SIGMAS}σ")
}

/// A measured row counts as not realizable when its coherency matrix's smallest eigenvalue is
/// below this many standard deviations of its noise (a bound, so noise alone rarely reaches it).
const REALIZABILITY_SIGMAS: f64 = 2.0;

/// A reduced χ² for the summary line: three decimals, in exponent form from 1e6 on (an absurd
/// fit's 3e50 is not printed as 51 digits).
fn chi2(x: f64) -> String {
    if x.abs() < 1e6 {
        format!("{x:.3}")
    } else {
        format!("{x:.3e}")
    }
}

/// `items` joined by `separator` between `open` and `close`, or nothing when there are none.
fn listed(open: &str, items: &[String], separator: &str, close: &str) -> String {
    if items.is_empty() {
        String::new()
    } else {
        format!("{open}{}{close}", items.join(separator))
    }
}

fn render_and_summarize(
    scene: &Path,
    out: Option<PathBuf>,
    max_minutes: f64,
) -> anyhow::Result<()> {
    let out = out.unwrap_or_else(|| default_output_dir(scene));
    cli::signals::remove_on_interrupt(vec![staging_folder(&out, std::process::id())], vec![]);
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

fn render_instants(
    scene: &Path,
    out: Option<PathBuf>,
    instants: &Instants,
    max_minutes: f64,
    thermal: Option<PathBuf>,
) -> anyhow::Result<()> {
    let out = out.unwrap_or_else(|| default_output_dir(scene));
    // One instant or a whole series: one output set staged beside the folder.
    cli::signals::remove_on_interrupt(vec![staging_folder(&out, std::process::id())], vec![]);
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

fn report_instants(scene: &Path, out: &Path, renders: &[TimedRender]) {
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

/// Each note on stderr: what irpol did that the user should know, not a problem.
fn note_all(notes: &[String]) {
    for note in notes {
        eprintln!("irpol: note: {note}");
    }
}

/// Each distinct warning once, in order, on stderr.
fn warn_once(warnings: &[String]) {
    let mut seen = std::collections::BTreeSet::new();
    for w in warnings.iter().filter(|w| seen.insert(w.as_str())) {
        eprintln!("irpol: warning: {w}");
    }
}

/// `out/<stem>_thermal/`, the default output folder of `irpol thermal`.
fn thermal_output_dir(scene: &Path) -> PathBuf {
    let mut dir = default_output_dir(scene).into_os_string();
    dir.push("_thermal");
    PathBuf::from(dir)
}

fn thermal_and_summarize(scene: &Path, out: Option<PathBuf>) -> anyhow::Result<()> {
    let out = out.unwrap_or_else(|| thermal_output_dir(scene));
    cli::signals::remove_on_interrupt(vec![staging_folder(&out, std::process::id())], vec![]);
    let store = run_store_beside(&out);
    let saved = SavedRun::Store(&store);
    let (summary, source) = run_thermal(scene, &out, saved, &TerminalProgress::new())?;
    note_run_source(&source);
    report_thermal(scene, &out, &summary);
    Ok(())
}

fn report_thermal(scene: &Path, out: &Path, summary: &ThermalSummary) {
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

fn print_library(dir: &Path) -> anyhow::Result<()> {
    let library = irpol::material::list_library(dir)?;
    warn_once(&library.warnings());
    let misfits: Vec<String> = library
        .materials
        .iter()
        .filter_map(|(_, m)| irpol::app::fit::misfit_warning(m))
        .collect();
    warn_once(&misfits);
    let materials = library.materials;
    if materials.is_empty() {
        say!("no materials in {}", dir.display());
        return Ok(());
    }
    say!(
        "{:<18} {:<9} {:<17} {:>9} {:>6} {:>6} {:>11} {:>11} {:>7} {:>8}",
        "material",
        "dist",
        "shadowing",
        "λ µm",
        "σ",
        "q",
        "n",
        "k",
        "ρ_d",
        "χ²_red"
    );
    // A spectral material shows the range of its table: λ first–last, n, k, ρ_d min–max.
    let span = |values: &[f64], digits: usize| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = (format!("{lo:.digits$}"), format!("{hi:.digits$}"));
        if lo == hi {
            lo
        } else {
            format!("{lo}–{hi}")
        }
    };
    for (_, m) in materials {
        let (wavelengths, n, k, rho_d) = match &m.model {
            MaterialModel::Grey(s) => (vec![s.wavelength_um], vec![s.n], vec![s.k], vec![s.rho_d]),
            MaterialModel::Spectral(s) => (
                s.wavelength_um.clone(),
                s.n.clone(),
                s.k.clone(),
                s.rho_d.clone(),
            ),
        };
        let q = m
            .model
            .distribution()
            .parameter(irpol::pbrdf::Parameter::Q)
            .map_or("—".into(), |q| format!("{q:.3}"));
        // A fit that does not describe its data is marked, and said below the table.
        let chi2 = m.fit.as_ref().map_or("—".into(), |f| {
            let mark = if f.misfit().is_empty() { "" } else { " !" };
            format!("{:.3}{mark}", f.reduced_chi2)
        });
        say!(
            "{:<18} {:<9} {:<17} {:>9} {:>6.3} {:>6} {:>11} {:>11} {:>7} {:>8}",
            m.name,
            m.model.distribution().name(),
            m.model.shadowing().name(),
            span(&wavelengths, if wavelengths.len() > 1 { 1 } else { 3 }),
            m.model.distribution().sigma(),
            q,
            span(&n, 3),
            span(&k, 3),
            span(&rho_d, 4),
            chi2
        );
    }
    Ok(())
}

/// The demo's own folder: everything it writes goes here (ignored by git), so a fresh clone stays
/// clean and the shipped library `fits/` is never rewritten (a fit's last digits differ between
/// CPUs, through the system math library's CPU-specific exp/log).
const DEMO_OUT: &str = "out/demo";

fn demo() -> anyhow::Result<()> {
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
    cli::signals::remove_on_interrupt(
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
