//! The library entry of a spectral fit: the spectral model and its fit record (docs/design.md §2.2,
//! §2.6), with the per-wavelength errors mirroring the model's arrays.

use super::super::data::MeasurementData;
use super::super::options::FitOptions;
use super::super::outcome::settings;
use super::SpectralFit;
use crate::material::{
    pinned_at_bound, DispersionChoice, FitRecord, Material, MaterialModel, MergedSource,
    WavelengthQuality,
};
use crate::measure::{MeasurementSet, MUELLER_ELEMENT_NAMES};
use std::collections::BTreeMap;

/// The material of the chosen fit, recording the table fit (when a law was chosen) and the other
/// distribution's fit for comparison.
pub(super) fn material(
    sets: &[MeasurementSet],
    data: &[MeasurementData],
    options: &FitOptions,
    chosen: &SpectralFit,
    table: Option<&SpectralFit>,
    alternative: Option<&SpectralFit>,
) -> Material {
    let table_fit = table.unwrap_or(chosen);
    let mut record = FitRecord {
        source: sets[0].source.clone(),
        source_sha256: sets[0].sha256.clone(),
        source_data: None,
        // How the files were read: set by the caller that read them.
        layout: None,
        selection: None,
        angles: None,
        merged_sources: merged_sources(sets),
        points: sets.iter().map(|s| s.points.len()).sum(),
        elements: element_names(sets),
        free_parameters: chosen.names.clone(),
        fixed_parameters: options
            .fixed
            .iter()
            .map(|(p, v)| (p.name().to_owned(), *v))
            .collect(),
        optimizer: format!("{} per wavelength, then joint lm", options.optimizer),
        seed: options.seed,
        settings: spectral_settings(&data[0], options),
        iterations: chosen.history.iterations,
        evaluations: chosen.evaluations,
        cost: chosen.chi2,
        reduced_chi2: chosen.reduced_chi2,
        degrees_of_freedom: chosen.degrees_of_freedom,
        aic: chosen.aic,
        bic: chosen.bic,
        termination: format!("joint lm: {}", chosen.history.termination),
        rmse: rmse(sets, chosen),
        uncertainty: shared_uncertainty(chosen),
        correlation: chosen.correlation.clone(),
        undetermined: Vec::new(),
        at_bound: chosen.at_bound.clone(),
        pinned: pinned_at_bound(&chosen.at_bound, &chosen.names, &chosen.values),
        profile_bounds: BTreeMap::new(),
        uncertainty_per_wavelength: uncertainty_per_wavelength(chosen),
        wavelengths: wavelength_quality(sets, chosen),
        dispersion: Some(dispersion_choice(chosen, table)),
        model_choice: alternative.map(|other| model_choice(table_fit, other)),
        alternative: None,
        convergence: chosen.history.best_cost.clone(),
        global_iterations: 0,
    };
    record.mark_non_finite_as_undetermined();
    Material {
        name: sets[0].material.clone(),
        tool_version: format!("irpol {}", env!("CARGO_PKG_VERSION")),
        model: MaterialModel::Spectral(chosen.model.clone()),
        fit: Some(record),
    }
}

/// The settings of one wavelength's fit, and how the joint fit followed.
fn spectral_settings(data: &MeasurementData, options: &FitOptions) -> BTreeMap<String, String> {
    let mut settings = settings(data, options);
    settings.insert(
        "spectral".into(),
        "each wavelength fitted alone (the stages above), then jointly by lm from the medians of \
         σ and q"
            .into(),
    );
    settings
}

/// 1-σ errors of the coordinates shared by every wavelength (a per-wavelength name has '(').
fn shared_uncertainty(chosen: &SpectralFit) -> BTreeMap<String, f64> {
    chosen
        .names
        .iter()
        .zip(&chosen.errors)
        .filter(|(name, _)| !name.contains('('))
        .map(|(name, &e)| (name.clone(), e))
        .collect()
}

/// 1-σ errors of n, k, ρ_d and the other per-wavelength parameters at each wavelength, by
/// name.
fn uncertainty_per_wavelength(chosen: &SpectralFit) -> BTreeMap<String, Vec<f64>> {
    [
        ("n", &chosen.n_errors),
        ("k", &chosen.k_errors),
        ("rho_d", &chosen.rho_d_errors),
    ]
    .into_iter()
    .chain(chosen.volume_errors.iter().map(|(p, e)| (p.name(), e)))
    .map(|(name, errors)| (name.to_owned(), errors.clone()))
    .collect()
}

/// The dispersion chosen, with the table fit's criteria and, when a law was chosen over the
/// `table` fit, the law's.
fn dispersion_choice(chosen: &SpectralFit, table: Option<&SpectralFit>) -> DispersionChoice {
    let table_fit = table.unwrap_or(chosen);
    DispersionChoice {
        chosen: chosen.dispersion.to_string(),
        table_aic: table_fit.aic,
        table_bic: table_fit.bic,
        law_aic: table.map(|_| chosen.aic),
        law_bic: table.map(|_| chosen.bic),
    }
}

/// Why the table fit's distribution was preferred over the `other`'s.
fn model_choice(table_fit: &SpectralFit, other: &SpectralFit) -> String {
    format!(
        "{} preferred over {} (ΔAIC = {:.1}, ΔBIC = {:.1}, table fits)",
        table_fit.distribution,
        other.distribution,
        other.aic - table_fit.aic,
        other.bic - table_fit.bic
    )
}

/// Every file after the first, once each (a spectral file gives several sets), with its rows.
fn merged_sources(sets: &[MeasurementSet]) -> Vec<MergedSource> {
    let first = &sets[0].sha256;
    let mut merged: Vec<MergedSource> = Vec::new();
    let files = sets.iter().flat_map(|set| {
        std::iter::once((set.source.clone(), set.sha256.clone(), set.points.len())).chain(
            set.merged
                .iter()
                .map(|f| (f.path.clone(), f.sha256.clone(), f.rows)),
        )
    });
    for (source, sha256, rows) in files.filter(|f| f.1 != *first) {
        match merged.iter_mut().find(|m| m.source_sha256 == sha256) {
            Some(m) => m.points += rows,
            None => merged.push(MergedSource {
                source,
                source_sha256: sha256,
                source_data: None,
                points: rows,
            }),
        }
    }
    merged
}

/// The Mueller elements measured at any wavelength, in index order.
fn element_names(sets: &[MeasurementSet]) -> Vec<String> {
    let mut elements: Vec<usize> = sets.iter().flat_map(|s| s.elements.clone()).collect();
    elements.sort_unstable();
    elements.dedup();
    elements
        .iter()
        .map(|&e| MUELLER_ELEMENT_NAMES[e].to_owned())
        .collect()
}

fn wavelength_quality(sets: &[MeasurementSet], fit: &SpectralFit) -> Vec<WavelengthQuality> {
    sets.iter()
        .zip(&fit.chi2_per_wavelength)
        .map(|(set, &(chi2, observations))| WavelengthQuality {
            wavelength_um: set.wavelength_um,
            points: set.points.len(),
            chi2_per_observation: chi2 / observations.max(1) as f64,
        })
        .collect()
}

/// RMS of (model − data) in sr⁻¹ per element over every wavelength that measured it.
fn rmse(sets: &[MeasurementSet], fit: &SpectralFit) -> BTreeMap<String, f64> {
    let mut sums: BTreeMap<usize, (f64, usize)> = BTreeMap::new();
    for (set, muellers) in sets.iter().zip(&fit.model_muellers) {
        for (point, m) in set.points.iter().zip(muellers) {
            for (e, &index) in set.elements.iter().enumerate() {
                let entry = sums.entry(index).or_default();
                entry.0 += (m[(index / 4, index % 4)] - point.values[e]).powi(2);
                entry.1 += 1;
            }
        }
    }
    sums.into_iter()
        .map(|(index, (sum, count))| {
            (
                MUELLER_ELEMENT_NAMES[index].to_owned(),
                (sum / count.max(1) as f64).sqrt(),
            )
        })
        .collect()
}
