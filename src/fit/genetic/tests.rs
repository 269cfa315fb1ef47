use super::*;
use argmin::core::{Executor, OptimizationResult, State};
use std::f64::consts::PI;
use std::sync::Mutex;

/// Rastrigin shifted to a minimum (0) at `centre`, so that the box centre is not the answer.
struct Rastrigin {
    centre: Vec<f64>,
}
impl CostFunction for Rastrigin {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
        Ok(x.iter()
            .zip(&self.centre)
            .map(|(xi, ci)| {
                let z = xi - ci;
                z * z - 10.0 * (2.0 * PI * z).cos() + 10.0
            })
            .sum())
    }
}

struct Rosenbrock;
impl CostFunction for Rosenbrock {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
        Ok(x.windows(2)
            .map(|w| 100.0 * (w[1] - w[0] * w[0]).powi(2) + (1.0 - w[0]).powi(2))
            .sum())
    }
}

/// Sphere centred at `centre`; records every point it is asked to evaluate.
struct RecordingSphere {
    centre: Vec<f64>,
    evaluated: Mutex<Vec<Vec<f64>>>,
}
impl RecordingSphere {
    fn new(centre: Vec<f64>) -> Self {
        RecordingSphere {
            centre,
            evaluated: Mutex::new(Vec::new()),
        }
    }
}
impl CostFunction for RecordingSphere {
    type Param = Vec<f64>;
    type Output = f64;
    fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
        self.evaluated.lock().unwrap().push(x.clone());
        Ok(x.iter()
            .zip(&self.centre)
            .map(|(a, c)| (a - c).powi(2))
            .sum())
    }
}

type Outcome<O> = OptimizationResult<O, GeneticAlgorithm, GeneticState>;

fn run<O>(problem: O, solver: GeneticAlgorithm, generations: u64) -> Outcome<O>
where
    O: CostFunction<Param = Vec<f64>, Output = f64> + Sync,
{
    Executor::new(problem, solver)
        .configure(|state| state.max_iters(generations))
        .run()
        .expect("GA run failed")
}

fn best<O>(outcome: &Outcome<O>) -> &Individual {
    outcome
        .state()
        .get_best_param()
        .expect("no best individual")
}

fn evaluations<O>(outcome: &Outcome<O>) -> u64 {
    outcome.problem().counts["cost_count"]
}

fn assert_near(x: &[f64], target: &[f64], tolerance: f64) {
    for (i, (a, b)) in x.iter().zip(target).enumerate() {
        assert!(
            (a - b).abs() < tolerance,
            "parameter {i}: {a} vs {b} (tolerance {tolerance}); x = {x:?}"
        );
    }
}

fn rastrigin_box(dim: usize) -> GeneticAlgorithm {
    GeneticAlgorithm::new(vec![-5.12; dim], vec![5.12; dim]).unwrap()
}

#[test]
fn rastrigin_2d_global_minimum() {
    let centre = vec![1.3, -0.7];
    let out = run(
        Rastrigin {
            centre: centre.clone(),
        },
        rastrigin_box(2).with_seed(1),
        300,
    );
    assert_near(&best(&out).params, &centre, 1e-3);
    assert!(best(&out).cost < 1e-4, "cost {}", best(&out).cost);
}

#[test]
fn rastrigin_4d_global_minimum() {
    let centre = vec![1.3, -0.7, 2.2, -3.1];
    let out = run(
        Rastrigin {
            centre: centre.clone(),
        },
        rastrigin_box(4).with_seed(3),
        400,
    );
    assert_near(&best(&out).params, &centre, 1e-3);
    assert!(best(&out).cost < 1e-4, "cost {}", best(&out).cost);
}

#[test]
fn rosenbrock_3d_global_minimum() {
    // The curved valley needs patience: with the default 30 generations the population
    // collapses in the valley before reaching (1, 1, 1) for ~2 seeds in 20.
    let solver = GeneticAlgorithm::new(vec![-2.0; 3], vec![2.0; 3])
        .unwrap()
        .with_seed(5)
        .with_stagnation(60, 1e-6)
        .unwrap();
    let out = run(Rosenbrock, solver, 2000);
    assert_near(&best(&out).params, &[1.0, 1.0, 1.0], 5e-2);
    assert!(best(&out).cost < 1e-3, "cost {}", best(&out).cost);
}

#[test]
fn sphere_6d_minimum() {
    let centre = vec![0.3, -1.2, 2.5, -0.4, 1.7, -2.9];
    let solver = GeneticAlgorithm::new(vec![-4.0; 6], vec![4.0; 6])
        .unwrap()
        .with_seed(11);
    let out = run(RecordingSphere::new(centre.clone()), solver, 400);
    assert_near(&best(&out).params, &centre, 1e-3);
}

#[test]
fn bounded_optimum_lies_on_the_bound_and_no_point_leaves_the_box() {
    // Unconstrained minimum at (3, -4, 0.5) is outside [-1, 1]³; the constrained one is
    // (1, -1, 0.5).
    let (lower, upper) = (vec![-1.0; 3], vec![1.0; 3]);
    let solver = GeneticAlgorithm::new(lower.clone(), upper.clone())
        .unwrap()
        .with_seed(2);
    let out = run(RecordingSphere::new(vec![3.0, -4.0, 0.5]), solver, 300);
    let x = &best(&out).params;
    assert_near(x, &[1.0, -1.0, 0.5], 1e-3);
    let evaluated = out
        .problem()
        .problem
        .as_ref()
        .unwrap()
        .evaluated
        .lock()
        .unwrap();
    assert_eq!(evaluated.len() as u64, evaluations(&out));
    for point in evaluated.iter() {
        for (i, &v) in point.iter().enumerate() {
            assert!(
                (lower[i]..=upper[i]).contains(&v),
                "evaluated point {point:?} leaves the box in parameter {i}"
            );
        }
    }
    // Something was evaluated on (or within 1e-9 of) the faces, i.e. the search pushed
    // against the bounds rather than stopping short.
    assert!(evaluated.iter().any(|p| p[0] > 1.0 - 1e-9));
}

fn rastrigin_4d_run(seed: u64) -> Outcome<Rastrigin> {
    let centre = vec![1.3, -0.7, 2.2, -3.1];
    run(Rastrigin { centre }, rastrigin_box(4).with_seed(seed), 100)
}

fn bits(x: &[f64]) -> Vec<u64> {
    x.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn same_seed_is_bit_identical_for_any_thread_count() {
    let in_pool = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let out = pool.install(|| rastrigin_4d_run(7));
        let b = best(&out);
        (
            bits(&b.params),
            b.cost.to_bits(),
            bits(out.solver().history()),
        )
    };
    let one_thread = in_pool(1);
    assert_eq!(one_thread, in_pool(2));
    assert_eq!(one_thread, in_pool(2));
    // And the seed matters: another seed takes another path.
    let other = rastrigin_4d_run(8);
    assert_ne!(one_thread.2, bits(other.solver().history()));
}

#[test]
fn different_seeds_all_find_the_global_minimum() {
    let centre = [1.3, -0.7, 2.2, -3.1];
    for seed in 100..105 {
        let out = run(
            Rastrigin {
                centre: centre.to_vec(),
            },
            rastrigin_box(4).with_seed(seed),
            400,
        );
        // Neighbouring local minima are 1 apart with cost ≥ 1.
        assert_near(&best(&out).params, &centre, 5e-3);
        assert!(
            best(&out).cost < 1e-3,
            "seed {seed}: cost {}",
            best(&out).cost
        );
    }
}

#[test]
fn initial_individual_enters_the_population_and_elitism_keeps_it() {
    let centre = vec![1.3, -0.7, 2.2, -3.1];
    let solver = rastrigin_box(4)
        .with_initial_individuals(vec![centre.clone()])
        .unwrap();
    let out = run(
        Rastrigin {
            centre: centre.clone(),
        },
        solver,
        20,
    );
    let history = out.solver().history();
    assert_eq!(history.len(), 21);
    assert!(history.iter().all(|&c| c == 0.0), "history {history:?}");
    assert_eq!(best(&out).params, centre);
    // Still in the final population, ranked first: it survived 20 generations as an elite.
    let population = out.state().get_population().unwrap();
    assert_eq!(population[0].params, centre);
}

#[test]
fn history_is_the_non_increasing_best_so_far() {
    let out = rastrigin_4d_run(9);
    let history = out.solver().history();
    assert_eq!(history.len() as u64, out.state().get_iter() + 1);
    assert!(history.windows(2).all(|w| w[1] <= w[0]));
    assert_eq!(*history.last().unwrap(), out.state().get_best_cost());
    assert!(
        history[0] > 1.0,
        "a random start should not already be optimal"
    );
}

#[test]
fn stagnation_stops_a_run_that_cannot_improve() {
    struct Flat;
    impl CostFunction for Flat {
        type Param = Vec<f64>;
        type Output = f64;
        fn cost(&self, _: &Vec<f64>) -> Result<f64, Error> {
            Ok(1.0)
        }
    }
    let solver = GeneticAlgorithm::new(vec![0.0; 2], vec![1.0; 2])
        .unwrap()
        .with_stagnation(12, 1e-6)
        .unwrap();
    let out = run(Flat, solver, 1000);
    assert_eq!(out.state().get_iter(), 12);
    let reason = out
        .state()
        .get_termination_reason()
        .unwrap()
        .text()
        .to_string();
    assert!(reason.starts_with("Stagnation"), "{reason}");
    // 40 initial + 12 generations of 38 children (2 elites are not re-evaluated).
    assert_eq!(evaluations(&out), 40 + 12 * 38);
}

#[test]
fn nan_costs_rank_last() {
    // NaN on half of the box, a sphere centred at (0.5, 0.5) on the other half.
    struct HalfNan;
    impl CostFunction for HalfNan {
        type Param = Vec<f64>;
        type Output = f64;
        fn cost(&self, x: &Vec<f64>) -> Result<f64, Error> {
            if x[0] < 0.0 {
                Ok(f64::NAN)
            } else {
                Ok((x[0] - 0.5).powi(2) + (x[1] - 0.5).powi(2))
            }
        }
    }
    let solver = GeneticAlgorithm::new(vec![-1.0; 2], vec![1.0; 2]).unwrap();
    let out = run(HalfNan, solver, 200);
    assert_near(&best(&out).params, &[0.5, 0.5], 1e-3);
    let population = out.state().get_population().unwrap();
    let costs: Vec<f64> = population.iter().map(|i| i.cost).collect();
    assert!(costs.iter().all(|c| !c.is_nan()), "{costs:?}");
}

fn error_text<T>(result: Result<T, Error>) -> String {
    match result {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn invalid_bounds_are_refused() {
    let ga = GeneticAlgorithm::new;
    assert!(error_text(ga(vec![], vec![])).contains("empty"));
    assert!(error_text(ga(vec![0.0; 2], vec![1.0; 3])).contains("2 components"));
    assert!(error_text(ga(vec![0.0, 1.0], vec![1.0, 1.0])).contains("parameter 1"));
    assert!(error_text(ga(vec![2.0], vec![1.0])).contains("lower < upper"));
    assert!(error_text(ga(vec![f64::NAN], vec![1.0])).contains("finite"));
    assert!(error_text(ga(vec![0.0], vec![f64::INFINITY])).contains("finite"));
    assert!(ga(vec![0.0], vec![1e-12]).is_ok());
}

#[test]
fn invalid_settings_are_refused() {
    let ga = || GeneticAlgorithm::new(vec![0.0; 2], vec![1.0; 2]).unwrap();
    assert!(ga().with_population_size(3).is_err());
    assert!(ga().with_tournament_size(0).is_err());
    assert!(ga().with_crossover(1.5, 10.0).is_err());
    assert!(ga().with_crossover(0.9, 0.0).is_err());
    assert!(ga().with_mutation(-0.1, 20.0).is_err());
    assert!(ga().with_mutation(0.5, f64::NAN).is_err());
    assert!(ga().with_stagnation(0, 1e-6).is_err());
    assert!(ga().with_stagnation(10, -1.0).is_err());
    let outside = error_text(ga().with_initial_individuals(vec![vec![0.5, 1.5]]));
    assert!(
        outside.contains("parameter 1 = 1.5 outside [0, 1]"),
        "{outside}"
    );
    assert!(ga().with_initial_individuals(vec![vec![0.5]]).is_err());

    // Cross-field settings are checked when the run starts, as an error, not a panic.
    let sphere = || RecordingSphere::new(vec![0.5, 0.5]);
    let too_many_elites = ga().with_population_size(10).unwrap().with_elite_count(10);
    let run = Executor::new(sphere(), too_many_elites).run();
    assert!(error_text(run).contains("elite count 10"));
    let big_tournament = ga()
        .with_population_size(10)
        .unwrap()
        .with_tournament_size(11);
    assert!(Executor::new(sphere(), big_tournament.unwrap())
        .run()
        .is_err());
}
