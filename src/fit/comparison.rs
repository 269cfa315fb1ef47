//! Model comparison between the slope distributions by information criteria on the χ² of the
//! weighted fit (Gaussian errors with the stated uncertainties, so −2 ln L = χ² + const):
//! AIC = χ² + 2p, BIC = χ² + p ln N (N observations, p free parameters). The model with the
//! lowest AIC is preferred; on a tie the one with fewer parameters, then the one fitted first.
//! The χ² is the plain one even when the fit used a robust loss.

use crate::pbrdf::DistributionKind;
use serde::{Deserialize, Serialize};
use std::cmp::Ordering;

pub fn aic(chi2: f64, free_parameters: usize) -> f64 {
    chi2 + 2.0 * free_parameters as f64
}

pub fn bic(chi2: f64, free_parameters: usize, observations: usize) -> f64 {
    chi2 + free_parameters as f64 * (observations as f64).ln()
}

/// One fitted distribution as the comparison sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate {
    pub distribution: DistributionKind,
    pub aic: f64,
    pub bic: f64,
    pub free_parameters: usize,
}

impl Candidate {
    /// Whether `self` is preferred over `other` (lower AIC; on a tie no more parameters).
    fn beats(&self, other: &Candidate) -> bool {
        match self.aic.partial_cmp(&other.aic) {
            Some(Ordering::Less) => true,
            Some(Ordering::Equal) => self.free_parameters <= other.free_parameters,
            _ => false,
        }
    }
}

/// Which distribution the data prefer and by how much.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelComparison {
    pub preferred: DistributionKind,
    /// The runner-up (the other one of two).
    pub rejected: DistributionKind,
    /// AIC(rejected) − AIC(preferred) ≥ 0; above ~10 the rejected model has essentially no
    /// support (Burnham & Anderson).
    pub delta_aic: f64,
    /// BIC(rejected) − BIC(preferred) (may be negative when AIC and BIC disagree).
    pub delta_bic: f64,
}

impl ModelComparison {
    /// Compares the fits of several distributions, in the order they were fitted; `None` for
    /// fewer than two.
    pub fn among(candidates: &[Candidate]) -> Option<ModelComparison> {
        fn best<'a>(among: impl Iterator<Item = &'a Candidate>) -> Option<&'a Candidate> {
            among.fold(None, |best, c| match best {
                Some(b) if b.beats(c) => Some(b),
                _ => Some(c),
            })
        }
        let preferred = best(candidates.iter())?;
        let rejected = best(candidates.iter().filter(|c| !std::ptr::eq(*c, preferred)))?;
        Some(ModelComparison {
            preferred: preferred.distribution,
            rejected: rejected.distribution,
            delta_aic: rejected.aic - preferred.aic,
            delta_bic: rejected.bic - preferred.bic,
        })
    }

    /// One line for the material file and the report.
    pub fn summary(&self) -> String {
        format!(
            "{} preferred over {}: ΔAIC = {:.1}, ΔBIC = {:.1}",
            self.preferred, self.rejected, self.delta_aic, self.delta_bic
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lower_aic_wins_and_ties_go_to_the_simpler_model() {
        let candidate = |distribution, aic, bic, free_parameters| Candidate {
            distribution,
            aic,
            bic,
            free_parameters,
        };
        let cauchy = candidate(
            DistributionKind::Cauchy,
            aic(100.0, 5),
            bic(100.0, 5, 1000),
            5,
        );
        let gauss = candidate(
            DistributionKind::Gaussian,
            aic(103.0, 4),
            bic(103.0, 4, 1000),
            4,
        );
        let c = ModelComparison::among(&[cauchy, gauss]).unwrap();
        assert_eq!(c.preferred, DistributionKind::Cauchy);
        assert_eq!(ModelComparison::among(&[gauss, cauchy]).unwrap(), c);
        assert!((c.delta_aic - 1.0).abs() < 1e-12);
        // BIC penalizes the extra parameter by ln 1000 = 6.9 > 3: it prefers the Gaussian.
        assert!(c.delta_bic < 0.0);
        let tie = ModelComparison::among(&[
            candidate(DistributionKind::Cauchy, 10.0, 10.0, 5),
            candidate(DistributionKind::Gaussian, 10.0, 10.0, 4),
        ])
        .unwrap();
        assert_eq!(tie.preferred, DistributionKind::Gaussian);
        assert!(c
            .summary()
            .starts_with("cauchy preferred over gaussian: ΔAIC = 1.0"));
        assert_eq!(ModelComparison::among(&[cauchy]), None);
    }
}
