//! One-sided profile-likelihood bounds for parameters the data do not determine, or bound from
//! one side only.
//!
//! Where the linearized covariance of [`super::uncertainty`] fails, its 1-σ error means nothing: at
//! k = 0 without circular elements the linear Mueller elements are even in k, so ∂F/∂k = 0 and
//! (JᵀJ)⁻¹ gives "k = 0.0 ± 5.3e3" although χ² rises as k² away from 0. The profile likelihood
//! does not linearize: hold the parameter at v, minimize χ² over the other free parameters, and
//! call χ²_p(v) the result. The one-sided 95 % bound on each side of the optimum is where
//! χ²_p(v) − χ²_p(v̂) = z²₀.₉₅ s² (z₀.₉₅ = 1.645, and s² the reduced χ², which also scales the
//! covariance, so that both statements assume the same noise level). A side whose search-interval
//! end stays below that level has no bound: the data allow the whole interval on that side.
//!
//! Profiled are the undetermined parameters and those whose linear one-sided 95 % interval
//! reaches an end of the search interval: k = 0.016 ± 0.057 with k ≥ 0 says only that k is
//! small, and the symmetric ± around a value near a bound hides which values the data allow.

use super::levenberg_marquardt::{levenberg_marquardt, LevenbergMarquardtSettings};
use super::objective::Objective;
use super::parameters::{from_search, Parameter, ParameterValues};
use super::space::ModelSpace;
use super::uncertainty::Uncertainty;
use crate::material::ConfidenceBound;

/// z² of the one-sided 95 % quantile of the standard normal: 1.6448536269514722².
pub const ONE_SIDED_95_DELTA_CHI2: f64 = 2.705_543_454_095_404;
/// The confidence of each side's bound.
pub const CONFIDENCE: f64 = 0.95;
/// The bisection stops when the bracket is this fraction of the bound's distance from the
/// optimum (search coordinates): far below the three significant digits shown, and independent
/// of the search interval's width (ρ_d < 4e-6 in [0, 1]). Each step is a local fit.
const RELATIVE_PRECISION: f64 = 1e-4;
/// Bisection steps at most per side (the bracket then is 2⁻⁶⁰ of the interval).
const MAX_BISECTIONS: usize = 60;

/// χ² profiled over the free parameters other than `parameter`, with the others warm-started from
/// the last point evaluated (the profile is evaluated along a path, so each start is close).
struct Profile<'o, 'a> {
    objective: &'o Objective<'a>,
    parameter: Parameter,
    settings: &'o LevenbergMarquardtSettings,
    /// Values of every parameter at the last evaluation.
    last: ParameterValues,
}

impl Profile<'_, '_> {
    /// χ²_p at the search coordinate `coordinate` of the profiled parameter (∞ for an invalid model).
    fn chi2(&mut self, coordinate: f64) -> f64 {
        let space = self.objective.space();
        let mut values = self.last;
        let interval = space.bounds().get(self.parameter);
        // Clamped: exp/sinh of a bound's coordinate may round just outside the interval.
        values.set(
            self.parameter,
            from_search(self.parameter, coordinate).clamp(interval.lower, interval.upper),
        );
        let others: Vec<Parameter> = space
            .free()
            .iter()
            .copied()
            .filter(|&p| p != self.parameter)
            .collect();
        if !others.is_empty() {
            let Ok(reduced) = ModelSpace::new(
                space.kind(),
                space.shadowing(),
                space.terms(),
                &others,
                values,
                space.bounds(),
            ) else {
                return f64::INFINITY;
            };
            // Plain least squares, whatever loss the fit used: the bound is a χ² statement.
            let objective = Objective::new(self.objective.data(), &reduced, None);
            let start = reduced.search(&values);
            let (best, _) = levenberg_marquardt(&objective, &start, self.settings);
            values = reduced.values(&best);
        }
        let chi2 = self
            .objective
            .normalized_residuals(&values)
            .map_or(f64::INFINITY, |residuals| {
                residuals.iter().map(|r| r * r).sum()
            });
        if chi2.is_finite() {
            self.last = values;
        }
        chi2
    }

    /// The bound between the coordinate `inside` (below `level`) and the search-interval end
    /// `end`, or `None` when χ²_p at `end` is still below `level`.
    fn bound_toward(&mut self, inside: f64, end: f64, level: f64) -> Option<f64> {
        if (end - inside).abs() <= f64::EPSILON * end.abs().max(1.0) {
            return None;
        }
        let start = self.last;
        let open = self.chi2(end) <= level;
        self.last = start;
        if open {
            return None;
        }
        let optimum = inside;
        let (mut inside, mut outside) = (inside, end);
        for _ in 0..MAX_BISECTIONS {
            if (outside - inside).abs() <= RELATIVE_PRECISION * (outside - optimum).abs() {
                break;
            }
            let middle = 0.5 * (inside + outside);
            if self.chi2(middle) <= level {
                inside = middle;
            } else {
                outside = middle;
            }
        }
        self.last = start;
        Some(from_search(self.parameter, 0.5 * (inside + outside)))
    }
}

/// The free parameters whose 1-σ error does not describe what the data allow (see the module
/// documentation), in canonical order.
pub(crate) fn parameters_to_profile(
    space: &ModelSpace,
    values: &ParameterValues,
    uncertainty: &Uncertainty,
) -> Vec<Parameter> {
    let z = ONE_SIDED_95_DELTA_CHI2.sqrt();
    uncertainty
        .parameters
        .iter()
        .zip(&uncertainty.errors)
        .filter(|&(p, &error)| {
            let interval = space.bounds().get(*p);
            let value = values.get(*p);
            uncertainty.undetermined.contains(p)
                || value - z * error <= interval.lower
                || value + z * error >= interval.upper
        })
        .map(|(&p, _)| p)
        .collect()
}

/// One-sided 95 % profile-likelihood bounds of the free parameter `parameter` around the optimum
/// `best` (search coordinates of `objective`), with `reduced_chi2` the noise scale s².
pub(crate) fn profile_bounds(
    objective: &Objective,
    best: &[f64],
    reduced_chi2: f64,
    parameter: Parameter,
    settings: &LevenbergMarquardtSettings,
) -> ConfidenceBound {
    let space = objective.space();
    let i = space
        .free()
        .iter()
        .position(|&p| p == parameter)
        .expect("a profiled parameter is free");
    let mut profile = Profile {
        objective,
        parameter,
        settings,
        last: space.values(best),
    };
    // The reference is the profile at the optimum itself: with a robust loss the plain χ² is
    // not minimal at `best`, and the profile's own minimum keeps Δχ² ≥ 0 near it.
    let minimum = profile.chi2(best[i]);
    let scale = if reduced_chi2.is_finite() && reduced_chi2 > 0.0 {
        reduced_chi2
    } else {
        1.0
    };
    let level = minimum + ONE_SIDED_95_DELTA_CHI2 * scale;
    ConfidenceBound {
        lower: profile.bound_toward(best[i], space.lower()[i], level),
        upper: profile.bound_toward(best[i], space.upper()[i], level),
        confidence: CONFIDENCE,
    }
}
