//! Interchange with other tools. Today: Mitsuba 3's measured polarized BSDF tables (`.pbsdf`,
//! docs/design.md §2.10), written from a material (`irpol export --to mitsuba`) and read as
//! measurements (`irpol fit F.pbsdf`).
//!
//! One job per module: [`tensor_file`] the container, [`pbsdf`] the table's fields,
//! [`convention`] Mitsuba's angles and Stokes frames against psps, [`grid`] the grid that
//! follows a material, [`tabulate`] a model on a grid, [`lookup`] Mitsuba's interpolation,
//! [`export`] a material as a table, [`measurements`] a table as measurement sets.

pub mod convention;
pub mod export;
pub mod grid;
pub mod lookup;
pub mod measurements;
pub mod pbsdf;
pub mod tabulate;
pub mod tensor_file;

pub use export::{export_material, Export, ExportError, ExportOptions};
pub use measurements::read_table_measurements;
pub use pbsdf::{is_tensor_file, PbsdfFile, PbsdfGrid, PbsdfTable};
pub use tensor_file::TensorError;
