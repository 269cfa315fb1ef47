//! The fit at each wavelength: the grey report of that wavelength's measurement against the joint
//! model there, drawn from a grey material whose record is the spectral one's at that wavelength.

use super::super::fit_report::encode_fit_figure;
use super::super::ReportError;
use super::wavelength_report_path;
use crate::fit::{aic, bic, SpectralFit, SpectralFitOutcome};
use crate::material::{AlternativeFit, FitRecord, Material, MaterialModel};
use crate::measure::{MeasurementSet, MUELLER_ELEMENT_NAMES};
use crate::optics::Mueller;
use crate::text::number;
use rayon::prelude::*;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// `<dir>/<λ>um.png` for every wavelength, ascending.
pub fn encode_wavelength_reports(
    outcome: &SpectralFitOutcome,
    dir: &Path,
) -> Result<Vec<(PathBuf, Vec<u8>)>, ReportError> {
    outcome
        .measurements
        .par_iter()
        .enumerate()
        .map(|(j, set)| {
            let path = wavelength_report_path(dir, set.wavelength_um);
            let material = grey_material(outcome, j)?;
            Ok((path.clone(), encode_fit_figure(&material, set, &path)?))
        })
        .collect()
}

/// The joint model at wavelength `j` as a grey material, so the grey report draws it.
pub fn grey_material(outcome: &SpectralFitOutcome, j: usize) -> Result<Material, ReportError> {
    let material = &outcome.material;
    let set = outcome
        .measurements
        .get(j)
        .ok_or_else(|| ReportError::Draw {
            path: PathBuf::from(&material.name),
            message: format!("no measurement at wavelength number {}", j + 1),
        })?;
    let model = material.at(set.wavelength_um)?;
    Ok(Material {
        name: material.name.clone(),
        tool_version: material.tool_version.clone(),
        model: MaterialModel::Grey(model),
        fit: material
            .fit
            .as_ref()
            .map(|record| wavelength_record(outcome, record, set, j)),
    })
}

/// The grey table's parameters free at wavelength `j` of `set`, their 1-σ errors, and their
/// correlations in the joint fit.
struct FreeAt {
    names: Vec<String>,
    uncertainty: BTreeMap<String, f64>,
    correlation: Vec<Vec<f64>>,
}

fn free_at(fit: &SpectralFit, record: &FitRecord, set: &MeasurementSet, j: usize) -> FreeAt {
    let at = format!("({}um)", number(set.wavelength_um));
    // Each parameter of the grey table and its coordinate in the joint fit, if free there (a
    // law's n, k are not: their errors are propagated from it).
    let coordinate = |name: &str| -> Option<usize> {
        let joint = if matches!(name, "sigma" | "q") {
            name.to_owned()
        } else {
            format!("{name}{at}")
        };
        fit.names.iter().position(|n| *n == joint)
    };
    let mut uncertainty: BTreeMap<String, f64> = ["sigma", "q"]
        .into_iter()
        .filter_map(|name| Some((name.to_owned(), *record.uncertainty.get(name)?)))
        .collect();
    for (name, errors) in [
        ("n", &fit.n_errors),
        ("k", &fit.k_errors),
        ("rho_d", &fit.rho_d_errors),
    ] {
        uncertainty.extend(errors.get(j).map(|&e| (name.to_owned(), e)));
    }
    let names: Vec<String> = ["sigma", "q", "n", "k", "rho_d"]
        .into_iter()
        .filter(|&name| coordinate(name).is_some() || uncertainty.contains_key(name))
        .map(str::to_owned)
        .collect();
    let correlation = names
        .iter()
        .map(|a| {
            names
                .iter()
                .map(|b| match (coordinate(a), coordinate(b)) {
                    (Some(i), Some(k)) => fit
                        .correlation
                        .get(i)
                        .and_then(|row| row.get(k))
                        .copied()
                        .unwrap_or(f64::NAN),
                    _ if a == b => 1.0,
                    _ => f64::NAN,
                })
                .collect()
        })
        .collect();
    FreeAt {
        names,
        uncertainty,
        correlation,
    }
}

/// The spectral record at wavelength `j`: that wavelength's data, χ² and errors of n, k, ρd, the
/// shared σ, q, their correlations, and the other distribution's fit there for comparison.
fn wavelength_record(
    outcome: &SpectralFitOutcome,
    record: &FitRecord,
    set: &MeasurementSet,
    j: usize,
) -> FitRecord {
    let fit = &outcome.chosen;
    let FreeAt {
        names: free,
        uncertainty,
        correlation,
    } = free_at(fit, record, set, j);
    let (chi2, observations) = fit.chi2_per_wavelength.get(j).copied().unwrap_or_default();
    let dof = observations.saturating_sub(free.len());
    FitRecord {
        source: set.source.clone(),
        source_sha256: set.sha256.clone(),
        source_data: None,
        layout: None,
        selection: None,
        angles: None,
        merged_sources: Vec::new(),
        points: set.points.len(),
        elements: set
            .elements
            .iter()
            .map(|&e| MUELLER_ELEMENT_NAMES[e].to_owned())
            .collect(),
        free_parameters: free.clone(),
        fixed_parameters: record.fixed_parameters.clone(),
        optimizer: record.optimizer.clone(),
        seed: record.seed,
        settings: record.settings.clone(),
        iterations: record.iterations,
        evaluations: record.evaluations,
        cost: chi2,
        reduced_chi2: chi2 / dof.max(1) as f64,
        degrees_of_freedom: dof,
        aic: aic(chi2, free.len()),
        bic: bic(chi2, free.len(), observations),
        termination: record.termination.clone(),
        rmse: rmse(set, fit.model_muellers.get(j).map_or(&[], Vec::as_slice)),
        uncertainty,
        correlation,
        undetermined: Vec::new(),
        at_bound: Vec::new(),
        pinned: Vec::new(),
        profile_bounds: BTreeMap::new(),
        uncertainty_per_wavelength: BTreeMap::new(),
        wavelengths: Vec::new(),
        dispersion: None,
        model_choice: record.model_choice.clone(),
        alternative: outcome
            .alternative
            .as_ref()
            .and_then(|other| alternative_at(other, set, j, free.len())),
        convergence: Vec::new(),
        global_iterations: 0,
    }
}

/// The other distribution's joint fit at wavelength `j`, with as many free parameters.
fn alternative_at(
    other: &SpectralFit,
    set: &MeasurementSet,
    j: usize,
    free: usize,
) -> Option<AlternativeFit> {
    let (chi2, observations) = *other.chi2_per_wavelength.get(j)?;
    Some(AlternativeFit {
        model: other.model.at(set.wavelength_um).ok()?,
        cost: chi2,
        reduced_chi2: chi2 / observations.saturating_sub(free).max(1) as f64,
        aic: aic(chi2, free),
        bic: bic(chi2, free, observations),
    })
}

/// RMS of (model − data) in sr⁻¹ per measured element of `set`.
fn rmse(set: &MeasurementSet, muellers: &[Mueller]) -> BTreeMap<String, f64> {
    set.elements
        .iter()
        .enumerate()
        .map(|(column, &element)| {
            let (sum, count) = set
                .points
                .iter()
                .zip(muellers)
                .map(|(point, m)| (m[(element / 4, element % 4)] - point.values[column]).powi(2))
                .fold((0.0, 0usize), |(s, c), r| (s + r, c + 1));
            let name = MUELLER_ELEMENT_NAMES[element].to_owned();
            (name, (sum / count.max(1) as f64).sqrt())
        })
        .collect()
}
