//! Light transport (docs/design.md §1.5, §1.7): what leaves a surface point toward a viewer.
//!
//! - [`open_world`]: the paper's model (every point sees the whole sky and ground), read from
//!   exact per-material [`tables`] built from the pBRDF's own quadrature ([`kernel`]); no noise.
//! - [`path`]: occlusion, polarized inter-reflection and the sun as a Monte Carlo correction to
//!   the open-world value (its control variate), with rays through [`accel`] and each pixel's
//!   first bounce stratified by [`sampler`].

pub mod accel;
pub mod band_environment;
mod band_scattering;
pub mod horizon;
pub mod kernel;
pub mod open_world;
pub mod path;
pub mod sampler;
pub mod tables;
