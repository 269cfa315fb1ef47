//! The result of fitting one measurement: the chosen model as a library [`Material`] with its
//! fit record (docs/design.md §2.2), the competing distribution's fit, and the comparison between them.

use super::comparison::ModelComparison;
use super::data::{ErrorSource, MeasurementData, DEFAULT_M00_RELATIVE_ERROR};
use super::model_fit::{fit_model, ModelFit};
use super::optimize::COARSE_POINTS;
use super::options::FitOptions;
use super::stages::Stage;
use super::FitError;
use crate::material::{pinned_at_bound, AlternativeFit, FitRecord, Material, MergedSource};
use crate::measure::{MeasurementSet, MUELLER_ELEMENT_NAMES};
use crate::optics::Mueller;
use crate::pbrdf::{DistributionKind, Parameter};
use std::borrow::Cow;
use std::collections::BTreeMap;

/// Everything a fit report needs about one measurement.
#[derive(Clone, Debug)]
pub struct FitOutcome {
    pub measurement: MeasurementSet,
    /// The chosen model, ready for `Material::save`, with `fit` filled.
    pub material: Material,
    /// The chosen distribution's fit.
    pub chosen: ModelFit,
    /// The other distribution's fit, when both were fitted.
    pub alternative: Option<ModelFit>,
    pub comparison: Option<ModelComparison>,
    /// How the model's terms were chosen, when there was a choice (`--terms a,b`, `--cv K`).
    pub terms_choice: Option<super::terms_choice::TermsChoice>,
    /// The options the chosen fit was given (its terms among them), from which its model is
    /// evaluated again on demand ([`FitOutcome::model_muellers`]).
    pub options: FitOptions,
}

impl FitOutcome {
    /// The chosen model's full Mueller matrix (sr⁻¹) at every measured point, in file order.
    pub fn model_muellers(&self) -> Result<Vec<Mueller>, FitError> {
        let data = MeasurementData::new(&self.measurement)?;
        self.chosen
            .model_muellers(&self.measurement, &data, &self.options)
    }

    /// The chosen model's normalized residuals (model − data)/σ, point-major, aligned with the
    /// set's elements.
    pub fn normalized_residuals(&self) -> Result<Vec<f64>, FitError> {
        let data = MeasurementData::new(&self.measurement)?;
        self.chosen
            .normalized_residuals(&self.measurement, &data, &self.options)
    }
}

/// Fits one measurement: each requested distribution (both in parallel when
/// `options.distribution` is `None`), keeps the one with the lower AIC and records the other as
/// the alternative. Deterministic for a given `options.seed`.
pub fn fit_measurement(set: &MeasurementSet, options: &FitOptions) -> Result<FitOutcome, FitError> {
    fit_measurement_set(Cow::Borrowed(set), options)
}

/// [`fit_measurement`] of a set lent or given (see [`finish`]).
pub(super) fn fit_measurement_set(
    set: Cow<'_, MeasurementSet>,
    options: &FitOptions,
) -> Result<FitOutcome, FitError> {
    let data = MeasurementData::new(&set)?;
    let fitted = fit_distributions(&set, &data, options)?;
    finish(set, data, options, fitted)
}

/// The fits of one measurement before the profile bounds: the kept distribution's, the other's
/// and their comparison.
#[derive(Clone, Debug)]
pub(super) struct Fitted {
    pub chosen: ModelFit,
    pub alternative: Option<ModelFit>,
    pub comparison: Option<ModelComparison>,
}

/// [`fit_measurement`]'s fits of every requested distribution (every slope law the registry
/// knows, [`DistributionKind::ALL`], unless the options name one), in parallel, and which is
/// kept: the lowest AIC, the runner-up recorded as the alternative.
pub(super) fn fit_distributions(
    set: &MeasurementSet,
    data: &MeasurementData,
    options: &FitOptions,
) -> Result<Fitted, FitError> {
    use rayon::prelude::*;
    let fit = |kind| fit_model(set, data.into(), kind, options);
    let kinds = options.distributions();
    // A dense set's laws are fitted one after the other: each evaluation already runs in
    // parallel over blocks of points, and two fits at once would hold two residual vectors
    // (72 MB each a million rows of 9 elements).
    let fits = if data.points() > COARSE_POINTS {
        kinds.into_iter().map(fit).collect::<Vec<_>>()
    } else {
        kinds.into_par_iter().map(fit).collect::<Vec<_>>()
    };
    let mut fits = fits
        .into_iter()
        .collect::<Result<Vec<ModelFit>, FitError>>()?;
    let candidates: Vec<_> = fits.iter().map(ModelFit::candidate).collect();
    let Some(comparison) = ModelComparison::among(&candidates) else {
        let chosen = fits.pop().expect("at least one distribution is fitted");
        return Ok(Fitted {
            chosen,
            alternative: None,
            comparison: None,
        });
    };
    let mut take = |kind: DistributionKind| {
        let at = fits.iter().position(|f| f.distribution == kind);
        fits.swap_remove(at.expect("the compared fits are at hand"))
    };
    let chosen = take(comparison.preferred);
    let alternative = take(comparison.rejected);
    Ok(Fitted {
        chosen,
        alternative: Some(alternative),
        comparison: Some(comparison),
    })
}

/// The outcome of the `fitted` model that is kept: its profile bounds (each costs dozens of
/// local fits, so only the kept fit gets them) and its library entry. The outcome keeps `set`:
/// a given set as it is, a lent one copied after `data` are dropped, so that the rows are
/// never held three times (set, prepared data, copy).
pub(super) fn finish(
    set: Cow<'_, MeasurementSet>,
    data: MeasurementData,
    options: &FitOptions,
    fitted: Fitted,
) -> Result<FitOutcome, FitError> {
    let Fitted {
        mut chosen,
        alternative,
        comparison,
    } = fitted;
    chosen.add_profile_bounds(&data, options)?;
    let given = options.clone();
    let options = &chosen.effective_options(options);
    let material = Material {
        name: set.material.clone(),
        tool_version: format!("irpol {}", env!("CARGO_PKG_VERSION")),
        model: crate::material::MaterialModel::Grey(chosen.model.clone()),
        fit: Some(fit_record(
            &set,
            &data,
            options,
            &chosen,
            alternative.as_ref(),
            comparison.as_ref(),
        )),
    };
    drop(data);
    Ok(FitOutcome {
        measurement: set.into_owned(),
        material,
        chosen,
        alternative,
        comparison,
        terms_choice: None,
        options: given,
    })
}

pub(super) fn names(parameters: &[Parameter]) -> Vec<String> {
    parameters.iter().map(|p| p.name().to_owned()).collect()
}

/// The chosen family's parameters held fixed, with their values (`--free` fixes
/// the others, and the record and the summary line say at what).
fn fixed_values(chosen: &ModelFit) -> BTreeMap<String, f64> {
    Parameter::ALL
        .iter()
        .filter(|p| {
            chosen.distribution.has(**p) && chosen.terms.has(**p) && !chosen.free.contains(p)
        })
        .map(|&p| (p.name().to_owned(), chosen.value(p)))
        .collect()
}

/// The provenance and quality record of docs/design.md §2.2.
fn fit_record(
    set: &MeasurementSet,
    data: &MeasurementData,
    options: &FitOptions,
    chosen: &ModelFit,
    alternative: Option<&ModelFit>,
    comparison: Option<&ModelComparison>,
) -> FitRecord {
    let uncertainty = &chosen.uncertainty;
    let (convergence, global_iterations) = chosen.history.best_cost_trace();
    let mut record = FitRecord {
        source: set.source.clone(),
        source_sha256: set.sha256.clone(),
        source_data: Some(set.source_data(0)),
        // How the files were read: set by the caller that read them.
        layout: None,
        selection: None,
        angles: None,
        merged_sources: merged_sources(set),
        points: set.points.len(),
        elements: set
            .elements
            .iter()
            .map(|&e| MUELLER_ELEMENT_NAMES[e].to_owned())
            .collect(),
        free_parameters: names(&chosen.free),
        fixed_parameters: fixed_values(chosen),
        optimizer: options.optimizer.to_string(),
        seed: options.seed,
        settings: settings_with_energy(data, options, chosen),
        iterations: chosen.history.iterations(),
        evaluations: chosen.evaluations,
        cost: chosen.cost,
        reduced_chi2: chosen.reduced_chi2,
        degrees_of_freedom: chosen.degrees_of_freedom,
        aic: chosen.aic,
        bic: chosen.bic,
        termination: chosen.history.termination(),
        rmse: chosen.rmse.clone(),
        uncertainty: uncertainty
            .parameters
            .iter()
            .zip(&uncertainty.errors)
            .map(|(p, &e)| (p.name().to_owned(), e))
            .collect(),
        correlation: uncertainty.correlation.clone(),
        undetermined: names(&uncertainty.undetermined),
        at_bound: names(&uncertainty.at_bound),
        pinned: pinned_at_bound(
            &names(&uncertainty.at_bound),
            &names(&chosen.free),
            &chosen.values,
        ),
        profile_bounds: uncertainty
            .profile_bounds
            .iter()
            .map(|(p, bound)| (p.name().to_owned(), *bound))
            .collect(),
        uncertainty_per_wavelength: BTreeMap::new(),
        wavelengths: Vec::new(),
        dispersion: None,
        model_choice: comparison.map(ModelComparison::summary),
        alternative: alternative.map(|other| AlternativeFit {
            model: other.model.clone(),
            cost: other.cost,
            reduced_chi2: other.reduced_chi2,
            aic: other.aic,
            bic: other.bic,
        }),
        convergence,
        global_iterations,
    };
    record.mark_non_finite_as_undetermined();
    record
}

/// The files merged into `set` as repeat measurements, for the record's provenance.
fn merged_sources(set: &MeasurementSet) -> Vec<MergedSource> {
    set.merged
        .iter()
        .map(|file| MergedSource {
            source: file.path.clone(),
            source_sha256: file.sha256.clone(),
            source_data: Some(file.data.clone()),
            points: file.rows,
        })
        .collect()
}

/// The settings that, with the optimizer name and seed, reproduce the fit.
/// [`settings`], and what the energy constraint did to `chosen` when it did anything.
fn settings_with_energy(
    data: &MeasurementData,
    options: &FitOptions,
    chosen: &ModelFit,
) -> BTreeMap<String, String> {
    let mut settings = settings(data, options);
    if let Some(energy) = &chosen.energy {
        settings.insert("energy".into(), energy.clone());
    }
    settings
}

pub(super) fn settings(data: &MeasurementData, options: &FitOptions) -> BTreeMap<String, String> {
    let mut settings = BTreeMap::new();
    settings.insert("uncertainties".into(), uncertainty_setting(data));
    settings.insert(
        "robust_loss".into(),
        options
            .robust
            .map_or_else(|| "none".to_owned(), |loss| loss.to_string()),
    );
    settings.insert(
        "distribution".into(),
        match options.distribution {
            Some(kind) => format!("{kind} (given)"),
            None => {
                let laws: Vec<&str> = DistributionKind::ALL.iter().map(|k| k.name()).collect();
                format!("{} fitted, lower AIC kept", laws.join(" and "))
            }
        },
    );
    settings.insert("bounds".into(), bounds_setting(options));
    // Only a model with the volume terms says which it has, so that others read as before.
    if options.terms != crate::pbrdf::ModelTerms::default() {
        settings.insert("terms".into(), options.terms.to_string());
    }
    if let Some(k) = options.cv_folds {
        settings.insert(
            "terms_choice".into(),
            format!(
                "{k}-fold cross-validation (rows dealt by a shuffle seeded with the fit's seed)"
            ),
        );
    } else if options.choose_terms {
        settings.insert(
            "terms_choice".into(),
            "auto: the admissible terms that predict best (5-fold cross-validation, AIC on small \
             sets; docs/design.md §1.10)"
                .into(),
        );
    }
    if !options.fixed.is_empty() {
        settings.insert(
            "fixed".into(),
            options
                .fixed
                .iter()
                .map(|(p, v)| format!("{p} = {v}"))
                .collect::<Vec<_>>()
                .join(", "),
        );
    }
    settings.extend(stage_settings(options));
    settings
}

/// Where the standard deviations came from: the file's `u_` columns, the default noise model,
/// or both.
fn uncertainty_setting(data: &MeasurementData) -> String {
    let from_file = data
        .error_sources()
        .iter()
        .filter(|s| **s == ErrorSource::File)
        .count();
    let default_model = format!(
        "default: {} % of m00 on m00, {} % of m00 on the others",
        100.0 * DEFAULT_M00_RELATIVE_ERROR,
        100.0 * super::data::DEFAULT_OTHER_ERROR_PER_M00
    );
    match from_file {
        0 => default_model,
        n if n == data.element_count() => "u_ columns of the file".to_owned(),
        _ => format!("u_ columns where present, else {default_model}"),
    }
}

/// Every parameter's effective search interval.
fn bounds_setting(options: &FitOptions) -> String {
    let bounds = options.bounds.effective(options.shadowing);
    Parameter::ALL
        .iter()
        .filter(|p| options.terms.has(**p))
        .map(|&p| {
            let i = bounds.get(p);
            format!("{p} [{}, {}]", i.lower, i.upper)
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The stopping rules of each stage the optimizer runs, keyed by stage.
fn stage_settings(options: &FitOptions) -> Vec<(String, String)> {
    let stages = options.optimizer.stages();
    let s = &options.settings;
    let mut settings = Vec::new();
    if stages.contains(&Stage::Ga) {
        let ga = s.genetic_for(stages);
        settings.push((
            "ga".into(),
            format!(
                "population {}, at most {} generations, stop after {} without {:e} relative gain",
                ga.population,
                ga.max_generations,
                ga.stagnation_generations,
                ga.stagnation_tolerance
            ),
        ));
    }
    if stages.contains(&Stage::Nm) {
        settings.push((
            "nm".into(),
            format!(
                "initial step {} rad (sine-mapped box), cost spread < {:e} × cost, at most {} steps, {} restarts",
                s.nelder_mead.initial_step,
                s.nelder_mead.relative_tolerance,
                s.nelder_mead.max_iterations,
                s.nelder_mead.restarts
            ),
        ));
    }
    if stages.contains(&Stage::Lm) {
        settings.push((
            "lm".into(),
            format!(
                "relative decrease < {:e}, at most {} iterations",
                s.levenberg_marquardt.relative_tolerance, s.levenberg_marquardt.max_iterations
            ),
        ));
    }
    settings
}
