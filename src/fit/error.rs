//! Why a fit is refused or fails.

use crate::material::MaterialError;
use crate::measure::MeasureError;
use std::path::PathBuf;

#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// A measurement file could not be read or is malformed (`file:line:column: …`).
    #[error(transparent)]
    Read(#[from] MeasureError),
    /// Rows selected that a file does not hold.
    #[error(transparent)]
    Selection(#[from] crate::measure::SelectionError),
    /// A measurement set that cannot be fitted.
    #[error("{}: {message}", crate::text::path(file))]
    Measurement { file: PathBuf, message: String },
    /// Inconsistent or invalid fit options.
    #[error("invalid fit options: {0}")]
    Options(String),
    /// A fit refused before any work for what it would cost ([`super::cost`]): the message names
    /// the file, the estimate's factors and the flag that allows it.
    #[error("{0}")]
    Cost(String),
    /// Two inputs of one material that cannot be merged into one measurement set.
    #[error(transparent)]
    Merge(#[from] crate::measure::MergeError),
    /// An optimizer failed (a bug or a degenerate problem, not bad input).
    #[error("{}: the {stage} stage failed: {message}", crate::text::path(file))]
    Optimizer {
        file: PathBuf,
        stage: String,
        message: String,
    },
    #[error(transparent)]
    Material(#[from] MaterialError),
}

impl From<crate::measure::ReadError> for FitError {
    fn from(error: crate::measure::ReadError) -> FitError {
        match error {
            crate::measure::ReadError::Measure(e) => FitError::Read(e),
            crate::measure::ReadError::Selection(e) => FitError::Selection(e),
        }
    }
}
