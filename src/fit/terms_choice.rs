//! What choosing a model's terms found ([`super::cross_validation`]): each candidate's scores
//! and which one was kept — the record a fit's outcome carries and the table `irpol fit` prints.

use crate::pbrdf::{DistributionKind, ModelTerms};

/// One candidate set of terms as the choice saw it.
#[derive(Clone, Debug, PartialEq)]
pub struct TermsScore {
    pub terms: ModelTerms,
    /// The distribution the candidate's own comparison kept.
    pub distribution: DistributionKind,
    pub free_parameters: usize,
    pub reduced_chi2: f64,
    pub aic: f64,
    /// Mean squared normalized residual on held-out folds, when folds were asked for.
    pub cv_score: Option<f64>,
}

/// The candidates' scores and which one was kept.
#[derive(Clone, Debug, PartialEq)]
pub struct TermsChoice {
    pub scores: Vec<TermsScore>,
    /// Index into `scores` of the kept candidate.
    pub chosen: usize,
    /// K, when the choice was made by K-fold cross-validation.
    pub folds: Option<usize>,
}

impl TermsChoice {
    /// Index of the candidate with the lowest AIC.
    pub fn best_by_aic(&self) -> usize {
        lowest(self.scores.iter().map(|s| s.aic))
    }

    /// One line per candidate, the kept one marked: `terms  distribution  χ²_ν  AIC  CV`.
    pub fn table(&self) -> String {
        let mut lines = vec![format!(
            "  {:<22} {:<9} {:>3} {:>10} {:>12} {:>10}",
            "terms", "slopes", "p", "χ²/dof", "AIC", "CV χ²/obs"
        )];
        for (i, s) in self.scores.iter().enumerate() {
            let cv = s.cv_score.map_or("—".to_owned(), |v| format!("{v:.4}"));
            let mark = if i == self.chosen { "*" } else { " " };
            lines.push(format!(
                "{mark} {:<22} {:<9} {:>3} {:>10.4} {:>12.1} {:>10}",
                s.terms.to_string(),
                s.distribution.to_string(),
                s.free_parameters,
                s.reduced_chi2,
                s.aic,
                cv
            ));
        }
        lines.join("\n")
    }
}

pub(super) fn lowest(values: impl Iterator<Item = f64>) -> usize {
    values
        .enumerate()
        .fold(
            (0, f64::INFINITY),
            |best, (i, v)| {
                if v < best.1 {
                    (i, v)
                } else {
                    best
                }
            },
        )
        .0
}
