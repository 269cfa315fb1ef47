//! Runs an [`Optimizer`]'s stages in order, each from the previous stage's best point.

use super::global::{genetic, GeneticSettings};
use super::levenberg_marquardt::{levenberg_marquardt, LevenbergMarquardtSettings};
use super::nelder_mead::{nelder_mead, NelderMeadSettings};
use super::objective::Objective;
use super::stages::{ConvergenceHistory, Optimizer, Stage};
use crate::pbrdf::terms::RESTART_COUNT;
use crate::pbrdf::Parameter;
use rayon::prelude::*;

/// Settings of every stage (the defaults suit fits of 3–5 parameters).
#[derive(Clone, Debug, PartialEq)]
pub struct OptimizerSettings {
    /// The GA when a local stage follows it.
    pub genetic: GeneticSettings,
    /// The GA when it is the only stage.
    pub genetic_alone: GeneticSettings,
    pub nelder_mead: NelderMeadSettings,
    pub levenberg_marquardt: LevenbergMarquardtSettings,
}

impl Default for OptimizerSettings {
    fn default() -> Self {
        OptimizerSettings {
            genetic: GeneticSettings::default(),
            genetic_alone: GeneticSettings::alone(),
            nelder_mead: NelderMeadSettings::default(),
            levenberg_marquardt: LevenbergMarquardtSettings::default(),
        }
    }
}

impl OptimizerSettings {
    /// The GA settings that apply to a run of `stages`.
    pub fn genetic_for(&self, stages: &[Stage]) -> &GeneticSettings {
        if stages == [Stage::Ga] {
            &self.genetic_alone
        } else {
            &self.genetic
        }
    }
}

/// Sets with more points than this search on a subsample first ([`minimize`]): far more than
/// the shipped measurements (≤ 4000 rows), so their fits do not change, and enough that the
/// subsample's minimum lies in the whole set's basin (20 000 geometries × the elements are
/// ≥ 20 000 observations for ≤ 9 parameters).
pub const COARSE_POINTS: usize = 20_000;

/// Every how many points the global search of a set of `points` points uses ([`minimize`]): 1
/// up to [`COARSE_POINTS`].
pub fn coarse_stride(points: usize) -> usize {
    points.div_ceil(COARSE_POINTS).max(1)
}

/// Minimizes `objective` from the search-box point `start` (the first point of the GA's initial
/// population, or where a local first stage starts). Returns the best point found and the
/// history of every stage.
///
/// A set of more than [`COARSE_POINTS`] points runs every stage and the trap restarts on every
/// n-th point (at most [`COARSE_POINTS`]), then the local stages once more on every point from
/// there: the global search only has to find the basin, which a dense scan's subsample shows as
/// well as the whole, and each of its hundreds of evaluations then costs a fixed amount
/// however many rows the file has. The subsample's costs in the history are scaled by the ratio
/// of observations, so that the convergence trace reads on the whole set's scale.
pub(crate) fn minimize(
    objective: &Objective,
    optimizer: &Optimizer,
    start: &[f64],
    seed: u64,
    settings: &OptimizerSettings,
) -> Result<(Vec<f64>, ConvergenceHistory), (Stage, argmin::core::Error)> {
    let mut point = start.to_vec();
    let mut history = ConvergenceHistory::default();
    let local = local_stages(optimizer);
    let points = objective.data().points();
    let mut tried = Vec::new();
    if points > COARSE_POINTS && !local.is_empty() {
        let coarse_data = objective.data().every_nth(coarse_stride(points));
        let coarse = Objective::new(&coarse_data, objective.space(), objective.robust());
        let stages = optimizer.stages();
        run_stages(&coarse, stages, &mut point, seed, settings, &mut history)?;
        tried = escape_traps(
            &coarse,
            &local,
            &mut point,
            seed,
            settings,
            &mut history,
            tried,
        )?;
        let scale = objective.observations() as f64 / coarse.observations() as f64;
        for stage in &mut history.stages {
            stage.best_cost.iter_mut().for_each(|cost| *cost *= scale);
        }
        objective.add_evaluations(coarse.evaluations());
        run_stages(objective, &local, &mut point, seed, settings, &mut history)?;
    } else {
        let stages = optimizer.stages();
        run_stages(objective, stages, &mut point, seed, settings, &mut history)?;
    }
    escape_traps(
        objective,
        &local,
        &mut point,
        seed,
        settings,
        &mut history,
        tried,
    )?;
    Ok((point, history))
}

/// The stages of `optimizer` other than the GA.
fn local_stages(optimizer: &Optimizer) -> Vec<Stage> {
    optimizer
        .stages()
        .iter()
        .copied()
        .filter(|&s| s != Stage::Ga)
        .collect()
}

/// Values of k tried from a result in the k = 0 trap.
const EXTINCTION_RESTARTS: [f64; 2] = [0.1, 1.0];
/// A result with k below this (and k free) may sit in the k = 0 trap.
const EXTINCTION_TRAP: f64 = 0.02;
/// A coordinate within this fraction of its box width from a bound counts as pinned there.
const PINNED: f64 = 1e-2;

/// How a local result may be a trap rather than the global minimum.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Trap {
    /// k ≈ 0 without circular elements: the linear-polarization Mueller elements are even in k
    /// (conjugating N conjugates r_s and r_p, which leaves |r_s|², |r_p|² and Re r_s* r_p
    /// unchanged), so ∂F/∂k = 0 at k = 0 and a local search that reaches the k = 0 bound stays
    /// there: derivative-based steps see no slope and the Gauss–Newton curvature in k vanishes.
    ZeroExtinction,
    /// σ pinned at either bound (a lobe far too narrow or too broad for the data) or q pinned at
    /// its lower bound (an extremely heavy tail): the false minima that local searches from poor
    /// starts reach on narrow specular lobes.
    PinnedShape,
}

fn trap_at(objective: &Objective, point: &[f64]) -> Option<Trap> {
    let space = objective.space();
    let pinned = space.free().iter().enumerate().any(|(i, &p)| {
        let margin = PINNED * (space.upper()[i] - space.lower()[i]);
        let at_lower = point[i] <= space.lower()[i] + margin;
        let at_upper = point[i] >= space.upper()[i] - margin;
        p.info().trap.traps(at_lower, at_upper)
    });
    let zero_extinction = space.free().contains(&Parameter::K)
        && !objective.data().has_circular()
        && space.values(point).get(Parameter::K) <= EXTINCTION_TRAP;
    if pinned {
        Some(Trap::PinnedShape)
    } else if zero_extinction {
        Some(Trap::ZeroExtinction)
    } else {
        None
    }
}

/// When the local stages end in a [`Trap`], runs them again from other starts and keeps the
/// best result: from the same point with k moved to each of [`EXTINCTION_RESTARTS`] for the
/// k = 0 trap, from each of the registry's restarts ([`crate::pbrdf::ParameterInfo::restarts`]) for a pinned shape. Each remedy is tried at most
/// once (escaping one trap can land in the other), `tried` holding those already tried (on a
/// subsample, [`minimize`]); returns them with the new ones. Deterministic.
fn escape_traps(
    objective: &Objective,
    local: &[Stage],
    point: &mut Vec<f64>,
    seed: u64,
    settings: &OptimizerSettings,
    history: &mut ConvergenceHistory,
    mut tried: Vec<Trap>,
) -> Result<Vec<Trap>, (Stage, argmin::core::Error)> {
    if local.is_empty() {
        return Ok(tried);
    }
    while let Some(trap) = trap_at(objective, point).filter(|t| !tried.contains(t)) {
        tried.push(trap);
        escape(objective, local, trap, point, seed, settings, history)?;
    }
    Ok(tried)
}

/// One remedy of [`escape_traps`].
fn escape(
    objective: &Objective,
    local: &[Stage],
    trap: Trap,
    point: &mut Vec<f64>,
    seed: u64,
    settings: &OptimizerSettings,
    history: &mut ConvergenceHistory,
) -> Result<(), (Stage, argmin::core::Error)> {
    let space = objective.space();
    let starts: Vec<Vec<f64>> = match trap {
        Trap::ZeroExtinction => EXTINCTION_RESTARTS
            .iter()
            .map(|&k| {
                let mut values = space.values(point);
                values.set(Parameter::K, k);
                space.search(&values)
            })
            .collect(),
        Trap::PinnedShape => (0..RESTART_COUNT)
            .map(|restart| {
                let mut values = space.values(point);
                for &p in space.free() {
                    values.set(p, p.info().restarts[restart]);
                }
                space.search(&values)
            })
            .collect(),
    };
    // The restarts are independent: run them in parallel, then merge in start order so that
    // the result and the history do not depend on the thread count.
    let runs = starts
        .into_par_iter()
        .map(|mut trial| {
            let mut trial_history = ConvergenceHistory::default();
            run_stages(
                objective,
                local,
                &mut trial,
                seed,
                settings,
                &mut trial_history,
            )?;
            Ok((objective.cost(&trial), trial, trial_history))
        })
        .collect::<Result<Vec<_>, (Stage, argmin::core::Error)>>()?;
    let mut best_cost = objective.cost(point);
    for (cost, trial, trial_history) in runs {
        history.stages.extend(trial_history.stages);
        if cost < best_cost {
            best_cost = cost;
            *point = trial;
        }
    }
    Ok(())
}

/// Runs `stages` from `point`, leaving the best point in it.
fn run_stages(
    objective: &Objective,
    stages: &[Stage],
    point: &mut Vec<f64>,
    seed: u64,
    settings: &OptimizerSettings,
    history: &mut ConvergenceHistory,
) -> Result<(), (Stage, argmin::core::Error)> {
    for &stage in stages {
        let (best, record) = match stage {
            Stage::Ga => genetic(
                objective,
                seed,
                settings.genetic_for(stages),
                vec![point.clone()],
            )
            .map_err(|e| (stage, e))?,
            Stage::Nm => {
                nelder_mead(objective, point, &settings.nelder_mead).map_err(|e| (stage, e))?
            }
            Stage::Lm => levenberg_marquardt(objective, point, &settings.levenberg_marquardt),
        };
        // A stage never hands on a worse point than it was given.
        if objective.cost(&best) <= objective.cost(point) {
            *point = best;
        }
        history.stages.push(record);
    }
    Ok(())
}
