//! What a spectral fit's joint problem gives at its optimum: the polish that holds energy at
//! every wavelength, the coordinates at a bound, each wavelength's model and quality, and the
//! 1-σ errors of the per-wavelength parameters, propagated through a dispersion law where n and
//! k follow one.

use super::*;

/// Polishes `problem` from `start` (holding energy at every wavelength) and gathers everything
/// about the optimum.
pub(super) fn solve(
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
/// wavelength, as one wavelength's fit holds it ([`super::super::energy`]): where a wavelength's model
/// reflects more than 1, its body reflectance gets the largest value that conserves energy as
/// the upper end of its box, and the whole problem is polished again (the joint form of the
/// active set). Returns the optimum, the history and what the constraint did.
fn polish_conserving_energy(
    problem: &mut JointProblem,
    start: &[f64],
    settings: &super::super::levenberg_marquardt::LevenbergMarquardtSettings,
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
        values: &[super::super::parameters::ParameterValues],
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
    values: &[super::super::parameters::ParameterValues],
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
