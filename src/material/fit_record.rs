//! How a material was fitted (docs/design.md §2.2): the `[fit]` table of a library entry —
//! provenance, optimizer, quality, uncertainties, what the data do not determine — and the
//! rules that read it (misfit, identification).

use super::ModelSpec;
use crate::text::{number, significant};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// How a material was fitted (docs/design.md §2.2): provenance, optimizer, quality and uncertainties.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitRecord {
    /// The measurement file, as given to `irpol fit`, and the SHA-256 of its bytes.
    pub source: PathBuf,
    pub source_sha256: String,
    /// The fingerprint of the source's parsed data (absent in files written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_data: Option<crate::measure::SourceData>,
    /// The instrument layout the sources were read through (docs/design.md §2.8), as given to
    /// `irpol fit --layout`; absent when the files were read as they say (docs/design.md §2.1,
    /// or through a layout their own `# layout:` line names).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub layout: Option<PathBuf>,
    /// The rows of the sources that were fitted (`--wavelength`, `--theta-i`); absent: all.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub selection: Option<crate::measure::RowSelection>,
    /// How the sources' angles were read when `irpol fit --angles` said (`degrees` or
    /// `radians`); absent: as the files declare them.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub angles: Option<crate::measure::AngleReading>,
    /// Further files of the same material and wavelength fitted with `source` as repeat
    /// measurements, in the order their rows follow its rows; absent for a fit of one file.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub merged_sources: Vec<MergedSource>,
    /// Measured geometries (rows) used, over all source files.
    pub points: usize,
    /// Mueller elements used, e.g. ["m00", "m01", …].
    pub elements: Vec<String>,
    pub free_parameters: Vec<String>,
    /// The model's parameters held fixed (`--fix`, or left out of `--free`), with their values.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub fixed_parameters: BTreeMap<String, f64>,
    pub optimizer: String,
    pub seed: u64,
    pub settings: BTreeMap<String, String>,
    pub iterations: u64,
    pub evaluations: u64,
    pub cost: f64,
    pub reduced_chi2: f64,
    pub degrees_of_freedom: usize,
    pub aic: f64,
    pub bic: f64,
    pub termination: String,
    /// Root-mean-square residual per Mueller element (sr⁻¹).
    pub rmse: BTreeMap<String, f64>,
    /// 1-σ uncertainty per free parameter (scaled by the reduced χ²).
    pub uncertainty: BTreeMap<String, f64>,
    /// Correlation matrix of the free parameters, in `free_parameters` order.
    pub correlation: Vec<Vec<f64>>,
    /// Free parameters the data do not determine (no sensitivity, |ρ| > 0.999, or a 1-σ error
    /// above both 50 % of the value and 1 % of the search interval).
    #[serde(default)]
    pub undetermined: Vec<String>,
    /// Free parameters resting on a bound of their search interval (e.g. ρ_d = 0).
    #[serde(default)]
    pub at_bound: Vec<String>,
    /// The `at_bound` parameters pinned at a bound other than zero (σ at its largest, q at its
    /// smallest, n at 10, …): the search wanted to go where the model means nothing, so the fit
    /// does not describe its data ([`FitRecord::misfit`]). A zero (ρ_d = 0, k = 0, Cauchy B = 0:
    /// the term absent) is an answer of the data, not a sign of a bad fit.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub pinned: Vec<String>,
    /// One-sided profile-likelihood bounds of the parameters whose 1-σ `uncertainty` does not
    /// describe what the data allow: the undetermined ones, and those the data bound from one
    /// side only (a linear 95 % interval reaching an end of the search interval).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub profile_bounds: BTreeMap<String, ConfidenceBound>,
    /// A spectral fit's 1-σ errors of the per-wavelength parameters (`n`, `k`, `rho_d`), one per
    /// table wavelength (`uncertainty` holds the shared ones: σ, q and a law's).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub uncertainty_per_wavelength: BTreeMap<String, Vec<f64>>,
    /// A spectral fit's quality at each wavelength.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub wavelengths: Vec<WavelengthQuality>,
    /// A spectral fit's dispersion: which was kept and the information criteria of each fitted.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dispersion: Option<DispersionChoice>,
    /// How the slope distribution was chosen when both were fitted (AIC/BIC comparison).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub model_choice: Option<String>,
    /// The competing slope distribution's best fit, for model comparison.
    pub alternative: Option<AlternativeFit>,
    /// Best cost after each global-stage generation, then after each local-stage iteration (for the
    /// report's convergence plot); the first `global_iterations` entries are the global stage.
    #[serde(default)]
    pub convergence: Vec<f64>,
    #[serde(default)]
    pub global_iterations: usize,
}

/// |ρ| above which two fitted parameters count as one combination the data determine, not two
/// (docs/design.md §1.10 "Identification").
pub const STRONG_CORRELATION: f64 = 0.98;

/// χ²_red above which a fit does not describe its data ([`FitRecord::misfit`]): the model's
/// residuals are more than three times the stated noise. The shipped fits reach 1.0 (synthetic
/// data) and 6.0 (NIST's PTFE, whose noise is estimated).
pub const MISFIT_REDUCED_CHI2: f64 = 10.0;

/// |value| below which a parameter on a bound of its search interval counts as zero (a term
/// absent, [`FitRecord::pinned`]); a search coordinate at its bound leaves ρ_d ≈ 1e-6.
pub const ZERO_AT_BOUND: f64 = 1e-4;

/// The parameters of `names` in `at_bound` whose value (aligned with `names`) is not zero: the
/// record's [`FitRecord::pinned`].
pub fn pinned_at_bound(at_bound: &[String], names: &[String], values: &[f64]) -> Vec<String> {
    names
        .iter()
        .zip(values)
        .filter(|(name, value)| at_bound.contains(name) && value.abs() > ZERO_AT_BOUND)
        .map(|(name, _)| name.clone())
        .collect()
}

impl FitRecord {
    /// Why the fit does not describe its data, one clause each (`χ²_red = 1508 > 10`, `pinned at
    /// a bound of the search interval: sigma, q`); empty for a fit that does. The fit warns of
    /// these, `--strict` refuses them, and the report and the library index mark them.
    pub fn misfit(&self) -> Vec<String> {
        let chi2 = (self.reduced_chi2 > MISFIT_REDUCED_CHI2).then(|| {
            format!(
                "χ²_red = {} > {MISFIT_REDUCED_CHI2}",
                crate::text::significant_trimmed(self.reduced_chi2, 4)
            )
        });
        let pinned = (!self.pinned.is_empty()).then(|| {
            format!(
                "pinned at a bound of the search interval: {}",
                self.pinned.join(", ")
            )
        });
        chi2.into_iter().chain(pinned).collect()
    }

    /// The fitted parameters the data do not determine (docs/design.md §1.10
    /// "Identification"), each with why: resting on a bound of its search interval, without
    /// sensitivity or a profile wider than its range (undetermined), or correlated beyond
    /// |ρ| = [`STRONG_CORRELATION`] with another. Names as in `free_parameters`; a pair is named
    /// once, by its first member.
    pub fn identification(&self) -> Vec<(String, String)> {
        let mut notes: Vec<(String, String)> = Vec::new();
        for name in &self.at_bound {
            notes.push((name.clone(), "at a bound of its search interval".into()));
        }
        for name in &self.undetermined {
            if !self.at_bound.contains(name) {
                notes.push((name.clone(), "not determined (no sensitivity)".into()));
            }
        }
        let names = &self.free_parameters;
        for (a, row) in self.correlation.iter().enumerate().take(names.len()) {
            for (b, &rho) in row.iter().enumerate().take(names.len()).skip(a + 1) {
                if rho.abs() > STRONG_CORRELATION {
                    notes.push((
                        names[a].clone(),
                        format!("correlated with {} (ρ = {})", names[b], significant(rho, 3)),
                    ));
                }
            }
        }
        notes
    }

    /// Keeps the record writable when the data do not determine a parameter at all (its 1-σ
    /// error infinite, as for a subsurface term's d and d_c when ρ_s → 0): the parameter is listed
    /// as undetermined, its error left out of `uncertainty` and its correlations written as 0,
    /// instead of the whole entry being refused for a non-finite number.
    pub fn mark_non_finite_as_undetermined(&mut self) {
        let infinite: Vec<String> = self
            .uncertainty
            .iter()
            .filter(|(_, e)| !e.is_finite())
            .map(|(name, _)| name.clone())
            .collect();
        for name in infinite {
            self.uncertainty.remove(&name);
            if !self.undetermined.contains(&name) {
                self.undetermined.push(name);
            }
        }
        for value in self.correlation.iter_mut().flatten() {
            if !value.is_finite() {
                *value = 0.0;
            }
        }
    }
}

/// What the data say about a parameter they do not determine: a one-sided bound on each side of
/// the fitted value from the profile likelihood (χ² minimized over the other parameters rises by
/// z² s² there, z the one-sided quantile of `confidence`). A missing side means the data allow
/// every value on that side within the fit's search interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConfidenceBound {
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lower: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub upper: Option<f64>,
    /// The confidence of each side's bound (0.95).
    pub confidence: f64,
}

impl ConfidenceBound {
    /// "k < 0.0312 (95 %)", "n > 1.21 (95 %)", "0.8 < n < 2.1 (95 % each side)", or
    /// "k not bounded in the search interval".
    pub fn describe(&self, name: &str) -> String {
        let percent = number(100.0 * self.confidence);
        match (self.lower, self.upper) {
            (None, Some(upper)) => format!("{name} < {} ({percent} %)", significant(upper, 3)),
            (Some(lower), None) => format!("{name} > {} ({percent} %)", significant(lower, 3)),
            (Some(lower), Some(upper)) => format!(
                "{} < {name} < {} ({percent} % each side)",
                significant(lower, 3),
                significant(upper, 3)
            ),
            (None, None) => format!("{name} not bounded in the search interval"),
        }
    }
}

/// How well a spectral fit matches one wavelength's data.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WavelengthQuality {
    pub wavelength_um: f64,
    pub points: usize,
    /// χ² of this wavelength's observations over their number.
    pub chi2_per_observation: f64,
}

/// The dispersion of a spectral fit and, when a law was fitted, the comparison with the table
/// (docs/design.md §1.9: the AIC of both).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DispersionChoice {
    /// `table` or `lorentz:N`.
    pub chosen: String,
    pub table_aic: f64,
    pub table_bic: f64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law_aic: Option<f64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub law_bic: Option<f64>,
}

/// A measurement file merged into a fit after [`FitRecord::source`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MergedSource {
    /// The file as given to `irpol fit`, and the SHA-256 of its bytes.
    pub source: PathBuf,
    pub source_sha256: String,
    /// The fingerprint of its parsed data (as [`FitRecord::source_data`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub source_data: Option<crate::measure::SourceData>,
    /// Its rows.
    pub points: usize,
}

/// The other distribution's best fit on the same data (model comparison by AIC/BIC).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AlternativeFit {
    pub model: ModelSpec,
    pub cost: f64,
    pub reduced_chi2: f64,
    pub aic: f64,
    pub bic: f64,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn confidence_bounds_say_which_sides_the_data_bound() {
        let bound = |lower, upper| ConfidenceBound {
            lower,
            upper,
            confidence: 0.95,
        };
        assert_eq!(
            bound(None, Some(0.031234)).describe("k"),
            "k < 0.0312 (95 %)"
        );
        assert_eq!(bound(Some(1.2157), None).describe("n"), "n > 1.22 (95 %)");
        assert_eq!(
            bound(Some(0.8), Some(2.1)).describe("n"),
            "0.800 < n < 2.10 (95 % each side)"
        );
        assert_eq!(
            bound(None, None).describe("q"),
            "q not bounded in the search interval"
        );
    }
}
