//! How well a model predicts a measurement it was not fitted to (docs/design.md §1.10, §4,
//! `irpol validate`): per Mueller element the RMS of model − measured (sr⁻¹) and, for the
//! elements other than m00, the RMS of the normalized elements m_ij/m00 (what polarimeters
//! measure best, and free of the absolute-radiometry error); for m00 the RMS of the relative
//! error (model − measured)/measured; and the normalized residuals (model − measured)/σ with the
//! σ the fit would use (the file's `u_` columns, else the default noise model).

use super::data::{ErrorSource, MeasurementData};
use super::FitError;
use crate::measure::{MeasurementSet, MUELLER_ELEMENT_NAMES};
use crate::optics::Mueller;
use crate::pbrdf::{Direction, Pbrdf};

/// The RMS prediction errors of one Mueller element.
#[derive(Clone, Debug, PartialEq)]
pub struct ElementError {
    /// `m00` … `m33`.
    pub name: &'static str,
    /// RMS of model − measured, sr⁻¹.
    pub rms: f64,
    /// RMS of model/measured − 1 for m00; of m_ij/m00 (model) − m_ij/m00 (measured) otherwise.
    pub rms_normalized: f64,
}

/// What [`validate_model`] measured.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    pub rows: usize,
    /// In the set's element order (m00 first).
    pub elements: Vec<ElementError>,
    /// RMS over every element but m00 of m_ij/m00 (model) − m_ij/m00 (measured).
    pub rms_normalized_elements: f64,
    /// Mean of r² over every observation, r = (model − measured)/σ.
    pub chi2_per_observation: f64,
    /// Largest |r|.
    pub max_abs_residual: f64,
    /// Whether every σ came from the file (else some from the default noise model).
    pub uncertainties_from_file: bool,
    /// Where the σ came from, in words (`σ from the file's u_ columns`, `σ estimated from the
    /// data by the layout (mirror pairs)`, `σ partly from the default noise model`).
    pub sigma_origin: String,
    /// The model's matrix at every row, in row order.
    pub model_muellers: Vec<Mueller>,
}

/// Where a set's σ came from: a layout's estimate from the data's own scatter fills the same
/// per-row uncertainties a file's `u_` columns do, so the set's `uncertainty_model` tells them
/// apart.
fn sigma_origin(set: &MeasurementSet, sources: &[ErrorSource]) -> String {
    let estimated = set
        .metadata
        .get("uncertainty_model")
        .and_then(|model| model.strip_prefix("estimate"));
    let from_rows = sources.iter().filter(|s| **s == ErrorSource::File).count();
    match (estimated, from_rows) {
        (Some(how), _) => format!("σ estimated from the data by the layout{how}"),
        (None, n) if n == sources.len() => "σ from the file's u_ columns".into(),
        (None, 0) => "σ from the default noise model, 3 % / 1 % of m00".into(),
        (None, _) => "σ partly from the default noise model".into(),
    }
}

impl Validation {
    /// m00's relative RMS error.
    pub fn m00_relative_rms(&self) -> f64 {
        self.elements[0].rms_normalized
    }
}

/// Scores `model` on every row of `set` (module docs).
pub fn validate_model(model: &Pbrdf, set: &MeasurementSet) -> Result<Validation, FitError> {
    let data = MeasurementData::new(set)?;
    let model_muellers: Vec<Mueller> = set
        .points
        .iter()
        .map(|p| {
            model.mueller(
                &Direction::from_degrees(p.theta_i_deg, p.phi_i_deg),
                &Direction::from_degrees(p.theta_r_deg, p.phi_r_deg),
            )
        })
        .collect();
    let width = set.elements.len();
    let mut squares = vec![(0.0, 0.0); width];
    let (mut chi2, mut max_abs) = (0.0f64, 0.0f64);
    for (row, (point, m)) in set.points.iter().zip(&model_muellers).enumerate() {
        let (measured00, model00) = (point.values[0], m[(0, 0)]);
        for (e, &index) in set.elements.iter().enumerate() {
            let (measured, predicted) = (point.values[e], m[(index / 4, index % 4)]);
            let normalized = if e == 0 {
                predicted / measured00 - 1.0
            } else {
                predicted / model00 - measured / measured00
            };
            squares[e].0 += (predicted - measured).powi(2);
            squares[e].1 += normalized.powi(2);
            let (_, sigma) = data.observation(row * width + e);
            let r = (predicted - measured) / sigma;
            chi2 += r * r;
            max_abs = max_abs.max(r.abs());
        }
    }
    let rows = set.points.len() as f64;
    let elements: Vec<ElementError> = set
        .elements
        .iter()
        .zip(&squares)
        .map(|(&index, &(abs, normalized))| ElementError {
            name: MUELLER_ELEMENT_NAMES[index],
            rms: (abs / rows).sqrt(),
            rms_normalized: (normalized / rows).sqrt(),
        })
        .collect();
    let others: f64 = squares.iter().skip(1).map(|s| s.1).sum();
    Ok(Validation {
        rows: set.points.len(),
        rms_normalized_elements: (others / (rows * (width.max(2) - 1) as f64)).sqrt(),
        elements,
        chi2_per_observation: chi2 / (rows * width as f64),
        max_abs_residual: max_abs,
        uncertainties_from_file: data.error_sources().iter().all(|s| *s == ErrorSource::File),
        sigma_origin: sigma_origin(set, data.error_sources()),
        model_muellers,
    })
}
