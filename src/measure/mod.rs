//! Measurement ingestion (docs/design.md §2.1): SOC-style Mueller-matrix BRDF CSV files into a validated
//! [`MeasurementSet`], the input of the fit. Anything ambiguous is refused with a
//! `file:line:column: what is wrong` [`MeasureError`]; nothing here writes.
//!
//! A file holds one material, at one wavelength or, in a wavelength_um column without a
//! `# wavelength_um:` header, at several (a spectral set, docs/design.md §1.9; [`read_measurement_sets`]):
//! ```text
//! # material: gloss_paint
//! # wavelength_um: 9.925
//! # mueller_convention: psps
//! theta_i_deg,phi_i_deg,theta_r_deg,phi_r_deg,m00,m01,u_m00
//! 60,0,55,180,1.92e-01,-3.1e-02,2e-03
//! ```
//! Required columns: theta_i_deg, theta_r_deg (signed: θ_r < 0 is read as (|θ_r|, φ_r + 180°),
//! with a note), m00. Optional: phi_i_deg (default 0°),
//! phi_r_deg (default 180°), wavelength_um (else the `# wavelength_um:` header; both must agree),
//! any of m01…m33, and absolute 1-σ uncertainties u_m00…u_m33 for any subset of the elements
//! present. Mueller elements are BRDF values in sr⁻¹ in SCATMECH's psps convention (docs/design.md §1.3),
//! not normalized by m00.
//!
//! Tables in an instrument's own columns and conventions are read through a [`Layout`]
//! (docs/design.md §2.8), given by the caller or named by the file's `# layout: FILE` line
//! ([`read_measurement_file`]); [`RowSelection`] keeps one wavelength and chosen incidence angles,
//! and [`unrealizable_rows`] flags rows that no passive surface can produce (Cloude).

mod columns;
mod csv_reader;
mod error;
mod files;
mod fingerprint;
mod layout;
mod merge;
mod metadata;
mod pbsdf;
mod reading;
mod realizability;
mod rows;
mod selection;
mod streaming;
mod table_file;
mod units;

use std::collections::BTreeMap;
use std::path::PathBuf;

pub use csv_reader::{
    parse_measurement_csv, parse_measurement_sets, read_measurement_csv, read_measurement_sets,
};
pub use error::{MeasureError, MeasureErrorKind};
pub use files::collect_measurement_files;
pub use fingerprint::SourceData;
pub use layout::{
    parse_with_layout, read_with_layout, xyxy_to_psps, AngleUnit, ColumnRoles, Conventions, Layout,
    MuellerBasis, SpecularAzimuth, UncertaintyModel,
};
pub use merge::{merge_repeat_measurements, MergeError, SAME_WAVELENGTH_UM};
pub use pbsdf::{read_table_measurements, MAX_TABLE_ROWS_PER_WAVELENGTH};
pub use reading::{
    parse_measurement_file, read_measurement_file, ReadError, ReadOptions, LAYOUT_KEY,
};
pub use realizability::{unrealizable_rows, Realizability};
pub use rows::{MeasurementRow, MeasurementRows, Rows};
pub use selection::{RowSelection, SelectionError, THETA_I_TOLERANCE_DEG};
pub(crate) use streaming::file_sha256;
pub(crate) use table_file::{hex, read_bytes};
pub use units::{is_angle_note, AngleReading};

/// Largest |Mueller element| and uncertainty a measurement file may hold (sr⁻¹): far above the
/// mirror peak of the smoothest model (σ = 1e-4, ~1e7 sr⁻¹), small enough that every weighted
/// residual, squared and summed over the largest file, stays finite (m00 = 1e308 once made a
/// fit whose χ² and covariance were inf and nan, written into the material file).
pub const MAX_MUELLER_SR: f64 = 1e12;

/// Smallest uncertainty (sr⁻¹): a subnormal one (5e-324) made every residual it weighs infinite.
/// Measured BRDF noise floors are ~1e-8 sr⁻¹.
pub const MIN_UNCERTAINTY_SR: f64 = 1e-15;

/// Column names of the 16 Mueller elements; element (r, c) has index r*4 + c (row-major).
pub const MUELLER_ELEMENT_NAMES: [&str; 16] = [
    "m00", "m01", "m02", "m03", "m10", "m11", "m12", "m13", "m20", "m21", "m22", "m23", "m30",
    "m31", "m32", "m33",
];

/// Row-major index r*4 + c of a Mueller element name such as `"m12"` (→ 6).
pub fn mueller_index(name: &str) -> Option<usize> {
    MUELLER_ELEMENT_NAMES.iter().position(|&m| m == name)
}

/// One measured geometry, owned: the Mueller elements of [`MeasurementSet::elements`] at (θ_i, φ_i) →
/// (θ_r, φ_r), directions pointing away from the surface (docs/design.md §1.1). A set stores its
/// rows as columns ([`MeasurementRows`]); this is one of them taken out, or one to build a set
/// from ([`MeasurementRows`] collects points).
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementPoint {
    /// Incidence zenith angle, degrees, in [0, 90).
    pub theta_i_deg: f64,
    /// Incidence azimuth, degrees (0 when the file has no phi_i_deg column).
    pub phi_i_deg: f64,
    /// Receiver zenith angle, degrees, in [0, 90) (a negative value in the file is read as
    /// (|θ_r|, φ_r + 180°)).
    pub theta_r_deg: f64,
    /// Receiver azimuth, degrees (180, the specular side, when the file has no phi_r_deg column).
    pub phi_r_deg: f64,
    /// Mueller-matrix BRDF elements, sr⁻¹, aligned with [`MeasurementSet::elements`]; `values[0]`
    /// is m00 ≥ 0.
    pub values: Vec<f64>,
    /// Absolute 1-σ uncertainties, sr⁻¹ (> 0), aligned with [`MeasurementSet::elements`]:
    /// `Some` for each element that has a `u_` column, `None` for the others. Which elements
    /// have one is the same for every point of a set, because it is decided by the header row.
    pub uncertainties: Vec<Option<f64>>,
    /// 1-based line of the row in the file, for messages.
    pub line: u64,
}

/// A validated measurement file: one material at one wavelength.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementSet {
    /// The path as given by the caller.
    pub source: PathBuf,
    /// Lower-case hex SHA-256 of the file's bytes (fit provenance, docs/design.md §2.2).
    pub sha256: String,
    /// The `# material:` header, else the file stem.
    pub material: String,
    /// Wavelength, µm: the `# wavelength_um:` header, else the wavelength_um column (one value
    /// per file).
    pub wavelength_um: f64,
    /// All `# key: value` header lines, material / wavelength_um / mueller_convention included.
    pub metadata: BTreeMap<String, String>,
    /// Mueller indices (r*4 + c) present in the file, ascending, so m00 (0) is always first.
    pub elements: Vec<usize>,
    /// The data rows in file order (after merging, `source`'s rows first), stored as columns
    /// whose values and uncertainties are aligned with `elements`; never empty.
    pub points: MeasurementRows,
    /// Further files of the same material and wavelength merged after `source` as repeat
    /// measurements ([`merge_repeat_measurements`]); empty for a set read from one file.
    pub merged: Vec<SourceFile>,
    /// What the reader did that the user should know (rows with θ_r < 0 read as (|θ_r|,
    /// φ_r + 180°), files merged), one line each, for the caller to print: the library never
    /// prints.
    pub notes: Vec<String>,
}

/// A measurement file merged into a [`MeasurementSet`].
#[derive(Debug, Clone, PartialEq)]
pub struct SourceFile {
    /// The path as given by the caller.
    pub path: PathBuf,
    /// Lower-case hex SHA-256 of the file's bytes.
    pub sha256: String,
    /// Its data rows.
    pub rows: usize,
    /// The fingerprint of its parsed data, taken before the merge (its own wavelength, which may
    /// differ from the set's by up to 1e-6 µm).
    pub data: SourceData,
}
