//! `irpol fit` on files: read and validate every input first, fit them all, then write
//! `fits/<material>.toml` for each (atomically), so a bad input leaves the library untouched.

use super::data::MeasurementData;
use super::options::FitOptions;
use super::outcome::{fit_measurement, FitOutcome};
use super::space::ModelSpace;
use super::FitError;
use crate::measure::{
    collect_measurement_files, merge_repeat_measurements, read_measurement_csv, MeasurementSet,
};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Fits every measurement CSV among `inputs` (files, or folders of `*.csv`) and writes each
/// chosen model to `fits_dir/<material>.toml` with [`crate::material::Material::save`].
///
/// Nothing is written unless every input reads, validates and fits: malformed files, options
/// that make no valid model, and files of one material that cannot be merged as repeat
/// measurements are refused up front (those that can are merged, with a note in the set). A
/// progress bar is drawn on stderr when `progress` is set and stderr is a terminal.
pub fn fit_files(
    inputs: &[PathBuf],
    options: &FitOptions,
    fits_dir: &Path,
    progress: bool,
) -> Result<Vec<FitOutcome>, FitError> {
    let outcomes = fit_inputs(inputs, options, progress)?;
    for outcome in &outcomes {
        let path = fits_dir.join(format!("{}.toml", outcome.material.name));
        outcome.material.save(&path)?;
    }
    Ok(outcomes)
}

/// [`fit_files`] without writing: every outcome, for a caller that writes the library entries
/// together with other outputs (`irpol fit` adds reports and an index).
pub fn fit_inputs(
    inputs: &[PathBuf],
    options: &FitOptions,
    progress: bool,
) -> Result<Vec<FitOutcome>, FitError> {
    let sets = read_all(inputs)?;
    validate_options(options)?;

    let bar = (progress && std::io::stderr().is_terminal()).then(|| {
        let bar = ProgressBar::new(sets.len() as u64);
        bar.set_style(
            ProgressStyle::with_template("fitting {bar:30} {pos}/{len} {msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
        );
        bar
    });
    let mut outcomes = Vec::with_capacity(sets.len());
    for set in &sets {
        if let Some(bar) = &bar {
            bar.set_message(set.material.clone());
        }
        let outcome = fit_measurement(set, options);
        if let Some(bar) = &bar {
            bar.inc(1);
        }
        outcomes.push(outcome.inspect_err(|_| {
            if let Some(bar) = &bar {
                bar.abandon();
            }
        })?);
    }
    if let Some(bar) = &bar {
        bar.finish_and_clear();
    }
    Ok(outcomes)
}

/// Reads every input and checks that each set can be fitted, before any fitting starts.
fn read_all(inputs: &[PathBuf]) -> Result<Vec<MeasurementSet>, FitError> {
    if inputs.is_empty() {
        return Err(FitError::Options("no measurement file given".into()));
    }
    let files = collect_measurement_files(inputs)?;
    let sets = files
        .iter()
        .map(|file| read_measurement_csv(file))
        .collect::<Result<Vec<_>, _>>()?;
    let sets = merge_materials(sets)?;
    for set in &sets {
        MeasurementData::new(set)?;
    }
    Ok(sets)
}

/// Builds the model spaces the options ask for, which checks bounds, free and fixed values.
fn validate_options(options: &FitOptions) -> Result<(), FitError> {
    let free = options.free_parameters()?;
    for kind in options.distributions() {
        ModelSpace::new(
            kind,
            options.shadowing,
            &free,
            options.base_values(),
            &options.bounds,
        )?;
    }
    Ok(())
}

/// The sets of each material, in the order the materials first appear, files of one material
/// merged as repeat measurements (DESIGN §1.9).
fn merge_materials(sets: Vec<MeasurementSet>) -> Result<Vec<MeasurementSet>, FitError> {
    let mut groups: Vec<Vec<MeasurementSet>> = Vec::new();
    for set in sets {
        match groups.iter_mut().find(|g| g[0].material == set.material) {
            Some(group) => group.push(set),
            None => groups.push(vec![set]),
        }
    }
    let mut merged = Vec::with_capacity(groups.len());
    for group in groups {
        merged.extend(merge_repeat_measurements(group)?);
    }
    Ok(merged)
}
