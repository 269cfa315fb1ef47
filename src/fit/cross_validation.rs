//! Choosing a model's terms (docs/design.md §1.10) by what it predicts: each candidate set of
//! terms is fitted to the whole measurement (both distributions unless one is asked for), then
//! scored by AIC and, with K folds, by K-fold cross-validation — the rows split at random (seeded)
//! into K folds, the model refitted on K − 1 of them and its normalized residuals taken on the
//! fold it did not see. The refit of a fold starts from the whole-data fit and runs the local
//! stage only (Levenberg–Marquardt, under the same energy constraint): the folds are the same surface minus a fifth of its rows,
//! so the global search would find the same basin at ten times the cost.
//!
//! Score = Σ r² over held-out observations / their number (≈ 1 for a model that predicts within
//! the stated uncertainties), with its standard error from the folds' scatter. Only physically
//! admissible models compete ([`super::admissible`]); among them the kept terms are the fewest
//! parameters whose score is within one standard error of the best (the one-standard-error rule:
//! data made by §1.3's model come back as §1.3's model), or the lowest AIC without folds. Both
//! are reported side by side.
//!
//! A set of more than [`CHOICE_POINTS`] points is compared on every n-th of its points (at most
//! that many) and the kept terms are then fitted to every point, exactly as a fit of those terms
//! alone: ranking a few candidates needs the surface's shape, which 50 000 points of a dense scan
//! show as well as a million, while the losing candidates' fits and every fold's refit were most
//! of a dense fit's time. What the fit writes (parameters, χ², uncertainties) is the fit of
//! every point; the printed table says the scores are the subsample's.

use super::admissible::why_inadmissible_where;
use super::data::MeasurementData;
use super::data_view::{DataView, PointSubset};
use super::levenberg_marquardt::LevenbergMarquardtSettings;
use super::model_fit::{fit_model, model_space, ModelFit};
use super::objective::Objective;
use super::options::FitOptions;
use super::outcome::{finish, fit_distributions, fit_measurement_set, FitOutcome, Fitted};
use super::stages::Optimizer;
pub use super::terms_choice::{TermsChoice, TermsScore};
use super::FitError;
use crate::measure::MeasurementSet;
use crate::pbrdf::ModelTerms;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use std::borrow::Cow;

/// The local stage of a fold's refit: it starts at the whole-data optimum, a few Gauss–Newton
/// steps from the fold's own, and a score good to 1e-6 relatively is all the choice needs (the
/// whole-data fit's 1e-10 and 200 iterations cost 4 s a candidate on PTFE's rows).
const FOLD_REFIT: LevenbergMarquardtSettings = LevenbergMarquardtSettings {
    relative_tolerance: 1e-6,
    max_iterations: 30,
};

/// Most folds `--cv` takes: each fold is a refit, and past ten or twenty folds the score
/// changes less than its own scatter while the cost keeps growing.
pub const MAX_FOLDS: usize = 20;

/// Folds the default choice of terms takes ([`FitOptions::choose_terms`]).
pub const DEFAULT_FOLDS: usize = 5;

/// Fewest rows per fold for the default choice to cross-validate; a smaller set is compared by
/// AIC (docs/design.md §1.10).
pub const MIN_ROWS_PER_FOLD: usize = 10;

/// Most points the choice of terms compares its candidates on (module docs).
pub const CHOICE_POINTS: usize = 50_000;

/// Every how many points the choice of terms of a set of `points` points uses: 1 up to
/// [`CHOICE_POINTS`].
fn choice_stride(points: usize) -> usize {
    points.div_ceil(CHOICE_POINTS).max(1)
}

/// The points the candidates are compared on: all of a set's prepared data, or every n-th
/// point of a dense one ([`choice_stride`]) with the whole data's standard deviations.
struct ChoicePoints<'a> {
    whole: &'a MeasurementData,
    sample: Option<MeasurementData>,
    stride: usize,
}

impl<'a> ChoicePoints<'a> {
    fn of(whole: &'a MeasurementData) -> ChoicePoints<'a> {
        let stride = choice_stride(whole.points());
        let sample = (stride > 1).then(|| DataView::from(whole).every_nth(stride));
        ChoicePoints {
            whole,
            sample,
            stride,
        }
    }

    fn data(&self) -> &MeasurementData {
        self.sample.as_ref().unwrap_or(self.whole)
    }

    /// The position in the whole data of point `point` of [`ChoicePoints::data`].
    fn whole_point(&self, point: usize) -> usize {
        point * self.stride
    }

    /// The options a candidate is compared with: `options`, with the stopping rule of a fold's
    /// refit (a score good to 1e-6) when the comparison takes a subsample, whose fits are
    /// thrown away (the kept terms are fitted anew to every point with `options` themselves).
    fn comparison_options(&self, options: &FitOptions) -> FitOptions {
        let mut options = options.clone();
        if self.sample.is_some() {
            options.settings.levenberg_marquardt.relative_tolerance = FOLD_REFIT.relative_tolerance;
        }
        options
    }

    /// (points compared, points of the set), when the comparison took a subsample.
    fn sampled(&self) -> Option<(usize, usize)> {
        let sample = self.sample.as_ref()?;
        Some((sample.points(), self.whole.points()))
    }

    /// The kept candidate's fits of every point: those of the comparison when it compared every
    /// point, else the kept terms fitted anew to the whole data ([`fit_distributions`], the
    /// fit of those terms alone).
    fn whole_data_fits(
        &self,
        set: &MeasurementSet,
        options: &FitOptions,
        compared: Fitted,
    ) -> Result<Fitted, FitError> {
        match self.sample {
            None => Ok(compared),
            Some(_) => fit_distributions(set, self.whole, options),
        }
    }
}

/// Fits one grey measurement as `options` ask: its `terms` alone, or choosing among
/// `term_candidates` (by cross-validation with `cv_folds`, else by AIC).
pub fn fit_grey(set: &MeasurementSet, options: &FitOptions) -> Result<FitOutcome, FitError> {
    fit_grey_set(Cow::Borrowed(set), options)
}

/// [`fit_grey`] of a set lent or given: a given set becomes the outcome's
/// [`FitOutcome::measurement`] as it is, a lent one is copied into it once the fit's prepared
/// data are gone (a dense scan's rows are the largest thing a fit holds).
pub(crate) fn fit_grey_set(
    set: Cow<'_, MeasurementSet>,
    options: &FitOptions,
) -> Result<FitOutcome, FitError> {
    if options.term_candidates.is_empty() && options.cv_folds.is_none() {
        return fit_measurement_set(set, options);
    }
    let folds = folds_for(&set, options)?;
    let (mut outcome, choice) = choosing_terms(set, options, &candidates(options), folds)?;
    outcome.terms_choice = Some(choice);
    Ok(outcome)
}

/// The candidate sets of terms `options` ask to choose among (its `terms` alone when none).
pub(super) fn candidates(options: &FitOptions) -> Vec<ModelTerms> {
    if options.term_candidates.is_empty() {
        vec![options.terms]
    } else {
        options.term_candidates.clone()
    }
}

/// The folds of `set`'s choice: `--cv K` as given (2 ≤ K ≤ min(rows, [`MAX_FOLDS`])), or for
/// the default choice [`DEFAULT_FOLDS`] where each fold has [`MIN_ROWS_PER_FOLD`] rows (else
/// AIC).
pub(super) fn folds_for(
    set: &MeasurementSet,
    options: &FitOptions,
) -> Result<Option<usize>, FitError> {
    let rows = set.points.len();
    match options.cv_folds {
        Some(k) if k < 2 || k > rows.min(MAX_FOLDS) => Err(FitError::Options(format!(
            "--cv {k}: the folds must number from 2 to {} (each fold refits the model; 5 or \
             10 are usual; the measurement has {rows} rows)",
            rows.min(MAX_FOLDS)
        ))),
        Some(k) => Ok(Some(k)),
        None if options.choose_terms && rows >= DEFAULT_FOLDS * MIN_ROWS_PER_FOLD => {
            Ok(Some(DEFAULT_FOLDS))
        }
        None => Ok(None),
    }
}

/// Fits `set` with each of `candidates` (in order) and keeps the admissible one that predicts
/// best ([`TermsChoice::choose`]). `folds` of `Some(K)` needs 2 ≤ K ≤ rows.
pub fn fit_choosing_terms(
    set: &MeasurementSet,
    options: &FitOptions,
    candidates: &[ModelTerms],
    folds: Option<usize>,
) -> Result<(FitOutcome, TermsChoice), FitError> {
    choosing_terms(Cow::Borrowed(set), options, candidates, folds)
}

/// [`fit_choosing_terms`] of a set lent or given ([`fit_grey_set`]).
fn choosing_terms(
    set: Cow<'_, MeasurementSet>,
    options: &FitOptions,
    candidates: &[ModelTerms],
    folds: Option<usize>,
) -> Result<(FitOutcome, TermsChoice), FitError> {
    let data = MeasurementData::new(&set)?;
    let points = ChoicePoints::of(&data);
    let mut fitted = Vec::new();
    let mut scores = Vec::new();
    for &terms in candidates {
        let options = points.comparison_options(&options.with_terms(terms));
        let (fit, mut score) = score_terms(&set, &points, &options, folds)?;
        score.inadmissible =
            why_fits_inadmissible([(&fit.chosen, &*set, &points)], &options, false)?;
        fitted.push(fit);
        scores.push(score);
    }
    let chosen = TermsChoice::choose(&scores, folds.is_some());
    let options = options.with_terms(candidates[chosen]);
    let kept = points.whole_data_fits(&set, &options, fitted.swap_remove(chosen))?;
    let sampled = points.sampled();
    if sampled.is_some() {
        // The verdict on the model written is that of every point.
        scores[chosen].inadmissible =
            why_fits_inadmissible([(&kept.chosen, &*set, &points)], &options, true)?;
    }
    drop(points);
    let mut outcome = finish(set, data, &options, kept)?;
    let choice = TermsChoice {
        scores,
        chosen,
        folds,
        sampled,
    };
    choice.note_sample(&mut outcome.material);
    Ok((outcome, choice))
}

/// One candidate's fits (`options.terms`) and scores: χ², AIC and the folds' held-out residuals
/// when `folds` are asked for. Whether it is admissible is the caller's to judge
/// ([`why_fits_inadmissible`]), on one wavelength or all of a material's.
fn score_terms(
    set: &MeasurementSet,
    points: &ChoicePoints,
    options: &FitOptions,
    folds: Option<usize>,
) -> Result<(Fitted, TermsScore), FitError> {
    let data = points.data();
    let fitted = fit_distributions(set, data, options)?;
    let fit = &fitted.chosen;
    let folds = match folds {
        Some(k) => cross_validate(set, data, options, fit, k)?,
        None => Vec::new(),
    };
    let score = TermsScore {
        terms: options.terms,
        distribution: fit.distribution,
        free_parameters: fit.free.len(),
        reduced_chi2: fit.reduced_chi2,
        aic: fit.aic,
        folds,
        inadmissible: None,
    };
    Ok((fitted, score))
}

/// Why the fits of one material (one per wavelength, each with its set and the points it was
/// compared on) are not admissible ([`why_inadmissible_where`]), judged on the points compared
/// or, with `every_point`, on all of them; a row named is a row of the whole set.
fn why_fits_inadmissible<'a>(
    judged: impl IntoIterator<Item = (&'a ModelFit, &'a MeasurementSet, &'a ChoicePoints<'a>)>,
    options: &FitOptions,
    every_point: bool,
) -> Result<Option<String>, FitError> {
    let (mut models, mut first_unrealizable) = (Vec::new(), Vec::new());
    for (fit, set, points) in judged {
        let data = if every_point {
            points.whole
        } else {
            points.data()
        };
        let first = fit.first_unrealizable_point(set, data, options)?;
        models.push(&fit.model);
        first_unrealizable.push(first.map(|point| match every_point {
            true => point,
            false => points.whole_point(point),
        }));
    }
    Ok(why_inadmissible_where(&models, |j| first_unrealizable[j]))
}

/// Chooses the terms of a material measured at several wavelengths as one (docs/design.md
/// §1.10): each candidate fitted at every wavelength, its scores added up over the wavelengths
/// (the folds' held-out residuals fold by fold) and its admissibility judged on all of them
/// together. Returns the record of the choice and the kept candidate's fits, per distribution
/// (in `options.distributions()` order) per wavelength, for the joint fit to start from.
pub(super) fn choose_spectral_terms(
    sets: &[MeasurementSet],
    options: &FitOptions,
) -> Result<(TermsChoice, Vec<Vec<ModelFit>>), FitError> {
    let folds = sets
        .iter()
        .map(|set| folds_for(set, options))
        .collect::<Result<Vec<_>, _>>()?;
    // One rule for the whole set: folds only where every wavelength can be folded.
    let folds = folds.iter().copied().min().flatten();
    let data = sets
        .iter()
        .map(MeasurementData::new)
        .collect::<Result<Vec<_>, _>>()?;
    let points: Vec<ChoicePoints> = data.iter().map(ChoicePoints::of).collect();
    let mut scores = Vec::new();
    let mut fits = Vec::new();
    for terms in candidates(options) {
        let options = options.with_terms(terms);
        let parts = sets
            .iter()
            .zip(&points)
            .map(|(set, points)| {
                score_terms(set, points, &points.comparison_options(&options), folds)
            })
            .collect::<Result<Vec<_>, _>>()?;
        let judged = parts.iter().zip(sets.iter().zip(&points));
        let inadmissible = why_fits_inadmissible(
            judged.map(|(p, (set, points))| (&p.0.chosen, set, points)),
            &options,
            false,
        )?;
        let (fitted, part_scores): (Vec<Fitted>, Vec<TermsScore>) = parts.into_iter().unzip();
        scores.push(TermsScore::combined(&part_scores, inadmissible));
        fits.push(fitted);
    }
    let chosen = TermsChoice::choose(&scores, folds.is_some());
    let kept_options = options.with_terms(scores[chosen].terms);
    let kept = fits
        .swap_remove(chosen)
        .into_iter()
        .zip(sets.iter().zip(&points))
        .map(|(fitted, (set, points))| points.whole_data_fits(set, &kept_options, fitted))
        .collect::<Result<Vec<_>, _>>()?;
    let by_distribution = fits_by_distribution(options, &kept);
    let sampled = sampled_rows(&points);
    if sampled.is_some() {
        // The verdict on the models written is that of every point of every wavelength.
        let judged = kept.iter().zip(sets.iter().zip(&points));
        scores[chosen].inadmissible = why_fits_inadmissible(
            judged.map(|(f, (set, points))| (&f.chosen, set, points)),
            &kept_options,
            true,
        )?;
    }
    let choice = TermsChoice {
        scores,
        chosen,
        folds,
        sampled,
    };
    Ok((choice, by_distribution))
}

/// The fits of each wavelength, per distribution (in `options.distributions()` order).
fn fits_by_distribution(options: &FitOptions, fits: &[Fitted]) -> Vec<Vec<ModelFit>> {
    options
        .distributions()
        .into_iter()
        .map(|kind| {
            fits.iter()
                .map(|f| match &f.alternative {
                    Some(other) if other.distribution == kind => other.clone(),
                    _ => f.chosen.clone(),
                })
                .collect()
        })
        .collect()
}

/// (rows compared, rows measured) over the wavelengths, when any took a subsample.
fn sampled_rows(points: &[ChoicePoints]) -> Option<(usize, usize)> {
    points
        .iter()
        .map(|p| {
            p.sampled()
                .unwrap_or((p.data().points(), p.data().points()))
        })
        .reduce(|a, b| (a.0 + b.0, a.1 + b.1))
        .filter(|(compared, all)| compared < all)
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
        points: set.points.select(rows),
        ..set.clone()
    }
}

/// Σ r² and the count of the held-out observations of each of K folds, for the family of `fit`
/// (module docs). Each fold's refit is constrained like the whole-data fit (energy,
/// [`super::energy`]).
fn cross_validate(
    set: &MeasurementSet,
    data: &MeasurementData,
    options: &FitOptions,
    fit: &ModelFit,
    k: usize,
) -> Result<Vec<(f64, usize)>, FitError> {
    let mut options = FitOptions {
        distribution: Some(fit.distribution),
        optimizer: Optimizer::parse("lm").expect("lm is a stage"),
        start: fit.free.iter().copied().zip(fit.values.clone()).collect(),
        ..options.clone()
    };
    options.settings.levenberg_marquardt = FOLD_REFIT;
    let mut folds = Vec::with_capacity(k);
    for held_out in fold_rows(data.points(), k, options.seed) {
        let training: Vec<usize> = (0..data.points())
            .filter(|r| held_out.binary_search(r).is_err())
            .collect();
        // The fold's rows read in place from the prepared data; errors name the file.
        let training = PointSubset::new(data, &training);
        let refit = fit_model(set, training.view(data), fit.distribution, &options)?;
        let effective = refit.effective_options(&options);
        let space = model_space(fit.distribution, &effective)?;
        let held_out = PointSubset::new(data, &held_out);
        // An invalid model adds nothing: the sum of no residuals.
        let held_out_chi2 = Objective::over(held_out.view(data), &space, None)
            .chi2(&refit.parameter_values(&effective))
            .unwrap_or((-0.0, 0));
        folds.push(held_out_chi2);
    }
    Ok(folds)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `--cv K` is bounded before any work (each fold is a refit): 2 ≤ K ≤ min(rows, 20); the
    /// default choice folds only a set with 10 rows a fold, else compares by AIC.
    #[test]
    fn folds_are_bounded_up_front() {
        let point = crate::measure::MeasurementPoint {
            theta_i_deg: 30.0,
            phi_i_deg: 0.0,
            theta_r_deg: 30.0,
            phi_r_deg: 180.0,
            values: vec![0.1],
            uncertainties: vec![None],
            line: 2,
        };
        let rows = |n: usize| MeasurementSet {
            source: "rows.csv".into(),
            sha256: String::new(),
            material: "rows".into(),
            wavelength_um: 10.0,
            metadata: Default::default(),
            elements: vec![0],
            points: std::iter::repeat_n(point.clone(), n).collect(),
            merged: Vec::new(),
            notes: Vec::new(),
        };
        let set = rows(1824);
        let with = |cv: Option<usize>, choose_terms: bool| FitOptions {
            cv_folds: cv,
            choose_terms,
            ..FitOptions::default()
        };
        let refused = folds_for(&set, &with(Some(1824), false))
            .unwrap_err()
            .to_string();
        assert!(
            refused.contains("--cv 1824: the folds must number from 2 to 20"),
            "{refused}"
        );
        assert!(folds_for(&set, &with(Some(1), false)).is_err());
        assert_eq!(folds_for(&set, &with(Some(20), false)).unwrap(), Some(20));
        assert_eq!(
            folds_for(&set, &with(None, true)).unwrap(),
            Some(DEFAULT_FOLDS)
        );
        assert_eq!(folds_for(&set, &with(None, false)).unwrap(), None);
        assert_eq!(folds_for(&rows(49), &with(None, true)).unwrap(), None);
    }

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
