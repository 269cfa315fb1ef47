//! One model family fitted to one measurement: optimization, goodness of fit and uncertainties.

use super::admissible::unrealizable;
use super::comparison::{aic, bic, Candidate};
use super::data::MeasurementData;
use super::data_view::DataView;
use super::energy::{check_energy, EnergyCheck, ENERGY_TOLERANCE};
use super::objective::Objective;
use super::optimize::minimize;
use super::options::FitOptions;
use super::parameters::ParameterValues;
use super::profile::{parameters_to_profile, profile_bounds};
use super::space::ModelSpace;
use super::stages::ConvergenceHistory;
use super::stages::{Optimizer, Stage};
use super::uncertainty::{estimate, Uncertainty};
use super::FitError;
use crate::material::ModelSpec;
use crate::measure::{MeasurementSet, MUELLER_ELEMENT_NAMES};
use crate::optics::Mueller;
use crate::pbrdf::ModelTerms;
use crate::pbrdf::{DistributionKind, Parameter};
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The best fit of one slope distribution, with everything a report needs.
#[derive(Clone, Debug)]
pub struct ModelFit {
    pub distribution: DistributionKind,
    /// The model's terms (docs/design.md §1.10).
    pub terms: ModelTerms,
    /// The fitted model (fixed parameters included).
    pub model: ModelSpec,
    /// Free parameters in canonical order, and their fitted values.
    pub free: Vec<Parameter>,
    pub values: Vec<f64>,
    /// The minimized cost: χ², or Σρ(r) with a robust loss.
    pub cost: f64,
    /// Σ r² of the normalized residuals (= `cost` without a robust loss).
    pub chi2: f64,
    pub observations: usize,
    pub degrees_of_freedom: usize,
    pub reduced_chi2: f64,
    pub aic: f64,
    pub bic: f64,
    /// Root-mean-square residual (sr⁻¹) per measured element, by name (`m00`, …).
    pub rmse: BTreeMap<String, f64>,
    pub uncertainty: Uncertainty,
    pub history: ConvergenceHistory,
    /// Model evaluations, all stages and the uncertainty estimate included.
    pub evaluations: u64,
    /// The body parameter the energy constraint held, and its value ([`fit_model`]).
    pub held_by_energy: Option<(Parameter, f64)>,
    /// What the energy constraint did, for the record (`None`: nothing to say).
    pub energy: Option<String>,
}

impl ModelFit {
    /// The fitted value of `parameter` (free or fixed); NaN for a slope parameter the
    /// distribution does not have (q of the Gaussian).
    pub fn value(&self, parameter: Parameter) -> f64 {
        self.model.parameter(parameter).unwrap_or(f64::NAN)
    }

    /// The fit as a model comparison sees it.
    pub fn candidate(&self) -> Candidate {
        Candidate {
            distribution: self.distribution,
            aic: self.aic,
            bic: self.bic,
            free_parameters: self.free.len(),
        }
    }

    /// The 1-σ error of a free parameter.
    pub fn error(&self, parameter: Parameter) -> Option<f64> {
        let i = self
            .uncertainty
            .parameters
            .iter()
            .position(|&p| p == parameter)?;
        Some(self.uncertainty.errors[i])
    }

    /// Every parameter's value: the fitted free ones over `options`' base values.
    pub(crate) fn parameter_values(&self, options: &FitOptions) -> ParameterValues {
        let mut values = options.base_values();
        for (&p, &value) in self.free.iter().zip(&self.values) {
            values.set(p, value);
        }
        values
    }

    /// `options` as the fit ran them: with the parameter the energy constraint held fixed.
    pub(crate) fn effective_options(&self, options: &FitOptions) -> FitOptions {
        let mut options = options.clone();
        if let Some((parameter, limit)) = self.held_by_energy {
            options.fixed.insert(parameter, limit);
            if let Some(free) = &mut options.free {
                free.retain(|p| *p != parameter);
            }
        }
        options
    }
}

/// The fitted model at every point of a measurement, recomputed on demand: a fit keeps
/// neither its model matrices nor its residuals (200 B a row of a 9-element file, and up to six
/// fits are kept while sets of terms are scored).
impl ModelFit {
    /// The model's full Mueller matrix (sr⁻¹) at every point of `data`, in its order;
    /// `options` are those the fit was given.
    pub fn model_muellers(
        &self,
        set: &MeasurementSet,
        data: &MeasurementData,
        options: &FitOptions,
    ) -> Result<Vec<Mueller>, FitError> {
        self.evaluated(
            set,
            data,
            options,
            "Mueller matrices",
            |objective, values| objective.model_muellers(values),
        )
    }

    /// The first point of `data` where the model's matrix is not realizable
    /// ([`super::admissible::unrealizable`]), found without holding the matrices; `options`
    /// are those the fit was given.
    pub(crate) fn first_unrealizable_point(
        &self,
        set: &MeasurementSet,
        data: &MeasurementData,
        options: &FitOptions,
    ) -> Result<Option<usize>, FitError> {
        self.evaluated(
            set,
            data,
            options,
            "Mueller matrices",
            |objective, values| objective.first_point_where(values, unrealizable),
        )
    }

    /// Normalized residuals (model − data)/σ at every observation of `data`, point-major,
    /// aligned with the set's elements; `options` are those the fit was given.
    pub fn normalized_residuals(
        &self,
        set: &MeasurementSet,
        data: &MeasurementData,
        options: &FitOptions,
    ) -> Result<Vec<f64>, FitError> {
        self.evaluated(set, data, options, "residuals", |objective, values| {
            objective.normalized_residuals(values)
        })
    }

    /// `evaluate` of the fit's objective on `data` at the fitted values, refused as `what`
    /// when the model cannot be evaluated there.
    fn evaluated<T>(
        &self,
        set: &MeasurementSet,
        data: &MeasurementData,
        options: &FitOptions,
        what: &str,
        evaluate: impl FnOnce(&Objective, &ParameterValues) -> Option<T>,
    ) -> Result<T, FitError> {
        let options = &self.effective_options(options);
        let space = model_space(self.distribution, options)?;
        evaluate(
            &Objective::new(data, &space, None),
            &self.parameter_values(options),
        )
        .ok_or_else(|| unevaluable(set, self.distribution, what))
    }
}

/// The refusal of a fitted `kind` model of `set` that cannot be evaluated (`what`).
fn unevaluable(set: &MeasurementSet, kind: DistributionKind, what: &str) -> FitError {
    FitError::Optimizer {
        file: set.source.clone(),
        stage: "final".into(),
        message: format!("the best {kind} model could not be evaluated ({what})"),
    }
}

/// The starting point of the first stage: the given start or [`Parameter::starting_value`] for
/// the free parameters, the fixed values for the others.
fn starting_values(space: &ModelSpace, options: &FitOptions) -> Result<ParameterValues, FitError> {
    let mut values = options.base_values();
    for &p in space.free() {
        let start = match options.start.get(&p) {
            Some(&value) => {
                let interval = space.bounds().get(p);
                if !interval.contains(value) {
                    return Err(FitError::Options(format!(
                        "the start value {p} = {value} is outside its bounds [{}, {}]",
                        interval.lower, interval.upper
                    )));
                }
                value
            }
            None => p.starting_value(),
        };
        values.set(p, start);
    }
    Ok(values)
}

/// The family `kind` with the free parameters, fixed values and bounds of `options`.
pub(crate) fn model_space(
    kind: DistributionKind,
    options: &FitOptions,
) -> Result<ModelSpace, FitError> {
    ModelSpace::new(
        kind,
        options.shadowing,
        options.terms,
        &options.free_parameters()?,
        options.base_values(),
        &options.bounds,
    )
}

impl ModelFit {
    /// Adds the profile-likelihood bounds of the parameters whose ± would mislead
    /// ([`super::profile`]) to the uncertainty. Each bound costs dozens of local fits, so only
    /// the fit that is kept gets them, after the distributions are compared.
    pub(crate) fn add_profile_bounds(
        &mut self,
        data: &MeasurementData,
        options: &FitOptions,
    ) -> Result<(), FitError> {
        let options = &self.effective_options(options);
        let space = model_space(self.distribution, options)?;
        let objective = Objective::new(data, &space, options.robust);
        let values = self.parameter_values(options);
        let best = space.search(&values);
        let settings = &options.settings.levenberg_marquardt;
        let reduced_chi2 = self.reduced_chi2;
        let uncertainty = &self.uncertainty;
        self.uncertainty.profile_bounds = parameters_to_profile(&space, &values, uncertainty)
            .par_iter()
            .map(|&p| {
                let error = uncertainty.errors[uncertainty
                    .parameters
                    .iter()
                    .position(|&q| q == p)
                    .expect("a profiled parameter has an error")];
                let bound = profile_bounds(&objective, &best, reduced_chi2, (p, error), settings);
                (p, bound)
            })
            .collect();
        Ok(())
    }
}

/// Rounds of [`fit_model`]'s energy constraint (each may move the facets and so the bound).
const ENERGY_ROUNDS: usize = 4;

/// Fits the `kind` family to a prepared measurement, with the energy constraint of
/// [`super::energy`]: where the fit's model reflects more than 1, its body reflectance is held at
/// the largest value that conserves energy and the rest refitted by the local stages.
pub(crate) fn fit_model(
    set: &MeasurementSet,
    data: DataView,
    kind: DistributionKind,
    options: &FitOptions,
) -> Result<ModelFit, FitError> {
    let mut fit = fit_model_unconstrained(set, data, kind, options)?;
    let mut options = options.clone();
    for _ in 0..ENERGY_ROUNDS {
        let space = model_space(kind, &options)?;
        match check_energy(&space, &fit.parameter_values(&options)) {
            EnergyCheck::Conserved => break,
            EnergyCheck::FacetsExceed {
                theta_deg,
                reflectance,
            } => {
                fit.energy = Some(format!(
                    "not conserved: the facets alone reflect {reflectance:.4} at θ = {theta_deg}° \
                     (shadowing {}; smith conserves energy)",
                    options.shadowing.name()
                ));
                break;
            }
            EnergyCheck::HoldBody { parameter, limit } => {
                options.start = fit.free.iter().copied().zip(fit.values.clone()).collect();
                options.start.remove(&parameter);
                options.fixed.insert(parameter, limit);
                if let Some(free) = &mut options.free {
                    free.retain(|p| *p != parameter);
                }
                options.optimizer = local_stages(&options.optimizer);
                fit = fit_model_unconstrained(set, data, kind, &options)?;
                fit.held_by_energy = Some((parameter, limit));
                fit.energy = Some(format!(
                    "{parameter} held at {limit:.6}, where the hemispherical reflectance reaches \
                     1 + {ENERGY_TOLERANCE}"
                ));
            }
        }
    }
    Ok(fit)
}

/// The local stages of `optimizer` (Levenberg–Marquardt when it has none).
fn local_stages(optimizer: &Optimizer) -> Optimizer {
    let local: Vec<&str> = optimizer
        .stages()
        .iter()
        .filter(|s| **s != Stage::Ga)
        .map(|s| s.name())
        .collect();
    let text = if local.is_empty() {
        "lm".to_owned()
    } else {
        local.join("+")
    };
    Optimizer::parse(&text).expect("local stage names parse")
}

/// Fits the `kind` family to a prepared measurement, without the energy constraint.
fn fit_model_unconstrained(
    set: &MeasurementSet,
    data: DataView,
    kind: DistributionKind,
    options: &FitOptions,
) -> Result<ModelFit, FitError> {
    let space = model_space(kind, options)?;
    let observations = data.observations();
    if observations <= space.dimension() {
        return Err(FitError::Measurement {
            file: set.source.clone(),
            message: format!(
                "{observations} observations cannot determine {} free parameters",
                space.dimension()
            ),
        });
    }
    let objective = Objective::over(data, &space, options.robust);
    let start = space.search(&starting_values(&space, options)?);
    let (best, history) = minimize(
        &objective,
        &options.optimizer,
        &start,
        options.seed,
        &options.settings,
    )
    .map_err(|(stage, error)| FitError::Optimizer {
        file: set.source.clone(),
        stage: stage.to_string(),
        message: error.to_string(),
    })?;
    let values = space.values(&best);
    let (chi2, rmse) = residual_sums(set, &objective, &values)
        .ok_or_else(|| unevaluable(set, kind, "residuals"))?;
    let free_count = space.dimension();
    let degrees_of_freedom = observations - free_count;
    let reduced_chi2 = chi2 / degrees_of_freedom as f64;
    let uncertainty = estimate(&objective, &best, reduced_chi2);
    Ok(ModelFit {
        distribution: kind,
        terms: space.terms(),
        model: space.model_spec(&values, set.wavelength_um),
        free: space.free().to_vec(),
        values: space.free_values(&values),
        cost: objective.cost(&best),
        chi2,
        observations,
        degrees_of_freedom,
        reduced_chi2,
        aic: aic(chi2, free_count),
        bic: bic(chi2, free_count, observations),
        rmse,
        uncertainty,
        history,
        evaluations: objective.evaluations(),
        held_by_energy: None,
        energy: None,
    })
}

/// χ² = Σ r² of the normalized residuals at `values`, and the RMS of (model − data) in sr⁻¹
/// per element (from the residuals and the σ's), each summed in observation order as
/// `Iterator::sum` sums (from −0.0), without holding the residuals; `None` for an invalid
/// model.
fn residual_sums(
    set: &MeasurementSet,
    objective: &Objective,
    values: &ParameterValues,
) -> Option<(f64, BTreeMap<String, f64>)> {
    let data = objective.data();
    let width = set.elements.len();
    let mut chi2 = -0.0;
    let mut squares = vec![-0.0; width];
    let mut next = 0;
    let valid = objective.visit_normalized_residuals(values, |block| {
        for (i, r) in (next..).zip(block) {
            chi2 += r * r;
            let (_, sigma) = data.observation(i);
            squares[i % width] += (r * sigma).powi(2);
        }
        next += block.len();
    });
    let rmse = set
        .elements
        .iter()
        .zip(squares)
        .map(|(&index, sum)| {
            (
                MUELLER_ELEMENT_NAMES[index].to_owned(),
                (sum / data.points() as f64).sqrt(),
            )
        })
        .collect();
    valid.then_some((chi2, rmse))
}
