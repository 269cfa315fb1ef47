//! Fitting pBRDF models to Mueller-matrix measurements (docs/design.md §3, `src/fit/`).
//!
//! A [`MeasurementSet`](crate::measure::MeasurementSet) is fitted by weighted least squares over
//! every Mueller element it holds ([`objective`](Objective)), with the weights from the file's
//! `u_` columns or a default noise model ([`DEFAULT_M00_RELATIVE_ERROR`]), optionally with a
//! [`RobustLoss`]. Any subset of σ, q, n, k, ρ_d is free inside bounds ([`parameters`]); the
//! optimizer is a sequence of stages ([`Optimizer`]): a seeded genetic algorithm over the box
//! ([`genetic`]), then local polishing by Nelder–Mead and/or Levenberg–Marquardt, with restarts
//! out of the known traps of this problem (k = 0 is stationary for the linear elements; lobes
//! pinned at a σ or q bound). The result carries 1-σ errors and correlations from the Jacobian
//! ([`Uncertainty`]) and, when both slope distributions are fitted, an AIC/BIC comparison
//! ([`ModelComparison`]).
//!
//! Entry points: [`fit_measurement`] for one set, [`fit_files`] for `irpol fit`.

mod admissible;
mod comparison;
pub mod cost;
mod cross_validation;
mod data;
mod data_view;
mod energy;
mod error;
mod files;
pub mod genetic;
mod global;
mod levenberg_marquardt;
mod model_fit;
mod nelder_mead;
mod normal_equations;
mod objective;
mod optimize;
mod option_error;
mod options;
mod outcome;
pub mod parameters;
mod profile;
mod robust;
mod space;
mod spectral;
mod stages;
mod terms_choice;
mod uncertainty;
mod validation;

pub use admissible::{why_inadmissible, STRONG_ABSORPTION_K};
pub use comparison::{aic, bic, Candidate, ModelComparison};
pub use cross_validation::{
    fit_choosing_terms, fit_grey, fold_rows, subset, TermsChoice, TermsScore, CHOICE_POINTS,
    DEFAULT_FOLDS, MAX_FOLDS,
};
pub use data::{
    observation_sigmas, ErrorSource, MeasurementData, DEFAULT_M00_RELATIVE_ERROR,
    DEFAULT_OTHER_ERROR_PER_M00,
};
pub use energy::{largest_reflectance, ENERGY_TOLERANCE};
pub use error::FitError;
pub use files::{fit_files, fit_inputs, fit_inputs_with, fit_read_inputs, FitInputs, MaterialFit};
pub use global::GeneticSettings;
pub use levenberg_marquardt::LevenbergMarquardtSettings;
pub use model_fit::ModelFit;
pub use nelder_mead::NelderMeadSettings;
pub use objective::{BoxCost, Objective};
pub use optimize::{coarse_stride, OptimizerSettings, COARSE_POINTS};
pub use option_error::OptionError;
pub use options::{parse_parameter_list, parse_parameter_values, FitOptions};
pub use outcome::{fit_measurement, FitOutcome};
pub use parameters::{Interval, InvalidBounds, ParameterBounds, ParameterValues, SMITH_MIN_Q};
pub use profile::{CONFIDENCE, ONE_SIDED_95_DELTA_CHI2};
pub use robust::RobustLoss;
pub use space::ModelSpace;
pub use spectral::{fit_spectral, Dispersion, SpectralFit, SpectralFitOutcome};
pub use stages::{ConvergenceHistory, Optimizer, Stage, StageHistory};
pub use uncertainty::Uncertainty;
pub use validation::{validate_model, ElementError, Validation};
