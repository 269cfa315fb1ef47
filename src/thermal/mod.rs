//! Temperatures from a thermal model (docs/design.md §1.8): per-vertex 1-D conduction through a
//! layer stack with the front surface energy balance. This is the numerical core; weather, the sun
//! and scenes feed it numbers per step.
//!
//! - [`layers`]: layer materials and stacks, validated, discretised into finite volumes.
//! - [`solver`]: implicit stepping with adaptive sub-steps, the non-linear surface balance and
//!   energy bookkeeping.
//! - [`batch`]: fixed-step BDF2 marching many vertices of one stack together, sharing one
//!   factorization per sub-step.
//! - [`config`], [`setup`]: a scene's `[thermal]` keys and their checked form (the run and each
//!   part's stack); [`convection`]: the front convective coefficient.
//!
//! The weather the surface balance needs (a CSV, an EPW or TMY3 file, a built-in clear day) is
//! read by [`crate::weather`], a layer below this one.

pub mod batch;
pub mod config;
pub mod convection;
mod forcing;
mod implicit_rows;
pub mod layers;
pub mod setup;
pub mod solver;

pub use batch::{
    BatchForcing, BatchReport, BatchSolver, BatchState, Lanes, BATCH_MAX_SUBSTEP_S, LANES,
};
pub use forcing::{Back, Forcing, FrontForcing};
pub use layers::{
    Grid, Layer, LayerLimit, LayerMaterial, LayerStack, Resolution, ThermalError, LAYER_LIMITS,
    MAX_GRID_NODES,
};
pub use solver::{Solver, SolverControl, StepReport, ThermalState};
