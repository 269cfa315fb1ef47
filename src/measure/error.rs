//! Errors of measurement ingestion (docs/design.md §2.1): every refusal names the file, the 1-based line
//! and the 1-based character column of the offending field, then says what is wrong, so that
//! `irpol fit` can print it as one line (`file:line:column: what is wrong`).

use crate::table_text::{TableError, TokenProblem};

/// A refused measurement input: the table reader's [`TableError`], displayed exactly as
/// `file:line:column: what is wrong`, with the file as the caller gave it. Whole-file problems
/// point at line 1 column 1 (or at the header row when they concern the columns).
pub type MeasureError = TableError<MeasureErrorKind>;

/// A refusal located in the file but not yet tied to a path; the reader attaches the path.
pub(crate) type Refusal = crate::table_text::Refusal<MeasureErrorKind>;

impl TableError<MeasureErrorKind> {
    /// The path could not be read at all (missing, a folder, unreadable), as opposed to a file
    /// that reads but is malformed: an I/O failure to callers that sort errors that way (the
    /// Python bindings' `OSError`). The reader keeps no `std::io::Error` source, so this is it.
    pub fn is_unreadable_path(&self) -> bool {
        matches!(
            self.kind,
            MeasureErrorKind::NotFound
                | MeasureErrorKind::IsDirectory
                | MeasureErrorKind::Unreadable { .. }
        )
    }
}

/// The reason a measurement input is refused. Values are quoted as they appear in the file
/// (trimmed), so the message can be matched against the file by eye.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum MeasureErrorKind {
    // --- the path itself ---
    #[error("no such file or directory")]
    NotFound,
    #[error("is a directory, expected a CSV file")]
    IsDirectory,
    #[error("cannot read: {reason}")]
    Unreadable { reason: String },
    #[error("the folder holds no *.csv files")]
    NoCsvInFolder,

    // --- Mitsuba tensor files (docs/design.md §2.10) ---
    #[error("Mitsuba table: {0}")]
    Table(crate::interop::TensorError),
    #[error("Mitsuba table: no node has both cosines > 0 and a finite m00 > 0 ({skipped} skipped): there is no reflection to fit")]
    NoTableRows { skipped: usize },

    // --- whole-file structure ---
    #[error("invalid UTF-8 (byte 0x{byte:02X}): a measurement CSV must be UTF-8 text")]
    InvalidUtf8 { byte: u8 },
    #[error("the file is empty")]
    EmptyFile,
    #[error("no header row: the file holds only comments and metadata")]
    NoHeader,
    #[error("a header row but no data rows")]
    NoDataRows,
    #[error("the file changed while it was read (its bytes differ between the reader's two passes): read it again once it is no longer being written")]
    ChangedWhileRead,

    // --- field splitting ---
    #[error("{0}")]
    Token(TokenProblem),

    // --- `# key: value` metadata ---
    #[error("header '{key}' given twice (first on line {first_line})")]
    DuplicateHeaderKey { key: String, first_line: u64 },
    #[error("header '{key}' has no value")]
    EmptyHeaderValue { key: String },
    #[error("header 'wavelength_um': '{value}' is not a positive number of micrometres")]
    BadHeaderWavelength { value: String },
    #[error("header 'mueller_convention': '{value}' is not supported; irpol uses 'psps' (SCATMECH's Stokes convention)")]
    UnsupportedConvention { value: String },
    #[error("header 'material': '{name}' cannot name a file ({reason})")]
    BadMaterialName { name: String, reason: String },

    // --- the header row ---
    #[error("empty column name (a doubled or trailing ',' in the header row)")]
    EmptyColumnName,
    #[error("unknown column '{name}'{hint}")]
    UnknownColumn { name: String, hint: String },
    #[error("duplicate column '{name}' (already column {first_column} of the header row)")]
    DuplicateColumn { name: String, first_column: u64 },
    #[error("missing required column '{name}'")]
    MissingColumn { name: String },
    #[error(
        "column '{name}' is the uncertainty of '{element}', but there is no '{element}' column"
    )]
    UncertaintyWithoutElement { name: String, element: String },
    #[error(
        "no wavelength: add a 'wavelength_um' column or a '# wavelength_um: <micrometres>' header line"
    )]
    NoWavelength,

    // --- data rows ---
    #[error("the row has {found} fields, the header row has {expected}")]
    FieldCount { found: usize, expected: usize },
    #[error("column '{column}' is empty, expected a number")]
    EmptyField { column: String },
    #[error("column '{column}': '{value}' is not a number")]
    NotANumber { column: String, value: String },
    #[error("column '{column}': '{value}' is not a finite number")]
    NotFinite { column: String, value: String },
    #[error("column '{column}': {value} is outside [0°, 90°) (zenith angles of the hemisphere above the surface)")]
    ThetaOutOfRange { column: String, value: String },
    #[error("column 'theta_r_deg': {value} is outside (−90°, 90°) (detector zenith angles; a negative one is read as (|θ_r|, φ_r + 180°))")]
    DetectorThetaOutOfRange { value: String },
    #[error("column 'm00': {value} is negative, but m00 (the unpolarized BRDF, sr⁻¹) is ≥ 0")]
    NegativeM00 { value: String },
    #[error("column '{column}': {value} is not a positive uncertainty")]
    NonPositiveUncertainty { column: String, value: String },
    #[error(
        "column '{column}': {value} sr⁻¹ is beyond ±{} sr⁻¹, far above any measurable BRDF (the \
         mirror peak of the smoothest model is ~1e7 sr⁻¹): a fit of it has no finite χ²",
        crate::text::number(super::MAX_MUELLER_SR)
    )]
    ElementTooLarge { column: String, value: String },
    #[error(
        "column '{column}': uncertainty {value} sr⁻¹ is outside {}…{} sr⁻¹: weighted by it, a \
         residual has no finite square",
        crate::text::number(super::MIN_UNCERTAINTY_SR),
        crate::text::number(super::MAX_MUELLER_SR)
    )]
    UncertaintyOutOfRange { column: String, value: String },
    #[error("column 'wavelength_um': {value} is not a positive wavelength")]
    NonPositiveWavelength { value: String },
    #[error("{place}: {value} µm is outside 0.1–1000 µm, the wavelengths irpol models")]
    WavelengthOutOfRange { place: String, value: String },
    #[error("column 'm00' is 0 on every row: there is no reflection to fit")]
    AllM00Zero,
    #[error(
        "column 'wavelength_um': {value} disagrees with the header '# wavelength_um: {header}' (line {header_line})"
    )]
    WavelengthDisagrees {
        value: String,
        header: String,
        header_line: u64,
    },
    #[error(
        "column 'wavelength_um': {value} differs from {first} on line {first_line}: the file holds several wavelengths, a spectral set, which `irpol fit` reads as one material but this reader of one wavelength cannot"
    )]
    MixedWavelengths {
        value: String,
        first: String,
        first_line: u64,
    },

    // --- instrument layouts (docs/design.md §2.8) ---
    #[error("not a valid layout: {message}")]
    LayoutSyntax { message: String },
    #[error("layout key {key}: {message}")]
    LayoutValue { key: &'static str, message: String },
    #[error("column '{column}', which the layout {layout} names for {role}, is not in the header row: fix [columns] {role} (names are case-sensitive)")]
    LayoutColumnMissing {
        column: String,
        role: &'static str,
        layout: String,
    },
    #[error("column '{column}' is named for both {first_role} and {second_role}: one column holds one role; fix [columns] {second_role}")]
    LayoutColumnTwoRoles {
        column: String,
        first_role: &'static str,
        second_role: &'static str,
    },
    #[error("the element pattern '{pattern}' of the layout {layout} matches no column of the header row (it names {names}): fix the pattern or index_base")]
    ElementPatternMatchesNothing {
        pattern: String,
        layout: String,
        names: String,
    },
    #[error("the layout's mueller_convention = \"xyxy\" is rotated into psps, which mixes {present} with {missing}, but the file has no column for {missing}: add it, or say mueller_convention = \"psps\" if the file already is psps")]
    BasisNeedsElement {
        present: &'static str,
        missing: &'static str,
    },
    #[error("column '{column}': {value}° is not a zenith angle within {}: the layout says angle_unit = \"deg\"; if the file's angles are in radians, set angle_unit = \"rad\"", if *.signed { "(−90°, 90°)" } else { "[0°, 90°)" })]
    LayoutDegreesOutOfRange {
        column: String,
        value: String,
        signed: bool,
    },
    #[error("column '{column}': {value} rad is not a zenith angle within {}: the layout says angle_unit = \"rad\"; if the file's angles are in degrees, set angle_unit = \"deg\"", if *.signed { "(−π/2, π/2)" } else { "[0, π/2)" })]
    LayoutRadiansOutOfRange {
        column: String,
        value: String,
        signed: bool,
    },
    #[error("column '{column}': {value} is negative, but the layout says signed_angles = false: set signed_angles = true if θ < 0 is the direction across the normal")]
    LayoutNegativeAngle { column: String, value: String },
    #[error("column '{column}' (the layout's m00): {value} is negative, but m00 (the unpolarized BRDF, sr⁻¹) is ≥ 0")]
    LayoutNegativeM00 { column: String, value: String },
    #[error("header 'layout': the file names the layout {named}, but the layout {given} was given too and reads the table differently: give one of them (drop --layout, or the '# layout:' line)")]
    LayoutsDisagree { named: String, given: String },
    #[error("{evidence}, but the angles are declared in degrees: {fix}")]
    LooksLikeRadians { evidence: String, fix: String },
    #[error("{flag}: {reason}")]
    AnglesFlag { flag: &'static str, reason: String },
    #[error("header 'layout': '{value}' (looked for at {path}, beside the file): {reason}: fix the path, relative to the measurement file's folder")]
    NamedLayoutUnreadable {
        value: String,
        path: String,
        reason: String,
    },
    #[error("header 'mueller_convention': '{value}' disagrees with the layout's mueller_convention = \"{layout_value}\"")]
    ConventionDisagreesWithLayout {
        value: String,
        layout_value: &'static str,
    },
}
