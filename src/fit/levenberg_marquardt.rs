//! The Levenberg–Marquardt stage: damped Gauss–Newton steps on the residual vector in search
//! coordinates, projected onto the search box. Near the minimum it converges quadratically where
//! Nelder–Mead crawls, and its Jacobian is the one the uncertainties need anyway.
//!
//! Steps solve (JᵀJ + λ diag JᵀJ) δ = −Jᵀr (Marquardt's scaling), with λ adapted by the gain
//! ratio (Nielsen's rule). Parameters resting on a bound whose gradient points outward are held
//! for that step (a simple active set), so the others keep converging.

use super::stages::{Stage, StageHistory};
use nalgebra::{DMatrix, DVector};

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
/// Levenberg–Marquardt needs. One measurement's [`super::Objective`] is one (its impl is in
/// `super::normal_equations`); the joint fit of a spectral set ([`super::spectral`]) is another,
/// whose Jacobian uses its block structure.
pub(crate) trait LeastSquares: Sync {
    /// Lower corner of the search box.
    fn lower(&self) -> &[f64];
    /// Upper corner of the search box.
    fn upper(&self) -> &[f64];
    /// Size of the residual vector.
    fn residual_count(&self) -> usize;
    /// Writes the residuals (whose squares sum to the cost) at search coordinates `s` into
    /// `out` (of [`LeastSquares::residual_count`]); false where the model is invalid (`out`
    /// then holds nothing of use).
    fn residuals_into(&self, s: &[f64], out: &mut DVector<f64>) -> bool;
    /// The residuals at `s` in a vector of their own; `None` where the model is invalid.
    fn residuals(&self, s: &[f64]) -> Option<DVector<f64>> {
        let mut r = DVector::zeros(self.residual_count());
        self.residuals_into(s, &mut r).then_some(r)
    }
    /// Residual vectors one Jacobian costs (for the evaluation count).
    fn jacobian_evaluations(&self) -> u64 {
        self.lower().len() as u64
    }
    /// The normal equations (JᵀJ, Jᵀr) of the Jacobian J = ∂r/∂s at `s`, where the residuals
    /// are `r`: all Levenberg–Marquardt (and the covariance) needs of J, so a problem with many
    /// residuals never has to hold J whole.
    fn normal_equations(&self, s: &[f64], r: &DVector<f64>)
        -> Option<(DMatrix<f64>, DVector<f64>)>;
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

/// Marquardt's damping λ and Nielsen's growth factor ν for the next rejection.
struct Damping {
    lambda: f64,
    nu: f64,
}

impl Damping {
    fn new() -> Self {
        Damping {
            lambda: 1e-3,
            nu: 2.0,
        }
    }

    /// After a rejected (or unsolvable) step: damp harder, twice as fast as last time.
    fn increase(&mut self) {
        self.lambda *= self.nu;
        self.nu *= 2.0;
    }

    /// After an accepted step with gain ratio `gain` (Nielsen's rule).
    fn relax(&mut self, gain: f64) {
        self.lambda *= (1.0 - (2.0 * gain - 1.0).powi(3)).max(1.0 / 3.0);
        self.nu = 2.0;
    }
}

/// The iterate of a Levenberg–Marquardt run and its record.
struct Iterate {
    s: Vec<f64>,
    /// The residuals at `s` until a step is rejected, then the rejected trial's: the one
    /// residual vector of the run (at 2e5 rows of 9 elements 14 MB, which a vector per trial
    /// made a new allocation each step and two alive at once). Only the normal equations read
    /// it, and after a rejection they are reused, not evaluated again, so `s`'s own residuals
    /// are never needed once a trial has overwritten them.
    r: DVector<f64>,
    cost: f64,
    /// The normal equations (JᵀJ, Jᵀr) of the Jacobian J = ∂r/∂s at `s`, evaluated again after
    /// each accepted step; a rejected step reuses them with more damping.
    normal_equations: Option<(DMatrix<f64>, DVector<f64>)>,
    damping: Damping,
    history: StageHistory,
}

/// Runs Levenberg–Marquardt from the search-box point `start`.
pub(crate) fn levenberg_marquardt(
    problem: &impl LeastSquares,
    start: &[f64],
    settings: &LevenbergMarquardtSettings,
) -> (Vec<f64>, StageHistory) {
    let s = clamp_to_box(start, problem.lower(), problem.upper());
    let mut history = StageHistory {
        stage: Stage::Lm,
        best_cost: Vec::new(),
        iterations: 0,
        evaluations: 0,
        termination: String::new(),
    };
    let mut r = DVector::zeros(problem.residual_count());
    if !problem.residuals_into(&s, &mut r) {
        history.termination = "invalid starting point".to_owned();
        return (s, history);
    }
    let cost = r.norm_squared();
    history.best_cost.push(cost);
    history.evaluations = 1;
    let mut iterate = Iterate {
        s,
        r,
        cost,
        normal_equations: None,
        damping: Damping::new(),
        history,
    };
    let reason = iterate.run(problem, settings);
    iterate.history.termination = reason.to_owned();
    (iterate.s, iterate.history)
}

fn clamp_to_box(start: &[f64], lower: &[f64], upper: &[f64]) -> Vec<f64> {
    start
        .iter()
        .zip(lower.iter().zip(upper))
        .map(|(&x, (&lo, &hi))| x.clamp(lo, hi))
        .collect()
}

impl Iterate {
    /// Iterates until a stopping rule holds; returns which.
    fn run(
        &mut self,
        problem: &impl LeastSquares,
        settings: &LevenbergMarquardtSettings,
    ) -> &'static str {
        let (lower, upper) = (problem.lower(), problem.upper());
        // One residual vector per trial point, and those of a Jacobian.
        let columns = problem.jacobian_evaluations();
        for _ in 0..settings.max_iterations {
            self.history.iterations += 1;
            if self.normal_equations.is_none() {
                self.normal_equations = problem.normal_equations(&self.s, &self.r);
                self.history.evaluations += columns;
            }
            let Some((a, g)) = &self.normal_equations else {
                return "the Jacobian could not be evaluated";
            };
            let free = free_parameters(&self.s, g, lower, upper);
            if free.is_empty() {
                return "every parameter rests on a bound";
            }
            let Some(step) = damped_step(a, g, &free, self.damping.lambda) else {
                self.damping.increase();
                self.history.best_cost.push(self.cost);
                continue;
            };
            let trial = step_in_box(&self.s, &step, &free, lower, upper);
            let delta: DVector<f64> = DVector::from_fn(self.s.len(), |i, _| trial[i] - self.s[i]);
            // Gain ratio: actual decrease over the decrease the linear model predicts,
            // −(2 gᵀδ + |Jδ|²) with |Jδ|² = δᵀ(JᵀJ)δ.
            let predicted = -(2.0 * g.dot(&delta) + delta.dot(&(a * &delta)));
            let stop = self.accept_or_reject(problem, trial, &delta, predicted, settings);
            if let Some(reason) = stop {
                return reason;
            }
        }
        "maximum number of iterations reached"
    }

    /// Moves to `trial` if it lowers the cost, else damps harder; returns the reason to stop
    /// when the run has converged.
    fn accept_or_reject(
        &mut self,
        problem: &impl LeastSquares,
        trial: Vec<f64>,
        delta: &DVector<f64>,
        predicted: f64,
        settings: &LevenbergMarquardtSettings,
    ) -> Option<&'static str> {
        // The trial's residuals overwrite `s`'s ([`Iterate::r`]).
        let valid = problem.residuals_into(&trial, &mut self.r);
        self.history.evaluations += 1;
        let trial_cost = if valid {
            self.r.norm_squared()
        } else {
            f64::INFINITY
        };
        if trial_cost < self.cost {
            let decrease = self.cost - trial_cost;
            let gain = if predicted > 0.0 {
                decrease / predicted
            } else {
                0.0
            };
            self.damping.relax(gain);
            self.s = trial;
            self.cost = trial_cost;
            self.normal_equations = None;
            self.history.best_cost.push(self.cost);
            (decrease <= settings.relative_tolerance * self.cost)
                .then_some("converged (relative decrease below tolerance)")
        } else {
            self.damping.increase();
            self.history.best_cost.push(self.cost);
            let stalled = delta.norm()
                <= 1e-14 * (1.0 + self.s.iter().map(|x| x * x).sum::<f64>().sqrt())
                || self.damping.lambda > 1e16;
            stalled.then_some("converged (no step lowers the cost)")
        }
    }
}

/// Active set: the parameters free to move this step. One on a bound stays there while the
/// descent direction −g points out of the box.
fn free_parameters(s: &[f64], g: &DVector<f64>, lower: &[f64], upper: &[f64]) -> Vec<usize> {
    (0..s.len())
        .filter(|&i| {
            let at_lower = s[i] <= lower[i] && g[i] > 0.0;
            let at_upper = s[i] >= upper[i] && g[i] < 0.0;
            !(at_lower || at_upper)
        })
        .collect()
}

/// The step δ of the `free` parameters solving (A + λ diag A) δ = −g with A = JᵀJ, the diagonal
/// floored at 1e-12 of its largest entry; `None` when the system is not positive definite.
fn damped_step(
    a: &DMatrix<f64>,
    g: &DVector<f64>,
    free: &[usize],
    lambda: f64,
) -> Option<DVector<f64>> {
    let scale_floor = 1e-12 * a.diagonal().max();
    let mut system = DMatrix::from_fn(free.len(), free.len(), |p, q| a[(free[p], free[q])]);
    let rhs = DVector::from_fn(free.len(), |p, _| -g[free[p]]);
    for p in 0..free.len() {
        system[(p, p)] += lambda * a[(free[p], free[p])].max(scale_floor);
    }
    system.cholesky().map(|c| c.solve(&rhs))
}

/// `s` moved by `step` on the `free` parameters, projected onto the search box.
fn step_in_box(
    s: &[f64],
    step: &DVector<f64>,
    free: &[usize],
    lower: &[f64],
    upper: &[f64],
) -> Vec<f64> {
    let mut trial = s.to_vec();
    for (p, &i) in free.iter().enumerate() {
        trial[i] = (s[i] + step[p]).clamp(lower[i], upper[i]);
    }
    trial
}
