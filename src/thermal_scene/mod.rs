//! Temperatures of a scene over time (docs/design.md §1.8): the thermal model of `thermal`
//! applied to every shading vertex of the parts that have a layer stack, with the sky and sun each
//! vertex sees from the ray tracer, and the scene rebuilt at an instant of the run for rendering.
//!
//! - [`exposure`]: sky view factors and sun visibility per vertex.
//! - [`solve`]: the per-vertex runs and the recorded surface temperatures.
//! - [`parts`]: min/mean/max per part over time.
//! - [`instant`]: the scene rebuilt at a recorded instant, for rendering.
//! - [`saved`]: a run's content key, and the run saved to a file and read back (sweeps).

pub mod exposure;
pub mod instant;
pub mod parts;
pub mod saved;
pub mod solve;

pub use instant::{scene_at, InstantError};
pub use parts::{part_series, PartSeries};
pub use saved::{SavedSolutionError, ThermalKey};
pub use solve::{solve_scene, vertex_surfaces, SolveStats, ThermalRunError, ThermalSolution};
