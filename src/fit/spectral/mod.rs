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
mod optimum;
use optimum::solve;
mod record;

use super::admissible::STRONG_ABSORPTION_K;
use super::comparison::{aic, bic};
use super::data::MeasurementData;
use super::energy::{check_energy, EnergyCheck, ENERGY_TOLERANCE};
use super::levenberg_marquardt::{levenberg_marquardt, LeastSquares};
use super::model_fit::{fit_model, model_space, ModelFit};
use super::objective::Objective;
use super::options::FitOptions;
use super::parameters::{from_search, to_search, value_per_coordinate};
use super::space::ModelSpace;
use super::space::VOLUME_MIN_N;
use super::stages::StageHistory;
use super::uncertainty::linearized_errors;
use super::FitError;
use crate::material::{Material, SpectralModel};
use crate::measure::MeasurementSet;
use crate::optics::{LorentzDispersion, Mueller};
use crate::pbrdf::{DistributionKind, Parameter};
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
                    .map(|(set, data)| fit_model(set, data.into(), kind, options))
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
