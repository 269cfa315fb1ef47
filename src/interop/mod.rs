//! Interchange with other tools. Today: Mitsuba 3's measured polarized BSDF tables (`.pbsdf`,
//! docs/design.md §2.10) — the format and its conventions, below the measurements and the
//! materials that use them: a material is written as a table by `material::pbsdf_export`
//! (`irpol export --to mitsuba`), a table read as measurements by `measure::pbsdf`
//! (`irpol fit F.pbsdf`).
//!
//! One job per module: [`tensor_file`] the container, [`pbsdf`] the table's fields,
//! [`convention`] Mitsuba's angles and Stokes frames against psps, [`grid`] the grid that
//! follows a model, [`tabulate`] a model on a grid, [`lookup`] Mitsuba's interpolation.

pub mod convention;
pub mod grid;
pub mod lookup;
pub mod pbsdf;
pub mod tabulate;
pub mod tensor_file;

pub use pbsdf::{is_tensor_file, PbsdfFile, PbsdfGrid, PbsdfTable};
pub use tensor_file::TensorError;
