//! Model comparison between the slope distributions by information criteria on the χ² of the
//! weighted fit (Gaussian errors with the stated uncertainties, so −2 ln L = χ² + const):
//! AIC = χ² + 2p, BIC = χ² + p ln N (N observations, p free parameters). The model with the
//! lower AIC is preferred; on a tie the one with fewer parameters. The χ² is the plain one even
//! when the fit used a robust loss.

use super::parameters::DistributionKind;
use serde::{Deserialize, Serialize};

pub fn aic(chi2: f64, free_parameters: usize) -> f64 {
    chi2 + 2.0 * free_parameters as f64
}

pub fn bic(chi2: f64, free_parameters: usize, observations: usize) -> f64 {
    chi2 + free_parameters as f64 * (observations as f64).ln()
}

/// Which distribution the data prefer and by how much.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ModelComparison {
    pub preferred: DistributionKind,
    pub rejected: DistributionKind,
    /// AIC(rejected) − AIC(preferred) ≥ 0; above ~10 the rejected model has essentially no
    /// support (Burnham & Anderson).
    pub delta_aic: f64,
    /// BIC(rejected) − BIC(preferred) (may be negative when AIC and BIC disagree).
    pub delta_bic: f64,
}

impl ModelComparison {
    /// Compares two fits given as (distribution, AIC, BIC, free parameters).
    pub fn new(
        a: (DistributionKind, f64, f64, usize),
        b: (DistributionKind, f64, f64, usize),
    ) -> ModelComparison {
        let a_first = a.1 < b.1 || (a.1 == b.1 && a.3 <= b.3);
        let (preferred, rejected) = if a_first { (a, b) } else { (b, a) };
        ModelComparison {
            preferred: preferred.0,
            rejected: rejected.0,
            delta_aic: rejected.1 - preferred.1,
            delta_bic: rejected.2 - preferred.2,
        }
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
        let cauchy = (
            DistributionKind::Cauchy,
            aic(100.0, 5),
            bic(100.0, 5, 1000),
            5,
        );
        let gauss = (
            DistributionKind::Gaussian,
            aic(103.0, 4),
            bic(103.0, 4, 1000),
            4,
        );
        let c = ModelComparison::new(cauchy, gauss);
        assert_eq!(c.preferred, DistributionKind::Cauchy);
        assert!((c.delta_aic - 1.0).abs() < 1e-12);
        // BIC penalizes the extra parameter by ln 1000 = 6.9 > 3: it prefers the Gaussian.
        assert!(c.delta_bic < 0.0);
        let tie = ModelComparison::new(
            (DistributionKind::Cauchy, 10.0, 10.0, 5),
            (DistributionKind::Gaussian, 10.0, 10.0, 4),
        );
        assert_eq!(tie.preferred, DistributionKind::Gaussian);
        assert!(c
            .summary()
            .starts_with("cauchy preferred over gaussian: ΔAIC = 1.0"));
    }
}
