//! Choosing a model's terms (docs/design.md §1.10) by what it predicts: each candidate set of
//! terms is fitted to the whole measurement (both distributions unless one is asked for), then
//! scored by AIC and, with K folds, by K-fold cross-validation — the rows split at random (seeded)
//! into K folds, the model refitted on K − 1 of them and its normalized residuals taken on the
//! fold it did not see. The refit of a fold starts from the whole-data fit and runs the local
//! stage only (Levenberg–Marquardt, under the same energy constraint): the folds are the same surface minus a fifth of its rows,
//! so the global search would find the same basin at ten times the cost.
//!
//! Score = Σ r² over held-out observations / their number (≈ 1 for a model that predicts within
//! the stated uncertainties). The chosen terms are those with the lowest cross-validated score
//! when folds were asked for, else the lowest AIC; both are reported side by side.

use super::data::MeasurementData;
use super::model_fit::{fit_model, model_space, ModelFit};
use super::objective::Objective;
use super::options::FitOptions;
use super::outcome::{fit_measurement, FitOutcome};
use super::stages::Optimizer;
use super::terms_choice::lowest;
pub use super::terms_choice::{TermsChoice, TermsScore};
use super::FitError;
use crate::measure::MeasurementSet;
use crate::pbrdf::ModelTerms;
use rand::seq::SliceRandom;
use rand::SeedableRng;

/// Fits one grey measurement as `options` ask: its `terms` alone, or choosing among
/// `term_candidates` (by cross-validation with `cv_folds`, else by AIC).
pub fn fit_grey(set: &MeasurementSet, options: &FitOptions) -> Result<FitOutcome, FitError> {
    if options.term_candidates.is_empty() && options.cv_folds.is_none() {
        return fit_measurement(set, options);
    }
    let candidates = if options.term_candidates.is_empty() {
        vec![options.terms]
    } else {
        options.term_candidates.clone()
    };
    let (mut outcome, choice) = fit_choosing_terms(set, options, &candidates, options.cv_folds)?;
    outcome.terms_choice = Some(choice);
    Ok(outcome)
}

/// Fits `set` with each of `candidates` (in order) and keeps the one that predicts best
/// (module docs). `folds` of `Some(K)` needs 2 ≤ K ≤ rows.
pub fn fit_choosing_terms(
    set: &MeasurementSet,
    options: &FitOptions,
    candidates: &[ModelTerms],
    folds: Option<usize>,
) -> Result<(FitOutcome, TermsChoice), FitError> {
    if let Some(k) = folds {
        if k < 2 || k > set.points.len() {
            return Err(FitError::Options(format!(
                "--cv {k}: the folds must number from 2 to the rows of the measurement ({})",
                set.points.len()
            )));
        }
    }
    let mut outcomes = Vec::new();
    let mut scores = Vec::new();
    for &terms in candidates {
        let options = FitOptions {
            terms,
            ..options.clone()
        };
        let outcome = fit_measurement(set, &options)?;
        let cv_score = match folds {
            Some(k) => Some(cross_validate(set, &options, &outcome.chosen, k)?),
            None => None,
        };
        scores.push(TermsScore {
            terms,
            distribution: outcome.chosen.distribution,
            free_parameters: outcome.chosen.free.len(),
            reduced_chi2: outcome.chosen.reduced_chi2,
            aic: outcome.chosen.aic,
            cv_score,
        });
        outcomes.push(outcome);
    }
    let chosen = match folds {
        Some(_) => lowest(scores.iter().map(|s| s.cv_score.unwrap_or(f64::INFINITY))),
        None => lowest(scores.iter().map(|s| s.aic)),
    };
    let outcome = outcomes.swap_remove(chosen);
    Ok((
        outcome,
        TermsChoice {
            scores,
            chosen,
            folds,
        },
    ))
}

/// The rows of each of `k` folds: a seeded shuffle dealt round-robin.
pub fn fold_rows(rows: usize, k: usize, seed: u64) -> Vec<Vec<usize>> {
    let mut order: Vec<usize> = (0..rows).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
    let mut folds = vec![Vec::new(); k];
    for (i, row) in order.into_iter().enumerate() {
        folds[i % k].push(row);
    }
    for fold in &mut folds {
        fold.sort_unstable();
    }
    folds
}

/// The rows `rows` of `set`, as a set of their own.
pub fn subset(set: &MeasurementSet, rows: &[usize]) -> MeasurementSet {
    MeasurementSet {
        points: rows.iter().map(|&r| set.points[r].clone()).collect(),
        ..set.clone()
    }
}

/// K-fold cross-validated score of the family of `fit` (module docs). Each fold's refit is
/// constrained like the whole-data fit (energy, [`super::energy`]).
fn cross_validate(
    set: &MeasurementSet,
    options: &FitOptions,
    fit: &ModelFit,
    k: usize,
) -> Result<f64, FitError> {
    let options = FitOptions {
        distribution: Some(fit.distribution),
        optimizer: Optimizer::parse("lm").expect("lm is a stage"),
        start: fit.free.iter().copied().zip(fit.values.clone()).collect(),
        ..options.clone()
    };
    let (mut total, mut count) = (0.0, 0usize);
    for held_out in fold_rows(set.points.len(), k, options.seed) {
        let training: Vec<usize> = (0..set.points.len())
            .filter(|r| held_out.binary_search(r).is_err())
            .collect();
        let train = subset(set, &training);
        let refit = fit_model(
            &train,
            &MeasurementData::new(&train)?,
            fit.distribution,
            &options,
        )?;
        let effective = refit.effective_options(&options);
        let space = model_space(fit.distribution, &effective)?;
        let test = subset(set, &held_out);
        let test_data = MeasurementData::new(&test)?;
        let residuals = Objective::new(&test_data, &space, None)
            .normalized_residuals(&refit.parameter_values(&effective))
            .unwrap_or_default();
        total += residuals.iter().map(|r| r * r).sum::<f64>();
        count += residuals.len();
    }
    Ok(total / count.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folds_partition_the_rows_and_depend_on_the_seed() {
        let folds = fold_rows(103, 5, 7);
        let mut all: Vec<usize> = folds.iter().flatten().copied().collect();
        all.sort_unstable();
        assert_eq!(all, (0..103).collect::<Vec<_>>());
        assert!(folds.iter().all(|f| f.len() == 20 || f.len() == 21));
        assert_eq!(folds, fold_rows(103, 5, 7));
        assert_ne!(folds, fold_rows(103, 5, 8));
    }
}
