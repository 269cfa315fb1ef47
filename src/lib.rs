//! irpol — infrared polarimetry: fit microfacet polarimetric BRDFs to Mueller-matrix BRDF
//! measurements and simulate long-wave infrared Stokes imagery (S0, S1, S2, DoLP, AoP).
//!
//! Data flows one way: CSV → [`measure::MeasurementSet`] → [`fit`] → [`material::Material`] →
//! [`scene`] → [`render`]. The physics lives in [`optics`] and [`pbrdf`]; everything else calls it.

pub mod commands;
pub mod fit;
pub mod material;
pub mod measure;
pub mod optics;
pub mod pbrdf;
pub mod render;
pub mod report;
pub mod scene;
pub mod text;
