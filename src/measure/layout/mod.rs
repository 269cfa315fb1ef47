//! Instrument layouts (docs/design.md §2.8): a TOML file that maps the table an instrument or a
//! published dataset writes onto the meaning of docs/design.md §2.1, so such a table is read
//! without being rewritten. A lab writes one layout per instrument:
//! ```toml
//! [columns]                      # role = column name in the file
//! theta_i_deg = "thetai"
//! phi_i_deg = "phi"
//! theta_r_deg = "thetar"
//! phi_r_deg = "phir"
//! wavelength_um = "lambda"
//! m00 = "f_r11"
//! elements = "f_r{i}{j}/f_r11"   # or a table: elements = { m01 = "M12", m10 = "M21" }
//! [conventions]
//! index_base = 1                 # the pattern's {i}{j} count from 1 (f_r12 is m01)
//! normalized = true              # elements are m_ij/m00: multiplied by the row's m00
//! signed_angles = true           # θ < 0 is the direction across the normal, (|θ|, φ + 180°)
//! specular_phi_r = "phi_i + 180" # or "phi_i": where the file puts the specular azimuth
//! angle_unit = "deg"             # or "rad"
//! mueller_convention = "xyxy"    # or "psps"
//! [uncertainty]
//! model = "estimate"             # or "fixed" (the fit's 3 % / 1 % of m00)
//! ```
//! [`read_with_layout`] returns the same [`MeasurementSet`]s as
//! [`read_measurement_sets`](super::read_measurement_sets): degrees with θ ≥ 0, specular at
//! φ_r = φ_i + 180°, elements in sr⁻¹ indexed from 0 in SCATMECH's psps basis.

mod basis;
mod config;
mod table;
mod uncertainty;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use super::error::{MeasureError, MeasureErrorKind, Refusal};
use super::MeasurementSet;

pub use basis::xyxy_to_psps;

/// A parsed instrument layout (docs/design.md §2.8).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The layout file as given by the caller (messages name it).
    pub source: PathBuf,
    pub columns: ColumnRoles,
    pub conventions: Conventions,
    pub uncertainty: UncertaintyModel,
}

/// The file's column for each role of docs/design.md §2.1.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnRoles {
    pub theta_i: String,
    /// Absent: φ_i = 0 on every row.
    pub phi_i: Option<String>,
    pub theta_r: String,
    /// Absent: φ_r on the specular side of the plane of incidence on every row.
    pub phi_r: Option<String>,
    /// Absent: the file's `# wavelength_um:` line gives it.
    pub wavelength: Option<String>,
    /// The unpolarized BRDF, sr⁻¹ (named, or the element pattern's first element).
    pub m00: String,
    /// Column of each other Mueller element the layout names, by row-major index (1…15). A
    /// pattern names all fifteen; the file may hold any subset, as in docs/design.md §2.1.
    pub elements: BTreeMap<usize, String>,
    /// The element pattern as written, for messages (`None` for an explicit table).
    pub pattern: Option<String>,
}

/// How the file's numbers differ from docs/design.md §2.1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Conventions {
    /// 0: the pattern's indices run m00…m33; 1: they run 11…44.
    pub index_base: u8,
    /// Elements other than m00 are m_ij/m00.
    pub normalized: bool,
    /// θ < 0 is the direction across the normal, (|θ|, φ + 180°); otherwise θ < 0 is refused.
    pub signed_angles: bool,
    pub specular_phi_r: SpecularAzimuth,
    pub angle_unit: AngleUnit,
    pub mueller_convention: MuellerBasis,
}

impl Default for Conventions {
    /// docs/design.md §2.1's own conventions.
    fn default() -> Self {
        Self {
            index_base: 0,
            normalized: false,
            signed_angles: true,
            specular_phi_r: SpecularAzimuth::OppositeIncidence,
            angle_unit: AngleUnit::Degrees,
            mueller_convention: MuellerBasis::Psps,
        }
    }
}

/// Where the file puts the specular direction's azimuth.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SpecularAzimuth {
    /// φ_r = φ_i + 180° (irpol's, docs/design.md §1.1).
    OppositeIncidence,
    /// φ_r = φ_i: the file's φ_r is irpol's minus 180°.
    SameAsIncidence,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AngleUnit {
    Degrees,
    Radians,
}

/// The Stokes bases the file's Mueller matrices are written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MuellerBasis {
    /// SCATMECH's s/p basis of each direction (irpol's, docs/design.md §1.3).
    Psps,
    /// SCATMECH's x/y basis in the sample frame ([`xyxy_to_psps`]).
    Xyxy,
}

impl MuellerBasis {
    /// The name a layout and a `# mueller_convention:` line use.
    pub fn name(self) -> &'static str {
        match self {
            Self::Psps => "psps",
            Self::Xyxy => "xyxy",
        }
    }
}

/// Where the uncertainties come from when the file has none.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UncertaintyModel {
    /// From the data's own scatter (mirror pairs of an isotropic sample, else smoothness along
    /// θ_r), as a fraction of each row's m00.
    Estimate,
    /// None recorded: the fit's fixed 3 % of m00 on m00 and 1 % of m00 on the other elements.
    Fixed,
}

impl Layout {
    /// Reads and validates a layout TOML; `path` is quoted as given in every message.
    pub fn read(path: &Path) -> Result<Layout, MeasureError> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            let kind = match e.kind() {
                std::io::ErrorKind::NotFound => MeasureErrorKind::NotFound,
                _ => MeasureErrorKind::Unreadable {
                    reason: e.to_string(),
                },
            };
            Refusal::new(1, 1, kind).in_file(path)
        })?;
        Self::parse(path, &text)
    }

    /// [`Layout::read`] of a layout's text; `source` names it.
    pub fn parse(source: &Path, text: &str) -> Result<Layout, MeasureError> {
        config::parse_layout(text)
            .map(|(columns, conventions, uncertainty)| Layout {
                source: source.to_path_buf(),
                columns,
                conventions,
                uncertainty,
            })
            .map_err(|refusal| refusal.in_file(source))
    }
}

/// Reads a measurement table through `layout` as one [`MeasurementSet`] per wavelength,
/// ascending, converted to docs/design.md §2.1's meaning (docs/design.md §2.8). `path` is quoted
/// as given in every message.
pub fn read_with_layout(path: &Path, layout: &Layout) -> Result<Vec<MeasurementSet>, MeasureError> {
    let bytes = super::table_file::read_bytes(path)?;
    parse_with_layout(path, &bytes, layout)
}

/// [`read_with_layout`] of a table's bytes; `source` names them.
pub fn parse_with_layout(
    source: &Path,
    bytes: &[u8],
    layout: &Layout,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    table::parse_table(source, bytes, layout, super::AngleReading::Auto)
}

/// [`parse_with_layout`] with `--angles` (radians declared as degrees are refused unless it
/// says how to read them).
pub(crate) fn parse_with_layout_reading(
    source: &Path,
    bytes: &[u8],
    layout: &Layout,
    angles: super::AngleReading,
) -> Result<Vec<MeasurementSet>, MeasureError> {
    table::parse_table(source, bytes, layout, angles)
}
