//! The command line's grammar: the subcommands and their flags (clap derives; the help text is
//! each item's doc comment).

use clap::{Args, Parser, Subcommand};
use irpol::app::{MeasurementArgs, ModelArgs};
use irpol::fit::FitOptions;
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "irpol",
    version,
    about = "Infrared polarimetry: fit polarimetric BRDFs and simulate LWIR Stokes imagery"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
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
pub(crate) struct FitArgs {
    /// Measurement CSVs or folders of them (or Mitsuba .pbsdf tables, docs/mitsuba.md).
    #[arg(required = true)]
    pub(crate) inputs: Vec<PathBuf>,
    #[command(flatten)]
    pub(crate) measurements: MeasurementArgs,
    /// Fit only this distribution (cauchy or gaussian); default: both, keep the preferred.
    #[arg(long)]
    pub(crate) distribution: Option<String>,
    /// Shadowing of the fitted model: none, torrance-sparrow or smith.
    #[arg(long, default_value = "smith")]
    pub(crate) shadowing: String,
    /// Free parameters, e.g. sigma,q,n,k,rho (default: all of the terms' parameters that are not
    /// fixed, except k behind internal facets, held at 0).
    #[arg(long)]
    pub(crate) free: Option<String>,
    /// Fixed parameter values, e.g. k=0.1,rho=0.
    #[arg(long)]
    pub(crate) fix: Option<String>,
    /// Optimizer stages joined by +: ga, nm, lm (default ga+lm).
    #[arg(long, default_value = "ga+lm")]
    pub(crate) optimizer: String,
    /// Seed of the genetic stage.
    #[arg(long, default_value_t = FitOptions::default().seed)]
    pub(crate) seed: u64,
    /// Robust loss on normalized residuals: huber or cauchy, optionally with a scale (huber:2).
    #[arg(long)]
    pub(crate) robust: Option<String>,
    /// For a material measured at several wavelengths (a spectral set): n, k free at each
    /// wavelength (table), n from Cauchy's normal dispersion A + B/λ² with B ≥ 0 (cauchy), or
    /// n, k from a Lorentz law of N oscillators (lorentz:N); auto (default): cauchy for a model
    /// with the subsurface term (a transparent dielectric), else table.
    #[arg(long, default_value = "auto")]
    pub(crate) dispersion: String,
    /// Model terms (docs/design.md §1.10): auto (default: external+depolarizer,
    /// external+subsurface and internal+subsurface each fitted, the admissible one that predicts
    /// best by 5-fold cross-validation kept), or one of those and internal+depolarizer; several
    /// comma-separated (or `all`) are compared by AIC (and by --cv).
    #[arg(long, default_value = irpol::app::fit::AUTO_TERMS)]
    pub(crate) terms: String,
    /// Score each set of terms by K-fold cross-validation (2–20 folds) and keep the one that
    /// predicts best.
    #[arg(long, value_name = "K")]
    pub(crate) cv: Option<usize>,
    /// A spectral fit's subsurface parameters to free at each wavelength instead of sharing
    /// them, e.g. d,n_sub (of d, n_sub, d_c, d1).
    #[arg(long, value_name = "LIST")]
    pub(crate) per_wavelength: Option<String>,
    /// Refuse up front a fit estimated to take longer than this (the estimate names its
    /// factors: rows, candidate models, folds, a spectral set's joint coordinates).
    #[arg(long, value_name = "MINUTES", default_value_t = irpol::fit::cost::DEFAULT_MAX_MINUTES)]
    pub(crate) max_minutes: f64,
    /// Library folder for the material TOMLs.
    #[arg(long, default_value = "fits")]
    pub(crate) out: PathBuf,
    /// Folder for the fit reports (PNG, SVG) and index.html.
    #[arg(long, default_value = "reports")]
    pub(crate) reports: PathBuf,
    /// Refuse a fit that does not describe its data (χ²_red above 10, or a parameter pinned at
    /// a bound of its search interval other than zero): an error, and nothing written.
    #[arg(long)]
    pub(crate) strict: bool,
}

#[derive(Subcommand)]
pub(crate) enum SceneCommand {
    /// Writes a commented starter scene (a sphere on a plane, no other file needed) to render
    /// and edit; an existing file is never overwritten.
    Init {
        /// The scene file to write (by default under out/, which git ignores, so a checkout
        /// stays clean).
        #[arg(long, default_value = "out/scene.toml")]
        out: PathBuf,
    },
}
