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
use super::parameters::{from_search, value_per_coordinate, ParameterValues};
use super::space::ModelSpace;
use super::uncertainty::Uncertainty;
use crate::material::ConfidenceBound;
use crate::pbrdf::Parameter;

/// z² of the one-sided 95 % quantile of the standard normal: 1.6448536269514722².
pub const ONE_SIDED_95_DELTA_CHI2: f64 = 2.705_543_454_095_404;
/// The confidence of each side's bound.
pub const CONFIDENCE: f64 = 0.95;
/// The search for a bound stops when its bracket is this fraction of the bound's distance from
/// the optimum (search coordinates): far below the three significant digits shown, and
/// independent of the search interval's width (ρ_d < 4e-6 in [0, 1]). Each step is a local fit.
const RELATIVE_PRECISION: f64 = 1e-4;
/// Steps at most per side (bisection alone would then have narrowed the bracket to 2⁻⁶⁰ of the
/// interval).
const MAX_STEPS: usize = 60;

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
            // Levenberg–Marquardt's last cost is Σ r² at its result: no evaluation more.
            let objective = Objective::over(self.objective.data(), &reduced, None);
            let start = reduced.search(&values);
            let (best, history) = levenberg_marquardt(&objective, &start, self.settings);
            values = reduced.values(&best);
            return self.remember(values, history.best_cost.last().copied());
        }
        let chi2 = self.objective.chi2(&values).map(|(chi2, _)| chi2);
        self.remember(values, chi2)
    }

    /// Keeps `values` as the next warm start when their χ² is finite; returns the χ² (∞ for an
    /// invalid model).
    fn remember(&mut self, values: ParameterValues, chi2: Option<f64>) -> f64 {
        let chi2 = chi2.unwrap_or(f64::INFINITY);
        if chi2.is_finite() {
            self.last = values;
        }
        chi2
    }

    /// The bound between the coordinate `optimum` (where χ²_p is `minimum`) and the
    /// search-interval end `end`, where χ²_p reaches `level`; `None` when χ²_p stays below
    /// `level` up to `end`. `step` (> 0) is the first distance tried.
    ///
    /// The search works on g = √(χ²_p − minimum) − √(level − minimum), which is nearly linear in
    /// the coordinate (χ²_p rises about quadratically, or linearly from a bound where the
    /// coordinate is √-mapped): it steps outward from the optimum, extrapolating g, until g > 0,
    /// then closes the bracket by Illinois false position. A handful of local fits, all near the
    /// bound where each warm start is close; bisection from the whole interval spent one per
    /// halving, and its first point, the interval's end, often took more than all the others.
    fn bound_toward(
        &mut self,
        optimum: f64,
        end: f64,
        step: f64,
        (minimum, level): (f64, f64),
    ) -> Option<f64> {
        if (end - optimum).abs() <= f64::EPSILON * end.abs().max(1.0) {
            return None;
        }
        let start = self.last;
        let rise = (level - minimum).sqrt();
        let g = |chi2: f64| (chi2 - minimum).max(0.0).sqrt() - rise;
        let bracket = self.bracket((optimum, -rise), end, step, &g);
        let bound = bracket.map(|(inside, outside)| self.close(optimum, inside, outside, &g));
        self.last = start;
        bound
    }

    /// Points (coordinate, g) inside (g ≤ 0) and outside (g > 0) of the bound, stepping from
    /// `optimum` (where g is `at_optimum`) toward `end`; `None` when g ≤ 0 at `end`.
    fn bracket(
        &mut self,
        (optimum, at_optimum): (f64, f64),
        end: f64,
        step: f64,
        g: &impl Fn(f64) -> f64,
    ) -> Option<((f64, f64), (f64, f64))> {
        let span = end - optimum;
        let mut inside = (optimum, at_optimum);
        // Without a usable step, a hundredth of the way to the end.
        let mut distance = if step.is_finite() && step > 0.0 {
            (step / span.abs()).clamp(1e-9, 1.0)
        } else {
            0.01
        };
        loop {
            let trial = optimum + distance * span;
            let value = g(self.chi2(trial));
            if value > 0.0 {
                return Some((inside, (trial, value)));
            }
            if distance >= 1.0 {
                return None;
            }
            // Where the line through the last two inside points reaches g = 0, at least twice and
            // at most 16 times as far out.
            let slope = (value - inside.1) / (trial - inside.0);
            let reach = if slope > 0.0 {
                (trial - value / slope - optimum) / span
            } else {
                f64::INFINITY
            };
            inside = (trial, value);
            distance = reach.clamp(2.0 * distance, 16.0 * distance).min(1.0);
        }
    }

    /// The bound within the bracket (`inside`, `outside`) by Illinois false position, to
    /// [`RELATIVE_PRECISION`] of its distance from `optimum`.
    fn close(
        &mut self,
        optimum: f64,
        mut inside: (f64, f64),
        mut outside: (f64, f64),
        g: &impl Fn(f64) -> f64,
    ) -> f64 {
        let mut last_side = None;
        for _ in 0..MAX_STEPS {
            if (outside.0 - inside.0).abs() <= RELATIVE_PRECISION * (outside.0 - optimum).abs() {
                break;
            }
            let middle = false_position(inside, outside);
            let value = g(self.chi2(middle));
            // The end kept twice in a row has its value halved (Illinois), so that the bracket
            // closes from both sides.
            if value <= 0.0 {
                inside = (middle, value);
                if last_side == Some(true) {
                    outside.1 *= 0.5;
                }
                last_side = Some(true);
            } else {
                outside = (middle, value);
                if last_side == Some(false) {
                    inside.1 *= 0.5;
                }
                last_side = Some(false);
            }
        }
        from_search(self.parameter, 0.5 * (inside.0 + outside.0))
    }
}

/// Where the line through (a, g_a) and (b, g_b), g_a ≤ 0 < g_b, crosses zero; the midpoint where
/// that is not strictly between a and b (an infinite or rounded value).
fn false_position((a, ga): (f64, f64), (b, gb): (f64, f64)) -> f64 {
    let x = a + (b - a) * (-ga / (gb - ga));
    let (low, high) = (a.min(b), a.max(b));
    if x.is_finite() && x > low && x < high {
        x
    } else {
        0.5 * (a + b)
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
/// `best` (search coordinates of `objective`), with `reduced_chi2` the noise scale s² and
/// `error` its linearized 1-σ error (∞ or NaN when there is none).
pub(crate) fn profile_bounds(
    objective: &Objective,
    best: &[f64],
    reduced_chi2: f64,
    (parameter, error): (Parameter, f64),
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
    // The first step: the linearized one-sided 95 % distance, in search coordinates.
    let step = ONE_SIDED_95_DELTA_CHI2.sqrt() * error / value_per_coordinate(parameter, best[i]);
    let levels = (minimum, level);
    ConfidenceBound {
        lower: profile.bound_toward(best[i], space.lower()[i], step, levels),
        upper: profile.bound_toward(best[i], space.upper()[i], step, levels),
        confidence: CONFIDENCE,
    }
}
