//! The Nelder–Mead stage: argmin's `NelderMead` on the objective, unconstrained through MINUIT's
//! sine map of the search box, s = lo + (hi − lo)(1 + sin z)/2, so that every simplex vertex is a
//! valid model and the simplex can settle exactly on a bound. A collapsed simplex is restarted
//! around its best vertex until a restart no longer improves the cost.

use super::global::cost_count;
use super::objective::Objective;
use super::stages::{Stage, StageHistory};
use argmin::core::observers::{Observe, ObserverMode};
use argmin::core::{CostFunction, Error, Executor, IterState, State, KV};
use argmin::solver::neldermead::NelderMead;
use std::sync::{Arc, Mutex};

/// Settings of the Nelder–Mead stage.
#[derive(Clone, Debug, PartialEq)]
pub struct NelderMeadSettings {
    /// Edge of the initial simplex in the sine-mapped coordinate z (radians): 0.2 moves a
    /// parameter by ~10 % of its box from the middle of the box.
    pub initial_step: f64,
    /// Stop when the standard deviation of the vertex costs falls below this times the
    /// starting cost.
    pub relative_tolerance: f64,
    /// Simplex steps per run.
    pub max_iterations: u64,
    /// Restarts after the first run (each stops early if it does not improve the cost).
    pub restarts: u32,
}

impl Default for NelderMeadSettings {
    fn default() -> Self {
        NelderMeadSettings {
            initial_step: 0.2,
            relative_tolerance: 1e-10,
            max_iterations: 3000,
            restarts: 2,
        }
    }
}

/// The box coordinates of a sine-mapped point and back.
pub(crate) struct SineMap<'b> {
    lower: &'b [f64],
    upper: &'b [f64],
}

impl<'b> SineMap<'b> {
    pub fn new(lower: &'b [f64], upper: &'b [f64]) -> Self {
        SineMap { lower, upper }
    }
    pub fn bounded(&self, z: &[f64]) -> Vec<f64> {
        z.iter()
            .zip(self.lower.iter().zip(self.upper))
            .map(|(&z, (&lo, &hi))| lo + 0.5 * (hi - lo) * (1.0 + z.sin()))
            .collect()
    }
    pub fn unbounded(&self, s: &[f64]) -> Vec<f64> {
        s.iter()
            .zip(self.lower.iter().zip(self.upper))
            .map(|(&s, (&lo, &hi))| (2.0 * (s - lo) / (hi - lo) - 1.0).clamp(-1.0, 1.0).asin())
            .collect()
    }
}

struct SineMappedCost<'o, 'a, 'b> {
    objective: &'o Objective<'a>,
    map: SineMap<'b>,
}

impl CostFunction for SineMappedCost<'_, '_, '_> {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, z: &Vec<f64>) -> Result<f64, Error> {
        Ok(self.objective.cost(&self.map.bounded(z)))
    }
}

/// Records the best cost after the initialization and after every simplex step.
#[derive(Clone, Default)]
struct BestCostRecorder(Arc<Mutex<Vec<f64>>>);

type NelderMeadState = IterState<Vec<f64>, (), (), (), (), f64>;

impl Observe<NelderMeadState> for BestCostRecorder {
    fn observe_init(&mut self, _: &str, state: &NelderMeadState, _: &KV) -> Result<(), Error> {
        self.push(state.get_best_cost());
        Ok(())
    }
    fn observe_iter(&mut self, state: &NelderMeadState, _: &KV) -> Result<(), Error> {
        self.push(state.get_best_cost());
        Ok(())
    }
}

impl BestCostRecorder {
    fn push(&self, cost: f64) {
        if let Ok(mut costs) = self.0.lock() {
            costs.push(cost);
        }
    }
    fn take(&self) -> Vec<f64> {
        self.0
            .lock()
            .map(|mut c| std::mem::take(&mut *c))
            .unwrap_or_default()
    }
}

/// Runs Nelder–Mead from the search-box point `start`; returns the best point and the stage's
/// history (all restarts concatenated).
pub(crate) fn nelder_mead(
    objective: &Objective,
    start: &[f64],
    settings: &NelderMeadSettings,
) -> Result<(Vec<f64>, StageHistory), Error> {
    let space = objective.space();
    let map = SineMap::new(space.lower(), space.upper());
    let mut best_z = map.unbounded(start);
    let mut best_cost = objective.cost(start);
    let mut history = StageHistory {
        stage: Stage::Nm,
        best_cost: vec![best_cost],
        iterations: 0,
        evaluations: 1,
        termination: String::new(),
    };
    for run in 0..=settings.restarts {
        let simplex = simplex_around(&best_z, settings.initial_step);
        let solver =
            NelderMead::new(simplex).with_sd_tolerance(settings.relative_tolerance * best_cost)?;
        let recorder = BestCostRecorder::default();
        let problem = SineMappedCost {
            objective,
            map: SineMap::new(space.lower(), space.upper()),
        };
        let result = Executor::new(problem, solver)
            .configure(|state| state.max_iters(settings.max_iterations))
            .add_observer(recorder.clone(), ObserverMode::Always)
            .timer(false)
            .run()?;
        let state = result.state();
        history.iterations += state.get_iter();
        history.evaluations += cost_count(&result.problem().counts);
        history.termination = state
            .get_termination_reason()
            .map(|r| r.to_string())
            .unwrap_or_default();
        for cost in recorder.take() {
            history.best_cost.push(cost.min(best_cost));
        }
        let run_cost = state.get_best_cost();
        let improvement = best_cost - run_cost;
        if run_cost < best_cost {
            best_cost = run_cost;
            if let Some(z) = state.get_best_param() {
                best_z = z.clone();
            }
        }
        // A restart that gains less than the tolerance means the simplex had not collapsed
        // prematurely: the minimum is found.
        if run > 0 && improvement <= settings.relative_tolerance * best_cost.abs() {
            break;
        }
    }
    Ok((map.bounded(&best_z), history))
}

/// A right-angled simplex: `centre` and one vertex `step` along each axis (towards the middle
/// of the sine period, so that no edge starts flat against a bound).
fn simplex_around(centre: &[f64], step: f64) -> Vec<Vec<f64>> {
    let mut simplex = vec![centre.to_vec()];
    for i in 0..centre.len() {
        let mut vertex = centre.to_vec();
        vertex[i] += if centre[i] > 0.0 { -step } else { step };
        simplex.push(vertex);
    }
    simplex
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sine_map_round_trips_and_stays_inside_the_box() {
        let (lower, upper) = ([-1.0, 0.0, 2.0], [3.0, 1.0, 2.5]);
        let map = SineMap::new(&lower, &upper);
        let s = [0.5, 0.0, 2.5];
        let back = map.bounded(&map.unbounded(&s));
        for (a, b) in s.iter().zip(&back) {
            assert!((a - b).abs() < 1e-12);
        }
        // Any z maps inside the box, and the bounds are reached exactly at z = ±π/2.
        for z in [-10.0, -std::f64::consts::FRAC_PI_2, 0.3, 7.0] {
            for (i, v) in map.bounded(&[z, z, z]).iter().enumerate() {
                assert!((lower[i]..=upper[i]).contains(v));
            }
        }
        assert_eq!(map.bounded(&[-std::f64::consts::FRAC_PI_2; 3])[1], 0.0);
    }
}
