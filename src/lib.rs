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
pub mod tables;
pub mod text;
pub mod thermal;
pub mod thermal_scene;
pub mod transport;
pub mod weather;

pub use app::fit::fit_and_write;
pub use app::render::{render_scene, render_scene_at};
pub use app::thermal::{run_thermal, run_thermal_and_render};
pub use app::{AppError, ModelArgs};
pub use fit::{fit_inputs, FitOptions, MaterialFit};
pub use material::{Material, MaterialModel, ModelSpec, SpectralModel};
pub use measure::{read_measurement_csv, read_measurement_sets, MeasurementPoint, MeasurementSet};
pub use optics::RefractiveIndex;
pub use pbrdf::{DistributionKind, Pbrdf, Shadowing, SlopeDistribution};
pub use progress::{Progress, Silent};
pub use scene::{load_scene, Scene, SceneError};

/// The version every output names (`tool_version` of a material, the `#` header of a table).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
