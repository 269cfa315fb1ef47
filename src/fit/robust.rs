//! Robust losses on normalized residuals r = (model − data)/σ, to keep a few outliers (a glint, a
//! detector spike) from pulling the fit. Off by default: with honest uncertainties plain least
//! squares is the maximum-likelihood estimate and its χ² is what the statistics assume.

use super::option_error::OptionError;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A loss ρ(r) that equals r² for small |r| and grows slower for outliers.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "loss", rename_all = "lowercase")]
pub enum RobustLoss {
    /// ρ = r² for |r| ≤ c, 2c|r| − c² beyond: outliers count linearly.
    Huber { scale: f64 },
    /// ρ = c² ln(1 + r²/c²): outliers count logarithmically (redescending influence).
    Cauchy { scale: f64 },
}

impl RobustLoss {
    /// Huber with c = 1.345, 95 % efficient for Gaussian noise.
    pub const HUBER: RobustLoss = RobustLoss::Huber { scale: 1.345 };
    /// Cauchy with c = 2.385, 95 % efficient for Gaussian noise.
    pub const CAUCHY: RobustLoss = RobustLoss::Cauchy { scale: 2.385 };

    /// Parses `huber` or `cauchy`, optionally with a scale: `huber:2`.
    pub fn parse(text: &str) -> Result<RobustLoss, OptionError> {
        let (name, scale) = match text.split_once(':') {
            Some((name, scale)) => {
                let scale: f64 = scale
                    .trim()
                    .parse()
                    .map_err(|_| OptionError::RobustScaleNotNumber(scale.to_owned()))?;
                if !(scale.is_finite() && scale > 0.0) {
                    return Err(OptionError::RobustScale(scale));
                }
                (name.trim(), Some(scale))
            }
            None => (text.trim(), None),
        };
        let loss = match name {
            "huber" => RobustLoss::HUBER,
            "cauchy" => RobustLoss::CAUCHY,
            _ => return Err(OptionError::UnknownRobustLoss(name.to_owned())),
        };
        Ok(match (loss, scale) {
            (RobustLoss::Huber { .. }, Some(scale)) => RobustLoss::Huber { scale },
            (RobustLoss::Cauchy { .. }, Some(scale)) => RobustLoss::Cauchy { scale },
            (loss, None) => loss,
        })
    }

    /// ρ(r).
    #[inline]
    pub fn rho(&self, r: f64) -> f64 {
        match *self {
            RobustLoss::Huber { scale } => {
                let a = r.abs();
                if a <= scale {
                    r * r
                } else {
                    scale * (2.0 * a - scale)
                }
            }
            RobustLoss::Cauchy { scale } => scale * scale * (r * r / (scale * scale)).ln_1p(),
        }
    }

    /// sign(r) √ρ(r): a residual whose square is the loss, so that least-squares solvers
    /// (Levenberg–Marquardt) minimize Σρ. Smooth, and ≈ r near 0.
    #[inline]
    pub fn pseudo_residual(&self, r: f64) -> f64 {
        self.rho(r).sqrt().copysign(r)
    }
}

impl fmt::Display for RobustLoss {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            RobustLoss::Huber { scale } => write!(f, "huber:{scale}"),
            RobustLoss::Cauchy { scale } => write!(f, "cauchy:{scale}"),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn losses_are_quadratic_inside_and_softer_outside() {
        for loss in [RobustLoss::HUBER, RobustLoss::CAUCHY] {
            assert!((loss.rho(0.1) / 0.01 - 1.0).abs() < 2e-3, "{loss}");
            assert!(loss.rho(20.0) < 0.3 * 400.0, "{loss}");
            assert_eq!(loss.pseudo_residual(-3.0), -loss.rho(3.0).sqrt());
        }
        // Huber is linear beyond the scale: ρ(10) = 1.345 (20 − 1.345).
        assert!((RobustLoss::HUBER.rho(10.0) - 1.345 * (20.0 - 1.345)).abs() < 1e-12);
        assert!((RobustLoss::CAUCHY.rho(2.385) - 2.385f64.powi(2) * 2f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn parses_names_and_scales() {
        assert_eq!(RobustLoss::parse("huber").unwrap(), RobustLoss::HUBER);
        assert_eq!(
            RobustLoss::parse("cauchy:3").unwrap(),
            RobustLoss::Cauchy { scale: 3.0 }
        );
        assert!(RobustLoss::parse("tukey").is_err());
        assert!(RobustLoss::parse("huber:-1").is_err());
    }
}
