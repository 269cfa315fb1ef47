//! The Levenberg–Marquardt stage: damped Gauss–Newton steps on the residual vector in search
//! coordinates, projected onto the search box. Near the minimum it converges quadratically where
//! Nelder–Mead crawls, and its Jacobian is the one the uncertainties need anyway.
//!
//! Steps solve (JᵀJ + λ diag JᵀJ) δ = −Jᵀr (Marquardt's scaling), with λ adapted by the gain
//! ratio (Nielsen's rule). Parameters resting on a bound whose gradient points outward are held
//! for that step (a simple active set), so the others keep converging.

use super::objective::Objective;
use super::stages::{Stage, StageHistory};
use nalgebra::{DMatrix, DVector};
use rayon::prelude::*;

/// Settings of the Levenberg–Marquardt stage.
#[derive(Clone, Debug, PartialEq)]
pub struct LevenbergMarquardtSettings {
    /// Converged when an accepted step lowers the cost by less than this, relatively.
    pub relative_tolerance: f64,
    pub max_iterations: u64,
}

impl Default for LevenbergMarquardtSettings {
    fn default() -> Self {
        LevenbergMarquardtSettings {
            relative_tolerance: 1e-10,
            max_iterations: 200,
        }
    }
}

/// A box-constrained nonlinear least-squares problem in search coordinates: what
/// Levenberg–Marquardt needs. One measurement's [`Objective`] is one; the joint fit of a spectral
/// set ([`super::spectral`]) is another, whose Jacobian uses its block structure.
pub(crate) trait LeastSquares: Sync {
    /// Lower corner of the search box.
    fn lower(&self) -> &[f64];
    /// Upper corner of the search box.
    fn upper(&self) -> &[f64];
    /// Residuals (whose squares sum to the cost) at search coordinates `s`; `None` where the
    /// model is invalid.
    fn residuals(&self, s: &[f64]) -> Option<DVector<f64>>;
    /// ∂r/∂s at `s`, where the residuals are `r`.
    fn jacobian(&self, s: &[f64], r: &DVector<f64>) -> Option<DMatrix<f64>>;
    /// Residual vectors one Jacobian costs (for the evaluation count).
    fn jacobian_evaluations(&self) -> u64 {
        self.lower().len() as u64
    }
}

/// The forward-difference step of coordinate `j` at `s`, pointing into the box at its upper end.
pub(crate) fn forward_step(s: &[f64], j: usize, upper: &[f64]) -> f64 {
    let h = 1e-7 * s[j].abs().max(1.0);
    if s[j] + h > upper[j] {
        -h
    } else {
        h
    }
}

impl LeastSquares for Objective<'_> {
    fn lower(&self) -> &[f64] {
        self.space().lower()
    }
    fn upper(&self) -> &[f64] {
        self.space().upper()
    }
    fn residuals(&self, s: &[f64]) -> Option<DVector<f64>> {
        let mut r = DVector::zeros(self.observations());
        self.residuals_at(&self.space().values(s), r.as_mut_slice())
            .then_some(r)
    }
    /// Forward differences, one column per thread task.
    fn jacobian(&self, s: &[f64], r: &DVector<f64>) -> Option<DMatrix<f64>> {
        let columns: Option<Vec<DVector<f64>>> = (0..s.len())
            .into_par_iter()
            .map(|j| {
                let mut shifted = s.to_vec();
                let h = forward_step(s, j, self.upper());
                shifted[j] += h;
                self.residuals(&shifted).map(|rh| (rh - r) / h)
            })
            .collect();
        Some(DMatrix::from_columns(&columns?))
    }
}

/// Runs Levenberg–Marquardt from the search-box point `start`.
pub(crate) fn levenberg_marquardt(
    problem: &impl LeastSquares,
    start: &[f64],
    settings: &LevenbergMarquardtSettings,
) -> (Vec<f64>, StageHistory) {
    let (lower, upper) = (problem.lower(), problem.upper());
    let mut s: Vec<f64> = start
        .iter()
        .zip(lower.iter().zip(upper))
        .map(|(&x, (&lo, &hi))| x.clamp(lo, hi))
        .collect();
    let mut history = StageHistory {
        stage: Stage::Lm,
        best_cost: Vec::new(),
        iterations: 0,
        evaluations: 0,
        termination: String::new(),
    };
    // One residual vector per trial point, and those of a Jacobian.
    let columns = problem.jacobian_evaluations();
    let finish = |history: &mut StageHistory, reason: &str| {
        history.termination = reason.to_owned();
    };
    let Some(mut r) = problem.residuals(&s) else {
        finish(&mut history, "invalid starting point");
        return (s, history);
    };
    let mut cost = r.norm_squared();
    history.best_cost.push(cost);
    history.evaluations = 1;
    let (mut lambda, mut nu) = (1e-3, 2.0);
    let mut jacobian = None;
    for _ in 0..settings.max_iterations {
        history.iterations += 1;
        if jacobian.is_none() {
            jacobian = problem.jacobian(&s, &r);
            history.evaluations += columns;
        }
        let Some(j) = &jacobian else {
            finish(&mut history, "the Jacobian could not be evaluated");
            return (s, history);
        };
        let a = j.transpose() * j;
        let g = j.transpose() * &r;
        // Active set: a parameter on a bound stays there while the descent direction −g points
        // out of the box.
        let free: Vec<usize> = (0..s.len())
            .filter(|&i| {
                let at_lower = s[i] <= lower[i] && g[i] > 0.0;
                let at_upper = s[i] >= upper[i] && g[i] < 0.0;
                !(at_lower || at_upper)
            })
            .collect();
        if free.is_empty() {
            finish(&mut history, "every parameter rests on a bound");
            return (s, history);
        }
        let scale_floor = 1e-12 * a.diagonal().max();
        let mut system = DMatrix::from_fn(free.len(), free.len(), |p, q| a[(free[p], free[q])]);
        let rhs = DVector::from_fn(free.len(), |p, _| -g[free[p]]);
        for p in 0..free.len() {
            system[(p, p)] += lambda * a[(free[p], free[p])].max(scale_floor);
        }
        let Some(step) = system.cholesky().map(|c| c.solve(&rhs)) else {
            lambda *= nu;
            nu *= 2.0;
            history.best_cost.push(cost);
            continue;
        };
        let mut trial = s.clone();
        for (p, &i) in free.iter().enumerate() {
            trial[i] = (s[i] + step[p]).clamp(lower[i], upper[i]);
        }
        let delta: DVector<f64> = DVector::from_fn(s.len(), |i, _| trial[i] - s[i]);
        // Gain ratio: actual decrease over the decrease the linear model predicts.
        let predicted = -(2.0 * g.dot(&delta) + (j * &delta).norm_squared());
        let trial_residuals = problem.residuals(&trial);
        history.evaluations += 1;
        let trial_cost = trial_residuals
            .as_ref()
            .map_or(f64::INFINITY, |r| r.norm_squared());
        if trial_cost < cost {
            let decrease = cost - trial_cost;
            let gain = if predicted > 0.0 {
                decrease / predicted
            } else {
                0.0
            };
            lambda *= (1.0 - (2.0 * gain - 1.0).powi(3)).max(1.0 / 3.0);
            nu = 2.0;
            s = trial;
            r = trial_residuals.unwrap_or(r);
            cost = trial_cost;
            jacobian = None;
            history.best_cost.push(cost);
            if decrease <= settings.relative_tolerance * cost {
                finish(
                    &mut history,
                    "converged (relative decrease below tolerance)",
                );
                return (s, history);
            }
        } else {
            lambda *= nu;
            nu *= 2.0;
            history.best_cost.push(cost);
            if delta.norm() <= 1e-14 * (1.0 + s.iter().map(|x| x * x).sum::<f64>().sqrt())
                || lambda > 1e16
            {
                finish(&mut history, "converged (no step lowers the cost)");
                return (s, history);
            }
        }
    }
    finish(&mut history, "maximum number of iterations reached");
    (s, history)
}
