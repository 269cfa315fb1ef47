//! irpol — infrared polarimetry: fit microfacet polarimetric BRDFs to Mueller-matrix BRDF
//! measurements and simulate long-wave infrared Stokes imagery (S0, S1, S2, DoLP, AoP).
//!
//! Data flows one way: CSV → [`measure::MeasurementSet`] → [`fit`] → [`material::Material`] →
//! [`scene`] → [`transport`] → [`render`] → [`output`]. The physics lives in [`optics`] and
//! [`pbrdf`]; everything else calls it.

pub mod atomic;
pub mod commands;
pub mod elementary;
pub mod emitter;
pub mod fit;
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
pub mod text;
pub mod thermal;
pub mod thermal_scene;
pub mod transport;

/// The version every output names (`tool_version` of a material, the `#` header of a table).
pub const VERSION: &str = env!("CARGO_PKG_VERSION");
