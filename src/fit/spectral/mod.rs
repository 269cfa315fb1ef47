//! Joint fit of a spectral measurement set (docs/design.md §1.9): every wavelength of one material at
//! once, with σ and q shared (the surface's geometry does not depend on λ) and per wavelength
//! either n, k, ρ_d free (`--dispersion table`, the default) or ρ_d free and n, k from a Lorentz
//! law with shared parameters (`--dispersion lorentz:N`).
//!
//! How: each wavelength is first fitted alone (the grey pipeline: GA then local stages, in
//! parallel), which finds each lobe and index without any joint search over 2 + 3K dimensions;
//! the joint problem ([`joint`]) then starts from the per-wavelength values with σ, q at their
//! medians and is polished by Levenberg–Marquardt, whose Jacobian costs five residual
//! evaluations whatever K is. A Lorentz fit starts from a law fitted to the table's ε(λ)
//! ([`lorentz_start`](mod@lorentz_start)). Uncertainties and correlations come from the joint Jacobian at the
//! optimum, as for one wavelength ([`super::uncertainty`]).

mod joint;
mod lorentz_start;
mod record;

use super::admissible::STRONG_ABSORPTION_K;
use super::comparison::{aic, bic};
use super::data::MeasurementData;
use super::energy::{check_energy, EnergyCheck, ENERGY_TOLERANCE};
use super::levenberg_marquardt::{levenberg_marquardt, LeastSquares};
use super::model_fit::{fit_model, model_space, ModelFit};
use super::objective::Objective;
use super::options::FitOptions;
use super::parameters::{
    from_search, to_search, value_per_coordinate, DistributionKind, Parameter,
};
use super::space::ModelSpace;
use super::space::VOLUME_MIN_N;
use super::stages::StageHistory;
use super::uncertainty::linearized_errors;
use super::FitError;
use crate::material::{Material, SpectralModel};
use crate::measure::MeasurementSet;
use crate::optics::{LorentzDispersion, Mueller};
use joint::{Block, IndexModel, JointProblem};
use lorentz_start::{law_bounds, lorentz_start};
use num_complex::Complex64;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// How n and k depend on wavelength in a spectral fit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Dispersion {
    /// n and k free at each wavelength.
    #[default]
    Table,
    /// A Lorentz law of this many oscillators (docs/design.md §1.9).
    Lorentz(usize),
    /// A dielectric's normal dispersion n = A + B/λ², B ≥ 0, with k free at each wavelength
    /// (docs/design.md §1.10).
    Cauchy,
    /// The default of `irpol fit`: [`Dispersion::Cauchy`] for a model whose body term lets light
    /// into the material (the subsurface term: a transparent dielectric, whose index falls with
    /// λ between absorption bands) when no wavelength absorbs strongly, else
    /// [`Dispersion::Table`].
    Auto,
}

/// Whether [`Dispersion::Auto`] takes Cauchy's law for the `table` fit of `options`' terms.
fn normal_dispersion_applies(options: &FitOptions, table: &SpectralFit) -> bool {
    options.terms.body == crate::pbrdf::Body::Subsurface
        && table.model.k.iter().all(|&k| k < STRONG_ABSORPTION_K)
}

impl Dispersion {
    /// `table` or `lorentz:N` (N ≥ 1).
    pub fn parse(text: &str) -> Result<Dispersion, super::OptionError> {
        let text = text.trim();
        if text == "table" {
            return Ok(Dispersion::Table);
        }
        if text == "cauchy" {
            return Ok(Dispersion::Cauchy);
        }
        if text == "auto" {
            return Ok(Dispersion::Auto);
        }
        match text.strip_prefix("lorentz:").map(str::parse::<usize>) {
            Some(Ok(n)) if (1..=6).contains(&n) => Ok(Dispersion::Lorentz(n)),
            _ => Err(super::OptionError::UnknownDispersion(text.to_owned())),
        }
    }
}

impl std::fmt::Display for Dispersion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Dispersion::Table => f.write_str("table"),
            Dispersion::Lorentz(n) => write!(f, "lorentz:{n}"),
            Dispersion::Cauchy => f.write_str("cauchy"),
            Dispersion::Auto => f.write_str("auto"),
        }
    }
}

/// One joint fit of a spectral set.
#[derive(Clone, Debug)]
pub struct SpectralFit {
    pub distribution: DistributionKind,
    pub dispersion: Dispersion,
    /// The fitted model (n, k of a law evaluated at the measured wavelengths).
    pub model: SpectralModel,
    /// Names of the free coordinates (`sigma`, `q`, `eps_inf`, `resonance_um_1`, …,
    /// `n(8.5um)`, …) and their values, 1-σ errors and correlations, in the same order.
    pub names: Vec<String>,
    pub values: Vec<f64>,
    pub errors: Vec<f64>,
    pub correlation: Vec<Vec<f64>>,
    /// 1-σ errors of n, k, ρ_d at each wavelength (of a law's n, k: propagated from it).
    pub n_errors: Vec<f64>,
    pub k_errors: Vec<f64>,
    pub rho_d_errors: Vec<f64>,
    /// 1-σ errors of the other per-wavelength parameters (ρ_s; d, n_sub, d_c when fitted per
    /// wavelength) at each wavelength.
    pub volume_errors: BTreeMap<Parameter, Vec<f64>>,
    pub chi2: f64,
    pub observations: usize,
    pub degrees_of_freedom: usize,
    pub reduced_chi2: f64,
    pub aic: f64,
    pub bic: f64,
    /// χ² and observations of each wavelength.
    pub chi2_per_wavelength: Vec<(f64, usize)>,
    /// The model's Mueller matrices at every point of every wavelength.
    pub model_muellers: Vec<Vec<Mueller>>,
    /// The normalized residuals (model − data)/σ of every wavelength, point by point with the
    /// measured elements in their set's column order (as [`ModelFit::normalized_residuals`]).
    pub normalized_residuals: Vec<Vec<f64>>,
    pub history: StageHistory,
    /// Model evaluations of the joint stage (residual vectors of every wavelength).
    pub evaluations: u64,
    /// What the energy constraint did, one line per wavelength it acted on.
    pub energy: Vec<String>,
    /// Names of the coordinates (as in `names`) resting on a bound of their search interval.
    pub at_bound: Vec<String>,
}

impl SpectralFit {
    /// The fitted value of a shared `parameter` (a free coordinate's, else the first
    /// wavelength's model's); 0 for one the model lacks.
    fn value(&self, parameter: Parameter) -> f64 {
        match self.names.iter().position(|n| n == parameter.name()) {
            Some(i) => self.values[i],
            None => self
                .model
                .nodes()
                .next()
                .and_then(|m| m.parameter(parameter))
                .unwrap_or(0.0),
        }
    }
}

/// A fitted spectral set.
#[derive(Clone, Debug)]
pub struct SpectralFitOutcome {
    /// One set per wavelength, ascending.
    pub measurements: Vec<MeasurementSet>,
    pub material: Material,
    pub chosen: SpectralFit,
    /// The table fit when a law was chosen (for the AIC comparison docs/design.md §1.9 asks for).
    pub table: Option<SpectralFit>,
    /// The other distribution's table fit, when both were fitted.
    pub alternative: Option<SpectralFit>,
    /// Each wavelength's own fit (chosen distribution), where the joint fit started.
    pub per_wavelength: Vec<ModelFit>,
    /// How the model's terms were chosen for the whole set, when there was a choice.
    pub terms_choice: Option<super::TermsChoice>,
}

/// Fits the sets (one material, one per wavelength, ascending) jointly.
pub fn fit_spectral(
    sets: Vec<MeasurementSet>,
    options: &FitOptions,
    dispersion: Dispersion,
) -> Result<SpectralFitOutcome, FitError> {
    fit_spectral_from(sets, options, dispersion, None)
}

/// [`fit_spectral`], with each wavelength's own fits of every distribution (in the order of
/// `options.distributions()`) given in `alone` where they were already made (the choice of
/// terms made them).
pub(crate) fn fit_spectral_from(
    sets: Vec<MeasurementSet>,
    options: &FitOptions,
    dispersion: Dispersion,
    alone: Option<Vec<Vec<ModelFit>>>,
) -> Result<SpectralFitOutcome, FitError> {
    let data = sets
        .iter()
        .map(MeasurementData::new)
        .collect::<Result<Vec<_>, _>>()?;
    let kinds = options.distributions();
    let alone = alone.map_or_else(
        || vec![None; kinds.len()],
        |a| a.into_iter().map(Some).collect(),
    );
    // Both distributions at once: their 2 × K wavelength fits share the cores instead of each
    // distribution's K waiting for its slowest (each fit is seeded, so the result is the same).
    let mut fits = kinds
        .into_par_iter()
        .zip(alone)
        .map(|(kind, given)| {
            let alone = match given {
                Some(fits) => fits,
                None => sets
                    .par_iter()
                    .zip(&data)
                    .map(|(set, data)| fit_model(set, data, kind, options))
                    .collect::<Result<Vec<_>, _>>()?,
            };
            let joint = fit_table(&sets, &data, kind, options, &alone)?;
            Ok((joint, alone))
        })
        .collect::<Result<Vec<_>, FitError>>()?;
    fits.sort_by(|a, b| a.0.aic.total_cmp(&b.0.aic));
    let (table, per_wavelength) = fits.remove(0);
    let alternative = fits.pop().map(|(fit, _)| fit);
    let (chosen, table) = match dispersion {
        Dispersion::Table => (table, None),
        Dispersion::Lorentz(oscillators) => (
            fit_lorentz(&sets, &data, options, &table, oscillators)?,
            Some(table),
        ),
        Dispersion::Cauchy => (fit_cauchy(&sets, &data, options, &table)?, Some(table)),
        Dispersion::Auto if normal_dispersion_applies(options, &table) => {
            (fit_cauchy(&sets, &data, options, &table)?, Some(table))
        }
        Dispersion::Auto => (table, None),
    };
    let material = record::material(
        &sets,
        &data,
        options,
        &chosen,
        table.as_ref(),
        alternative.as_ref(),
    );
    Ok(SpectralFitOutcome {
        measurements: sets,
        material,
        chosen,
        table,
        alternative,
        per_wavelength,
        terms_choice: None,
    })
}

/// The table fit of family `kind`, from the wavelengths' own fits `alone`.
fn fit_table(
    sets: &[MeasurementSet],
    data: &[MeasurementData],
    kind: DistributionKind,
    options: &FitOptions,
    alone: &[ModelFit],
) -> Result<SpectralFit, FitError> {
    let space = model_space(kind, options)?;
    let spaces = vec![space; sets.len()];
    let mut problem = joint_problem(sets, data, &spaces, options, IndexModel::Table, None);
    let median = |p: Parameter| {
        let mut v: Vec<f64> = alone.iter().map(|f| f.value(p)).collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let mut start = Vec::new();
    for &p in &problem.shared {
        start.push(to_search(p, median(p)));
    }
    for &p in &problem.families {
        start.extend(alone.iter().map(|fit| to_search(p, fit.value(p))));
    }
    solve(&mut problem, sets, &start, options, kind, Dispersion::Table)
}

/// The Lorentz fit with `oscillators`, started from the `table` fit.
fn fit_lorentz(
    sets: &[MeasurementSet],
    data: &[MeasurementData],
    options: &FitOptions,
    table: &SpectralFit,
    oscillators: usize,
) -> Result<SpectralFit, FitError> {
    let kind = table.distribution;
    let free: Vec<Parameter> = options
        .free_parameters()?
        .into_iter()
        .filter(|p| !matches!(p, Parameter::N | Parameter::K))
        .collect();
    let mut law_options = options.clone();
    law_options.free = Some(free);
    let space = model_space(kind, &law_options)?;
    let spaces = vec![space; sets.len()];
    let wavelengths = &table.model.wavelength_um;
    let eps: Vec<Complex64> = (0..wavelengths.len())
        .map(|j| Complex64::new(table.model.n[j], table.model.k[j]).powi(2))
        .collect();
    let law_start = lorentz_start(oscillators, wavelengths, &eps);
    let bounds = law_bounds(
        oscillators,
        wavelengths[0],
        wavelengths[wavelengths.len() - 1],
    );
    let model = IndexModel::Lorentz(oscillators);
    let mut problem = joint_problem(sets, data, &spaces, options, model, Some(bounds));
    let mut start = shared_starts(&problem, table);
    start.extend(law_start);
    start.extend(family_starts(&problem, table));
    solve(
        &mut problem,
        sets,
        &start,
        options,
        kind,
        Dispersion::Lorentz(oscillators),
    )
}

/// The fit with Cauchy's normal dispersion (n = A + B/λ², B ≥ 0), started from the `table`
/// fit: A and B from a least-squares line of its n against 1/λ², B held at 0 where the table's n
/// rises with λ. Refused for a material that absorbs (k ≥ [`STRONG_ABSORPTION_K`] at a
/// wavelength): near an absorption band n follows no normal-dispersion law.
fn fit_cauchy(
    sets: &[MeasurementSet],
    data: &[MeasurementData],
    options: &FitOptions,
    table: &SpectralFit,
) -> Result<SpectralFit, FitError> {
    let model = &table.model;
    if let Some(j) = (0..model.k.len()).find(|&j| model.k[j] >= STRONG_ABSORPTION_K) {
        return Err(FitError::Options(format!(
            "--dispersion cauchy is a transparent dielectric's normal dispersion, but {} absorbs \
             (k = {} at {} µm): use --dispersion table or lorentz:N",
            sets[0].material,
            crate::text::significant(model.k[j], 3),
            crate::text::number(model.wavelength_um[j])
        )));
    }
    let kind = table.distribution;
    let free: Vec<Parameter> = options
        .free_parameters()?
        .into_iter()
        .filter(|p| *p != Parameter::N)
        .collect();
    let mut law_options = options.clone();
    law_options.free = Some(free);
    let space = model_space(kind, &law_options)?;
    let spaces = vec![space; sets.len()];
    let bounds = (vec![VOLUME_MIN_N, 0.0], vec![10.0, 1.0]);
    let mut problem = joint_problem(
        sets,
        data,
        &spaces,
        options,
        IndexModel::Cauchy,
        Some(bounds),
    );
    let (a, b) = cauchy_start(&model.wavelength_um, &model.n);
    let mut start = shared_starts(&problem, table);
    start.extend([a, b]);
    start.extend(family_starts(&problem, table));
    solve(
        &mut problem,
        sets,
        &start,
        options,
        kind,
        Dispersion::Cauchy,
    )
}

/// The start of every shared model coordinate of `problem`: the `table` fit's value.
fn shared_starts(problem: &JointProblem, table: &SpectralFit) -> Vec<f64> {
    problem
        .shared
        .iter()
        .map(|&p| to_search(p, table.value(p)))
        .collect()
}

/// The start of every per-wavelength coordinate of `problem`: the `table` fit's value of its
/// parameter at its wavelength (0 where the table's model lacks it).
fn family_starts(problem: &JointProblem, table: &SpectralFit) -> Vec<f64> {
    let model = &table.model;
    let mut start = Vec::new();
    for &p in &problem.families {
        for &wavelength_um in &model.wavelength_um {
            let node = model.at(wavelength_um).ok();
            start.push(to_search(
                p,
                node.and_then(|m| m.parameter(p)).unwrap_or(0.0),
            ));
        }
    }
    start
}

/// A and B ≥ 0 of the least-squares line n = A + B x, x = 1/λ², through the table's `n`.
fn cauchy_start(wavelengths: &[f64], n: &[f64]) -> (f64, f64) {
    let x: Vec<f64> = wavelengths.iter().map(|w| 1.0 / (w * w)).collect();
    let count = x.len() as f64;
    let (mean_x, mean_n) = (x.iter().sum::<f64>() / count, n.iter().sum::<f64>() / count);
    let sxx: f64 = x.iter().map(|x| (x - mean_x).powi(2)).sum();
    let sxn: f64 = x
        .iter()
        .zip(n)
        .map(|(x, n)| (x - mean_x) * (n - mean_n))
        .sum();
    let b = if sxx > 0.0 { (sxn / sxx).max(0.0) } else { 0.0 };
    ((mean_n - b * mean_x).max(VOLUME_MIN_N), b)
}

fn joint_problem<'a>(
    sets: &[MeasurementSet],
    data: &'a [MeasurementData],
    spaces: &'a [ModelSpace],
    options: &FitOptions,
    index_model: IndexModel,
    law_bounds: Option<(Vec<f64>, Vec<f64>)>,
) -> JointProblem<'a> {
    let mut end = 0;
    let blocks = data
        .iter()
        .zip(spaces)
        .zip(sets)
        .map(|((data, space), set)| {
            let rows = end..end + data.observations();
            end = rows.end;
            Block {
                objective: Objective::new(data, space, options.robust),
                wavelength_um: set.wavelength_um,
                rows,
            }
        })
        .collect();
    JointProblem::new(blocks, index_model, law_bounds.unwrap_or_default(), &|p| {
        options.shared_across_wavelengths(p)
    })
}

/// Polishes `problem` from `start` (holding energy at every wavelength) and gathers everything
/// about the optimum.
fn solve(
    problem: &mut JointProblem,
    sets: &[MeasurementSet],
    start: &[f64],
    options: &FitOptions,
    kind: DistributionKind,
    dispersion: Dispersion,
) -> Result<SpectralFit, FitError> {
    let settings = &options.settings.levenberg_marquardt;
    let (best, history, energy) = polish_conserving_energy(problem, start, settings);
    let problem = &*problem;
    let invalid = || FitError::Optimizer {
        file: sets[0].source.clone(),
        stage: "joint lm".into(),
        message: format!("the best {kind} {dispersion} model could not be evaluated"),
    };
    let r = problem.residuals(&best).ok_or_else(invalid)?;
    let (normal_matrix, _) = problem.normal_equations(&best, &r).ok_or_else(invalid)?;
    let values: Vec<_> = (0..sets.len())
        .map(|j| problem.block_values(&best, j))
        .collect();
    let blocks = BlockResults::new(problem, &values).ok_or_else(invalid)?;
    let chi2: f64 = blocks.chi2_per_wavelength.iter().map(|c| c.0).sum();
    let free = best.len();
    let observations = problem.observations;
    let degrees_of_freedom = observations.saturating_sub(free).max(1);
    let reduced_chi2 = chi2 / degrees_of_freedom as f64;
    let coordinates = coordinates(problem, sets);
    let (physical_values, physical_normal_matrix) =
        physical_coordinates(&coordinates, &best, normal_matrix);
    let (errors, correlation, _) = linearized_errors(&physical_normal_matrix, reduced_chi2);
    let law = problem.law(&best);
    let model = spectral_model(problem, &values, law.clone());
    let wavelength_errors = WavelengthErrors::new(
        problem,
        &coordinates,
        law.as_ref(),
        &model.wavelength_um,
        &errors,
        &correlation,
    );
    let at_bound = coordinates_at_bound(problem, &coordinates, &best);
    Ok(SpectralFit {
        distribution: kind,
        dispersion,
        model,
        names: coordinates.into_iter().map(|c| c.0).collect(),
        values: physical_values,
        n_errors: wavelength_errors.n,
        k_errors: wavelength_errors.k,
        rho_d_errors: wavelength_errors.rho_d,
        volume_errors: wavelength_errors.volume,
        errors,
        correlation,
        chi2,
        observations,
        degrees_of_freedom,
        reduced_chi2,
        aic: aic(chi2, free),
        bic: bic(chi2, free, observations),
        chi2_per_wavelength: blocks.chi2_per_wavelength,
        model_muellers: blocks.model_muellers,
        normalized_residuals: blocks.normalized_residuals,
        evaluations: history.evaluations,
        history,
        energy,
        at_bound,
    })
}

/// Rounds of the joint energy constraint (each may move the facets and so the bounds).
const ENERGY_ROUNDS: usize = 4;

/// Levenberg–Marquardt from `start` with docs/design.md §1.10's energy constraint at every
/// wavelength, as one wavelength's fit holds it ([`super::energy`]): where a wavelength's model
/// reflects more than 1, its body reflectance gets the largest value that conserves energy as
/// the upper end of its box, and the whole problem is polished again (the joint form of the
/// active set). Returns the optimum, the history and what the constraint did.
fn polish_conserving_energy(
    problem: &mut JointProblem,
    start: &[f64],
    settings: &super::levenberg_marquardt::LevenbergMarquardtSettings,
) -> (Vec<f64>, StageHistory, Vec<String>) {
    let (mut best, mut history) = levenberg_marquardt(problem, start, settings);
    let mut notes = Vec::new();
    for _ in 0..ENERGY_ROUNDS {
        let mut held = false;
        for j in 0..problem.blocks.len() {
            let values = problem.block_values(&best, j);
            let at = crate::text::number(problem.blocks[j].wavelength_um);
            match check_energy(problem.blocks[j].objective.space(), &values) {
                EnergyCheck::Conserved => {}
                EnergyCheck::FacetsExceed {
                    theta_deg,
                    reflectance,
                } => notes.push(format!(
                    "not conserved at {at} µm: the facets alone reflect {reflectance:.4} at θ = \
                     {theta_deg}°"
                )),
                EnergyCheck::HoldBody { parameter, limit } => {
                    let Some(c) = problem.family_coordinate(parameter, j) else {
                        continue;
                    };
                    problem.upper[c] = to_search(parameter, limit).max(problem.lower[c]);
                    best[c] = best[c].min(problem.upper[c]);
                    held = true;
                    notes.push(format!(
                        "{parameter} at {at} µm held at {limit:.6}, where the hemispherical \
                         reflectance reaches 1 + {ENERGY_TOLERANCE}"
                    ));
                }
            }
        }
        if !held {
            break;
        }
        let (polished, more) = levenberg_marquardt(problem, &best, settings);
        best = polished;
        history.iterations += more.iterations;
        history.evaluations += more.evaluations;
        history.best_cost.extend(more.best_cost);
        history.termination = more.termination;
    }
    (best, history, notes)
}

/// The names of the coordinates resting on a bound of their search interval (within 1e-6 of
/// its width; a held reflectance counts).
fn coordinates_at_bound(
    problem: &JointProblem,
    coordinates: &[(String, Option<Parameter>, Option<usize>)],
    best: &[f64],
) -> Vec<String> {
    coordinates
        .iter()
        .enumerate()
        .filter(|&(c, _)| {
            let margin = 1e-6 * (problem.upper[c] - problem.lower[c]);
            best[c] <= problem.lower[c] + margin || best[c] >= problem.upper[c] - margin
        })
        .map(|(_, coordinate)| coordinate.0.clone())
        .collect()
}

/// What each wavelength's block of the joint problem gives at the optimum.
struct BlockResults {
    chi2_per_wavelength: Vec<(f64, usize)>,
    model_muellers: Vec<Vec<Mueller>>,
    normalized_residuals: Vec<Vec<f64>>,
}

impl BlockResults {
    /// `None` when a block's model cannot be evaluated at its `values`.
    fn new(
        problem: &JointProblem,
        values: &[super::parameters::ParameterValues],
    ) -> Option<BlockResults> {
        let mut chi2_per_wavelength = Vec::new();
        let mut model_muellers = Vec::new();
        let mut normalized_residuals = Vec::new();
        for (j, block) in problem.blocks.iter().enumerate() {
            let residuals = block.objective.normalized_residuals(&values[j])?;
            chi2_per_wavelength.push((residuals.iter().map(|x| x * x).sum(), residuals.len()));
            normalized_residuals.push(residuals);
            model_muellers.push(block.objective.model_muellers(&values[j])?);
        }
        Some(BlockResults {
            chi2_per_wavelength,
            model_muellers,
            normalized_residuals,
        })
    }
}

/// The physical value of each search coordinate at `best`, and JᵀJ with J taken with respect to
/// the physical values: D⁻¹ (JᵀJ) D⁻¹, D the diagonal of each coordinate's d(value)/d(search).
fn physical_coordinates(
    coordinates: &[(String, Option<Parameter>, Option<usize>)],
    best: &[f64],
    normal_matrix: nalgebra::DMatrix<f64>,
) -> (Vec<f64>, nalgebra::DMatrix<f64>) {
    let (physical_values, per_coordinate): (Vec<f64>, Vec<f64>) = coordinates
        .iter()
        .enumerate()
        .map(|(c, coordinate)| match coordinate.1 {
            Some(p) => (from_search(p, best[c]), value_per_coordinate(p, best[c])),
            None => (best[c], 1.0),
        })
        .unzip();
    let mut physical = normal_matrix;
    for (c, &scale) in per_coordinate.iter().enumerate() {
        physical.column_mut(c).unscale_mut(scale);
        physical.row_mut(c).unscale_mut(scale);
    }
    (physical_values, physical)
}

/// The fitted spectral model: each wavelength's model (its block `values` in its block's space:
/// every term the fit had, as a grey fit writes it), and the `law` when n and k follow one.
fn spectral_model(
    problem: &JointProblem,
    values: &[super::parameters::ParameterValues],
    law: Option<LorentzDispersion>,
) -> SpectralModel {
    let nodes: Vec<_> = problem
        .blocks
        .iter()
        .zip(values)
        .map(|(block, v)| block.objective.space().model_spec(v, block.wavelength_um))
        .collect();
    SpectralModel::from_nodes(&nodes, law)
}

/// 1-σ errors of n, k, ρ_d and the other per-wavelength parameters at each wavelength.
struct WavelengthErrors {
    n: Vec<f64>,
    k: Vec<f64>,
    rho_d: Vec<f64>,
    volume: BTreeMap<Parameter, Vec<f64>>,
}

impl WavelengthErrors {
    /// From the coordinates' `errors` and `correlation`: a family's own coordinate (0 where
    /// fixed), or for a law's n and k, propagated from the law's coordinates.
    fn new(
        problem: &JointProblem,
        coordinates: &[(String, Option<Parameter>, Option<usize>)],
        law: Option<&LorentzDispersion>,
        wavelengths: &[f64],
        errors: &[f64],
        correlation: &[Vec<f64>],
    ) -> WavelengthErrors {
        let family_errors = |p: Parameter| {
            (0..wavelengths.len())
                .map(|j| {
                    coordinates
                        .iter()
                        .position(|c| c.1 == Some(p) && c.2 == Some(j))
                        .map_or(0.0, |c| errors[c])
                })
                .collect::<Vec<_>>()
        };
        let (n, k) = match law {
            None if problem.index_model == IndexModel::Cauchy => (
                cauchy_errors(problem, wavelengths, errors, correlation),
                family_errors(Parameter::K),
            ),
            None => (family_errors(Parameter::N), family_errors(Parameter::K)),
            Some(law) => propagate_law_errors(law, problem, wavelengths, errors, correlation),
        };
        let volume = problem
            .families
            .iter()
            .filter(|p| !matches!(p, Parameter::N | Parameter::K | Parameter::RhoD))
            .map(|&p| (p, family_errors(p)))
            .collect();
        WavelengthErrors {
            n,
            k,
            rho_d: family_errors(Parameter::RhoD),
            volume,
        }
    }
}

/// Name, model parameter (None for a law coordinate) and wavelength index of each coordinate.
fn coordinates(
    problem: &JointProblem,
    sets: &[MeasurementSet],
) -> Vec<(String, Option<Parameter>, Option<usize>)> {
    let mut out: Vec<_> = problem
        .shared
        .iter()
        .map(|&p| (p.name().to_owned(), Some(p), None))
        .collect();
    if problem.index_model == IndexModel::Cauchy {
        out.push(("cauchy_a".into(), None, None));
        out.push(("cauchy_b_um2".into(), None, None));
    }
    if let IndexModel::Lorentz(oscillators) = problem.index_model {
        out.push(("eps_inf".into(), None, None));
        for o in 1..=oscillators {
            for name in ["resonance_um", "strength", "damping_um"] {
                out.push((format!("{name}_{o}"), None, None));
            }
        }
    }
    for &p in &problem.families {
        for (j, set) in sets.iter().enumerate() {
            let at = crate::text::number(set.wavelength_um);
            out.push((format!("{}({at}um)", p.name()), Some(p), Some(j)));
        }
    }
    out
}

/// 1-σ errors of a Cauchy law's n at each wavelength: g·C·g with g = ∂n/∂(A, B) = (1, 1/λ²).
fn cauchy_errors(
    problem: &JointProblem,
    wavelengths: &[f64],
    errors: &[f64],
    correlation: &[Vec<f64>],
) -> Vec<f64> {
    let (a, b) = (problem.shared.len(), problem.shared.len() + 1);
    wavelengths
        .iter()
        .map(|w| {
            let g = 1.0 / (w * w);
            let covariance = correlation[a][b] * errors[a] * errors[b];
            (errors[a].powi(2) + 2.0 * g * covariance + g * g * errors[b].powi(2))
                .max(0.0)
                .sqrt()
        })
        .collect()
}

/// 1-σ errors of a law's n and k at each wavelength, g·C·g with g = ∂(n, k)/∂(law) by central
/// differences and C the law coordinates' covariance.
fn propagate_law_errors(
    law: &LorentzDispersion,
    problem: &JointProblem,
    wavelengths: &[f64],
    errors: &[f64],
    correlation: &[Vec<f64>],
) -> (Vec<f64>, Vec<f64>) {
    let at = problem.shared.len();
    let coordinates: Vec<f64> = std::iter::once(law.eps_inf)
        .chain(
            law.oscillators
                .iter()
                .flat_map(|o| [o.resonance_um, o.strength, o.damping_um]),
        )
        .collect();
    let gradient = |w: f64| {
        (0..coordinates.len())
            .map(|c| {
                let h = 1e-6 * coordinates[c].abs().max(1e-3);
                let shifted = |sign: f64| {
                    let mut s = coordinates.clone();
                    s[c] += sign * h;
                    lorentz_start::law_of(&s).index(w)
                };
                let (plus, minus) = (shifted(1.0), shifted(-1.0));
                (
                    (plus.n - minus.n) / (2.0 * h),
                    (plus.k - minus.k) / (2.0 * h),
                )
            })
            .collect::<Vec<_>>()
    };
    let variance = |g: &[f64]| {
        let mut sum = 0.0;
        for (a, ga) in g.iter().enumerate() {
            for (b, gb) in g.iter().enumerate() {
                let (ea, eb) = (errors[at + a], errors[at + b]);
                sum += ga * gb * correlation[at + a][at + b] * ea * eb;
            }
        }
        sum.max(0.0).sqrt()
    };
    wavelengths
        .iter()
        .map(|&w| {
            let g = gradient(w);
            let gn: Vec<f64> = g.iter().map(|x| x.0).collect();
            let gk: Vec<f64> = g.iter().map(|x| x.1).collect();
            (variance(&gn), variance(&gk))
        })
        .unzip()
}
