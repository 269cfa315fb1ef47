//! Real-coded genetic algorithm as an argmin [`Solver`]: the global stage of a fit, before the
//! Nelder–Mead polish (docs/design.md §3, `src/fit/`: "genetic optimizer (an argmin Solver)").
//!
//! The algorithm is a generational GA on real vectors inside a box `[lower, upper]`:
//! tournament selection, simulated binary crossover (SBX), polynomial mutation and elitism. It runs
//! on argmin's [`PopulationState`] with [`Individual`]s (parameters + cost), so
//! `state.get_best_param()` is the best [`Individual`] found and `state.get_best_cost()` its cost.
//!
//! Reproducibility: all random numbers come from one `ChaCha8Rng` seeded from a `u64`
//! ([`GeneticAlgorithm::with_seed`]) and re-seeded in `init`, and they are drawn serially. Only the
//! cost evaluations run in parallel (argmin's `Problem::bulk_cost`, which uses rayon and returns the
//! costs in order), so the same seed gives bit-identical results for any rayon thread count.
//!
//! Stopping: argmin's `max_iters` (one iteration = one generation), argmin's `target_cost`, and
//! stagnation — the run ends when the best cost has not improved by more than a relative
//! tolerance for a number of generations ([`GeneticAlgorithm::with_stagnation`]). Always set
//! `max_iters`: on a problem whose cost keeps shrinking geometrically (e.g. a zero-residual
//! synthetic fit) the relative improvement never becomes small.
//!
//! Convergence history: the solver records the best-so-far cost after the initial population and
//! after every generation; read it after the run from the solver returned by the executor,
//! `result.solver().history()`. (An argmin observer would also do, but it is moved into the
//! executor, so the caller would need a shared `Arc<Mutex<Vec<f64>>>` to read it back.) The
//! per-generation key/values (`generation_best_cost`, `stagnant_generations`) reach any observer.
//!
//! Costs: NaN ranks last (stored as `+∞`); an `Err` from the cost function aborts the run with
//! that error. The evaluation count is argmin's `result.problem().counts["cost_count"]`:
//! population size + generations · (population size − elites).
//!
//! ```
//! use argmin::core::{CostFunction, Error, Executor, State};
//! use irpol::fit::genetic::GeneticAlgorithm;
//!
//! struct Sphere;
//! impl CostFunction for Sphere {
//!     type Param = Vec<f64>;
//!     type Output = f64;
//!     fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
//!         Ok(x.iter().map(|v| (v - 0.5) * (v - 0.5)).sum())
//!     }
//! }
//!
//! let solver = GeneticAlgorithm::new(vec![-2.0; 3], vec![2.0; 3])?.with_seed(42);
//! let result = Executor::new(Sphere, solver)
//!     .configure(|state| state.max_iters(300))
//!     .run()?;
//! let best = result.state().get_best_param().unwrap();
//! assert!(best.params.iter().all(|v| (v - 0.5).abs() < 1e-2));
//! let history: &[f64] = result.solver().history(); // best cost after init and each generation
//! assert_eq!(history.len() as u64, result.state().get_iter() + 1);
//! # Ok::<(), Error>(())
//! ```

use argmin::core::{
    ArgminError, CostFunction, Error, PopulationState, Problem, Solver, SyncAlias,
    TerminationReason, TerminationStatus, KV,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

mod operators;

/// One member of the population: a parameter vector inside the box and its cost.
///
/// A NaN cost is stored as `+∞` so that it ranks last instead of poisoning the ordering.
#[derive(Clone, Debug, PartialEq)]
pub struct Individual {
    pub params: Vec<f64>,
    pub cost: f64,
}

/// The argmin state the genetic algorithm runs on.
pub type GeneticState = PopulationState<Individual, f64>;

/// Real-coded genetic algorithm on a box `[lower, upper]` (see the module documentation).
///
/// Defaults (chosen for the 3–6 bounded parameters of a pBRDF fit):
/// population `max(40, 10·dim)`, tournament size 3, 2 elites, SBX with probability 0.9 and
/// distribution index 10, polynomial mutation with probability `1/dim` per parameter and
/// distribution index 20, stagnation after 30 generations without a relative improvement of
/// more than 1e-6, seed 0.
#[derive(Clone, Debug)]
pub struct GeneticAlgorithm {
    lower: Vec<f64>,
    upper: Vec<f64>,
    population_size: usize,
    tournament_size: usize,
    elite_count: usize,
    crossover_probability: f64,
    crossover_index: f64,
    mutation_probability: f64,
    mutation_index: f64,
    stagnation_generations: u64,
    stagnation_tolerance: f64,
    initial_individuals: Vec<Vec<f64>>,
    seed: u64,
    /// Run state, reset by `init`.
    rng: ChaCha8Rng,
    history: Vec<f64>,
    /// Best cost at the last significant improvement, and generations since then.
    reference_cost: f64,
    stagnant_generations: u64,
}

fn invalid(text: String) -> Error {
    ArgminError::InvalidParameter { text }.into()
}

/// Ranks NaN last: a cost function that fails numerically for some parameters should lose the
/// tournament, not abort the ordering.
fn sanitize_cost(cost: f64) -> f64 {
    if cost.is_nan() {
        f64::INFINITY
    } else {
        cost
    }
}

fn sort_by_cost(population: &mut [Individual]) {
    population.sort_by(|a, b| a.cost.total_cmp(&b.cost));
}

impl GeneticAlgorithm {
    /// A GA searching the box `[lower, upper]` with the default settings.
    ///
    /// Errors if the bounds are empty, of different lengths, not finite, or not `lower < upper`
    /// component-wise.
    pub fn new(lower: Vec<f64>, upper: Vec<f64>) -> Result<Self, Error> {
        if lower.is_empty() {
            return Err(invalid("GeneticAlgorithm: the bounds are empty".into()));
        }
        if lower.len() != upper.len() {
            return Err(invalid(format!(
                "GeneticAlgorithm: lower bound has {} components but upper bound has {}",
                lower.len(),
                upper.len()
            )));
        }
        for (i, (&lo, &hi)) in lower.iter().zip(&upper).enumerate() {
            if !lo.is_finite() || !hi.is_finite() {
                return Err(invalid(format!(
                    "GeneticAlgorithm: bounds of parameter {i} must be finite, got [{lo}, {hi}]"
                )));
            }
            if lo >= hi {
                return Err(invalid(format!(
                    "GeneticAlgorithm: parameter {i} needs lower < upper, got [{lo}, {hi}]"
                )));
            }
        }
        let dim = lower.len();
        Ok(GeneticAlgorithm {
            lower,
            upper,
            population_size: (10 * dim).max(40),
            tournament_size: 3,
            elite_count: 2,
            crossover_probability: 0.9,
            crossover_index: 10.0,
            mutation_probability: 1.0 / dim as f64,
            mutation_index: 20.0,
            stagnation_generations: 30,
            stagnation_tolerance: 1e-6,
            initial_individuals: Vec::new(),
            seed: 0,
            rng: ChaCha8Rng::seed_from_u64(0),
            history: Vec::new(),
            reference_cost: f64::INFINITY,
            stagnant_generations: 0,
        })
    }

    /// Seed of the random generator (default 0). The same seed and settings give bit-identical
    /// results for any number of rayon threads.
    #[must_use]
    pub fn with_seed(mut self, seed: u64) -> Self {
        self.seed = seed;
        self
    }

    /// Number of individuals per generation (at least 4).
    pub fn with_population_size(mut self, size: usize) -> Result<Self, Error> {
        if size < 4 {
            return Err(invalid(format!(
                "GeneticAlgorithm: population size must be at least 4, got {size}"
            )));
        }
        self.population_size = size;
        Ok(self)
    }

    /// Number of individuals drawn (with replacement) per tournament; the best one becomes a
    /// parent. Larger means stronger selection pressure; 1 means random mating. Must not exceed
    /// the population size (checked when the run starts).
    pub fn with_tournament_size(mut self, size: usize) -> Result<Self, Error> {
        if size == 0 {
            return Err(invalid(
                "GeneticAlgorithm: tournament size must be at least 1".into(),
            ));
        }
        self.tournament_size = size;
        Ok(self)
    }

    /// Number of best individuals copied unchanged into the next generation (0 disables
    /// elitism). Must be smaller than the population size (checked when the run starts).
    #[must_use]
    pub fn with_elite_count(mut self, count: usize) -> Self {
        self.elite_count = count;
        self
    }

    /// SBX crossover: probability that a pair of parents is crossed (in [0, 1]) and the
    /// distribution index η_c (> 0; larger keeps children closer to their parents).
    pub fn with_crossover(mut self, probability: f64, index: f64) -> Result<Self, Error> {
        check_probability("crossover probability", probability)?;
        check_index("crossover distribution index", index)?;
        self.crossover_probability = probability;
        self.crossover_index = index;
        Ok(self)
    }

    /// Polynomial mutation: probability that each parameter of a child mutates (in [0, 1];
    /// default 1/dim) and the distribution index η_m (> 0; larger makes smaller steps).
    pub fn with_mutation(mut self, probability: f64, index: f64) -> Result<Self, Error> {
        check_probability("mutation probability", probability)?;
        check_index("mutation distribution index", index)?;
        self.mutation_probability = probability;
        self.mutation_index = index;
        Ok(self)
    }

    /// Stop when the best cost has not improved by more than `tolerance · |best|` for
    /// `generations` consecutive generations (`generations` ≥ 1, `tolerance` ≥ 0 and finite).
    pub fn with_stagnation(mut self, generations: u64, tolerance: f64) -> Result<Self, Error> {
        if generations == 0 {
            return Err(invalid(
                "GeneticAlgorithm: stagnation needs at least 1 generation".into(),
            ));
        }
        if !(tolerance.is_finite() && tolerance >= 0.0) {
            return Err(invalid(format!(
                "GeneticAlgorithm: stagnation tolerance must be finite and >= 0, got {tolerance}"
            )));
        }
        self.stagnation_generations = generations;
        self.stagnation_tolerance = tolerance;
        Ok(self)
    }

    /// Individuals placed in the initial population as given (e.g. a starting guess); the rest
    /// is a Latin hypercube sample of the box. Each must have the box's dimension and lie inside
    /// it; at most the population size of them (checked when the run starts).
    pub fn with_initial_individuals(mut self, individuals: Vec<Vec<f64>>) -> Result<Self, Error> {
        for (n, params) in individuals.iter().enumerate() {
            if params.len() != self.lower.len() {
                return Err(invalid(format!(
                    "GeneticAlgorithm: initial individual {n} has {} parameters, the box has {}",
                    params.len(),
                    self.lower.len()
                )));
            }
            let outside = params
                .iter()
                .zip(self.lower.iter().zip(&self.upper))
                .position(|(&x, (&lo, &hi))| !(lo..=hi).contains(&x));
            if let Some(i) = outside {
                return Err(invalid(format!(
                    "GeneticAlgorithm: initial individual {n} has parameter {i} = {} outside [{}, {}]",
                    params[i], self.lower[i], self.upper[i]
                )));
            }
        }
        self.initial_individuals = individuals;
        Ok(self)
    }

    /// The seed the run uses.
    pub fn seed(&self) -> u64 {
        self.seed
    }

    /// Number of individuals per generation.
    pub fn population_size(&self) -> usize {
        self.population_size
    }

    /// Best-so-far cost after the initial population (index 0) and after each generation
    /// (index g); non-increasing. Filled during a run, reset at its start.
    pub fn history(&self) -> &[f64] {
        &self.history
    }

    /// Cross-field settings that can only be checked once all builder calls are done.
    fn check_consistency(&self) -> Result<(), Error> {
        let n = self.population_size;
        if self.elite_count >= n {
            return Err(invalid(format!(
                "GeneticAlgorithm: elite count {} must be smaller than the population size {n}",
                self.elite_count
            )));
        }
        if self.tournament_size > n {
            return Err(invalid(format!(
                "GeneticAlgorithm: tournament size {} exceeds the population size {n}",
                self.tournament_size
            )));
        }
        if self.initial_individuals.len() > n {
            return Err(invalid(format!(
                "GeneticAlgorithm: {} initial individuals exceed the population size {n}",
                self.initial_individuals.len()
            )));
        }
        Ok(())
    }

    /// Appends the best-so-far cost to the history and updates the stagnation counter.
    fn record_generation(&mut self, best_so_far: f64) {
        self.history.push(best_so_far);
        let reference = self.reference_cost;
        let improved = best_so_far < reference
            && (reference.is_infinite()
                || reference - best_so_far > self.stagnation_tolerance * reference.abs());
        if improved {
            self.reference_cost = best_so_far;
            self.stagnant_generations = 0;
        } else {
            self.stagnant_generations += 1;
        }
    }
}

fn check_probability(what: &str, p: f64) -> Result<(), Error> {
    if (0.0..=1.0).contains(&p) {
        Ok(())
    } else {
        Err(invalid(format!(
            "GeneticAlgorithm: {what} must lie in [0, 1], got {p}"
        )))
    }
}

fn check_index(what: &str, eta: f64) -> Result<(), Error> {
    if eta.is_finite() && eta > 0.0 {
        Ok(())
    } else {
        Err(invalid(format!(
            "GeneticAlgorithm: {what} must be finite and > 0, got {eta}"
        )))
    }
}

/// Evaluates all parameter vectors (in parallel through argmin's rayon `bulk_cost`, results in
/// input order) and pairs them with their costs.
fn evaluate<O>(problem: &mut Problem<O>, params: Vec<Vec<f64>>) -> Result<Vec<Individual>, Error>
where
    O: CostFunction<Param = Vec<f64>, Output = f64> + SyncAlias,
{
    let costs = problem.bulk_cost(&params)?;
    Ok(params
        .into_iter()
        .zip(costs)
        .map(|(params, cost)| Individual {
            params,
            cost: sanitize_cost(cost),
        })
        .collect())
}

impl<O> Solver<O, GeneticState> for GeneticAlgorithm
where
    O: CostFunction<Param = Vec<f64>, Output = f64> + SyncAlias,
{
    fn name(&self) -> &str {
        "Genetic algorithm (SBX, polynomial mutation)"
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        mut state: GeneticState,
    ) -> Result<(GeneticState, Option<KV>), Error> {
        self.check_consistency()?;
        if state.take_population().is_some() {
            return Err(invalid(
                "GeneticAlgorithm: give starting points with `with_initial_individuals`, \
                 not as a population on the state"
                    .into(),
            ));
        }
        self.rng = ChaCha8Rng::seed_from_u64(self.seed);
        self.history.clear();
        self.reference_cost = f64::INFINITY;
        self.stagnant_generations = 0;

        let mut params = self.initial_individuals.clone();
        let sampled = self.latin_hypercube(self.population_size - params.len());
        params.extend(sampled);
        let mut population = evaluate(problem, params)?;
        sort_by_cost(&mut population);
        let best = population[0].clone();
        self.record_generation(best.cost);
        Ok((
            state
                .cost(best.cost)
                .individual(best)
                .population(population),
            None,
        ))
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        mut state: GeneticState,
    ) -> Result<(GeneticState, Option<KV>), Error> {
        let mut parents = state.take_population().ok_or_else(|| {
            Error::from(ArgminError::PotentialBug {
                text: "GeneticAlgorithm: no population in the state".into(),
            })
        })?;
        let children = self.breed(&parents);
        parents.truncate(self.elite_count);
        let mut population = parents;
        population.extend(evaluate(problem, children)?);
        sort_by_cost(&mut population);

        let best = population[0].clone();
        // Without elitism the generation's best can be worse than an earlier one; the history
        // and the stagnation test follow the best so far (argmin's `update` runs after this).
        let best_so_far = best.cost.min(state.get_best_cost());
        self.record_generation(best_so_far);
        let kv = argmin::kv!(
            "generation_best_cost" => best.cost;
            "stagnant_generations" => self.stagnant_generations;
        );
        Ok((
            state
                .cost(best.cost)
                .individual(best)
                .population(population),
            Some(kv),
        ))
    }

    fn terminate(&mut self, _state: &GeneticState) -> TerminationStatus {
        if self.stagnant_generations >= self.stagnation_generations {
            TerminationStatus::Terminated(TerminationReason::SolverExit(format!(
                "Stagnation: best cost improved by less than {:e} (relative) in {} generations",
                self.stagnation_tolerance, self.stagnation_generations
            )))
        } else {
            TerminationStatus::NotTerminated
        }
    }
}

#[cfg(test)]
mod tests;
