//! irpol — infrared polarimetry: fit microfacet polarimetric BRDFs to Mueller-matrix BRDF
//! measurements and simulate long-wave infrared Stokes imagery (S0, S1, S2, DoLP, AoP).
//!
//! Data flows one way: CSV → [`measure::MeasurementSet`] → [`fit`] → [`material::Material`] →
//! [`scene`] → [`transport`] → [`render`] → [`output`]. The physics lives in [`optics`] and
//! [`pbrdf`]; everything else calls it. The layers and their rules are in docs/design.md §3.
//!
//! **Start here.** The application layer [`app`] is what the `irpol` command and the Python
//! bindings call: one function per subcommand, one error type ([`AppError`]). The re-exports
//! below are what a program needs for the tour of the README (read measurements, fit, load a
//! material, evaluate a pBRDF, load and render a scene, run the thermal model); the modules stay
//! public for the physics (`optics`, `pbrdf`) and for tests that reach inside.
//!
//! # Tour
//!
//! Evaluate a pBRDF (docs/design.md §1.3). Its Mueller matrix obeys reciprocity: swapping
//! ω_i and ω_r leaves m00 unchanged.
//!
//! ```
//! use irpol::optics::Direction;
//! use irpol::{Pbrdf, RefractiveIndex, Shadowing, SlopeDistribution};
//!
//! let paint = Pbrdf::new(
//!     SlopeDistribution::Cauchy { sigma: 0.3, q: 2.5 },
//!     Shadowing::Smith,
//!     RefractiveIndex::new(1.55, 0.05),
//!     0.03, // ρ_d
//! )?;
//! let incident = Direction::from_angles(30f64.to_radians(), 0.0);
//! let scattered = Direction::from_angles(45f64.to_radians(), 160f64.to_radians());
//! let forward = paint.mueller(&incident, &scattered);
//! let backward = paint.mueller(&scattered, &incident);
//! assert!(forward[(0, 0)] > 0.03 / std::f64::consts::PI);
//! assert!((forward[(0, 0)] - backward[(0, 0)]).abs() < 1e-12 * forward[(0, 0)]);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Read a measurement file and fit it (docs/design.md §2.1–2.2): the shipped rough paint was
//! made by an independent implementation with σ = 0.3 and its noise, so the fit recovers σ and
//! a χ²_red near 1.
//!
//! ```
//! use irpol::fit::{fit_measurement, Optimizer};
//! use irpol::{read_measurement_csv, DistributionKind, FitOptions, MaterialModel};
//!
//! let set = read_measurement_csv("measurements/rough_paint.csv".as_ref())?;
//! let options = FitOptions {
//!     distribution: Some(DistributionKind::Cauchy),
//!     optimizer: Optimizer::parse("lm")?,
//!     ..FitOptions::default()
//! };
//! let outcome = fit_measurement(&set, &options)?;
//! let MaterialModel::Grey(model) = &outcome.material.model else { unreachable!() };
//! assert!((model.distribution.sigma() - 0.3).abs() < 0.01);
//! assert!(outcome.chosen.reduced_chi2 < 1.5);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Load a library material and a scene, and render the scene's Stokes images into a folder
//! (TIFF, EXR, PNG previews and `summary.json`, docs/design.md §2.5):
//!
//! ```no_run
//! use irpol::{load_scene, render_scene, Material, Silent};
//!
//! let paint = Material::load("fits/rough_paint.toml".as_ref())?;
//! let scene = load_scene("scenes/car.toml".as_ref())?;
//! let summary = render_scene("scenes/car.toml".as_ref(), "out/car".as_ref(), &Silent)?;
//! println!("{} materials, S0 of {} × {}", scene.materials.len(), summary.width, summary.height);
//! # let _ = paint;
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub mod app;
pub mod atmosphere;
pub mod atomic;
pub mod elementary;
pub mod emitter;
pub mod fit;
pub mod interop;
pub mod interrupt;
pub mod material;
pub mod measure;
pub mod optics;
pub mod output;
pub mod pbrdf;
pub mod plot_style;
pub mod progress;
pub mod render;
pub mod report;
pub mod scene;
pub mod table_text;
pub mod text;
pub mod thermal;
pub mod thermal_scene;
pub mod toml_table;
pub mod transport;
pub mod weather;

pub use app::fit::fit_and_write;
pub use app::render::{render_scene, render_scene_at};
pub use app::thermal::{run_thermal, run_thermal_and_render};
pub use app::{AppError, ModelArgs};
pub use fit::{fit_inputs, FitOptions, MaterialFit};
pub use material::{Material, MaterialModel, ModelSpec, SpectralModel};
pub use measure::{
    read_measurement_csv, read_measurement_sets, MeasurementPoint, MeasurementRow, MeasurementRows,
    MeasurementSet,
};
pub use optics::RefractiveIndex;
pub use pbrdf::{DistributionKind, Pbrdf, Shadowing, SlopeDistribution};
pub use progress::{Progress, Silent};
pub use scene::{load_scene, Scene, SceneError};

/// The version every output names (`tool_version` of a material, the `#` header of a table).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
