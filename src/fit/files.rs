//! `irpol fit` on files: read and validate every input first, fit them all, then write
//! `fits/<material>.toml` for each (atomically), so a bad input leaves the library untouched.

use super::data::MeasurementData;
use super::options::FitOptions;
use super::outcome::FitOutcome;
use super::space::ModelSpace;
use super::spectral::{fit_spectral, fit_spectral_from, SpectralFitOutcome};
use super::FitError;
use crate::material::Material;
use crate::measure::{
    collect_measurement_files, merge_repeat_measurements, AngleReading, MeasurementSet,
    ReadOptions, SAME_WAVELENGTH_UM,
};
use crate::progress::Progress;
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// One material's fit: of one wavelength, or jointly of several (a spectral set, docs/design.md §1.9).
#[derive(Clone, Debug)]
pub enum MaterialFit {
    Grey(Box<FitOutcome>),
    Spectral(Box<SpectralFitOutcome>),
}

impl MaterialFit {
    /// The library entry.
    pub fn material(&self) -> &Material {
        match self {
            MaterialFit::Grey(o) => &o.material,
            MaterialFit::Spectral(o) => &o.material,
        }
    }

    /// What the reader did that the user should know, one line each and each once (the sets
    /// of one file carry the file's notes alike).
    pub fn notes(&self) -> Vec<String> {
        match self {
            MaterialFit::Grey(o) => once([&o.measurement]),
            MaterialFit::Spectral(o) => once(&o.measurements),
        }
    }
}

/// The notes of `sets`, each once, in order.
fn once<'a>(sets: impl IntoIterator<Item = &'a MeasurementSet>) -> Vec<String> {
    let mut once: Vec<String> = Vec::new();
    for note in sets.into_iter().flat_map(|set| &set.notes) {
        if !once.contains(note) {
            once.push(note.clone());
        }
    }
    once
}

/// Every input of a fit read and checked, before any fitting starts (`irpol fit` prints the
/// readers' notes before the fit, and repeats those about angle units with any error): the sets
/// of each material, one per wavelength, ascending.
#[derive(Clone, Debug)]
pub struct FitInputs {
    materials: Vec<Vec<MeasurementSet>>,
}

impl FitInputs {
    /// Reads every file among `inputs` (files, or folders of `*.csv`) as `reading` says and
    /// checks that each set can be fitted; files of one material are merged.
    pub fn read(inputs: &[PathBuf], reading: &ReadOptions) -> Result<FitInputs, FitError> {
        Ok(FitInputs {
            materials: read_all(inputs, reading)?,
        })
    }

    /// What the readers did that the user should know, each note once.
    pub fn notes(&self) -> Vec<String> {
        once(self.materials.iter().flatten())
    }
}

/// Fits every measurement CSV among `inputs` (files, or folders of `*.csv`) and writes each
/// chosen model to `fits_dir/<material>.toml` with [`crate::material::Material::save`].
///
/// Nothing is written unless every input reads, validates and fits: malformed files, options
/// that make no valid model, and files of one material that cannot be merged as repeat
/// measurements are refused up front (those that can are merged, with a note in the set).
/// `progress` hears of each material as it is fitted (the binary draws a bar from it).
pub fn fit_files(
    inputs: &[PathBuf],
    options: &FitOptions,
    fits_dir: &Path,
    progress: &dyn Progress,
) -> Result<Vec<MaterialFit>, FitError> {
    let outcomes = fit_inputs(inputs, options, progress)?;
    for outcome in &outcomes {
        let material = outcome.material();
        let path = fits_dir.join(format!("{}.toml", material.name));
        material.save(&path)?;
    }
    Ok(outcomes)
}

/// [`fit_files`] without writing: every outcome, for a caller that writes the library entries
/// together with other outputs (`irpol fit` adds reports and an index). A material measured at
/// several wavelengths is fitted jointly ([`fit_spectral`]). Each file is read as it says
/// (docs/design.md §2.1, or through the layout its `# layout:` line names).
pub fn fit_inputs(
    inputs: &[PathBuf],
    options: &FitOptions,
    progress: &dyn Progress,
) -> Result<Vec<MaterialFit>, FitError> {
    fit_inputs_with(inputs, &ReadOptions::default(), options, progress)
}

/// [`fit_inputs`] of the files read through `reading`'s layout and with only its selected rows;
/// each fit record names the layout given and the selection, so that `irpol report` re-reads
/// the same rows the same way.
pub fn fit_inputs_with(
    inputs: &[PathBuf],
    reading: &ReadOptions,
    options: &FitOptions,
    progress: &dyn Progress,
) -> Result<Vec<MaterialFit>, FitError> {
    fit_read_inputs(
        FitInputs::read(inputs, reading)?,
        reading,
        options,
        progress,
    )
}

/// [`fit_inputs_with`] of inputs already read by [`FitInputs::read`] with `reading`.
pub fn fit_read_inputs(
    inputs: FitInputs,
    reading: &ReadOptions,
    options: &FitOptions,
    progress: &dyn Progress,
) -> Result<Vec<MaterialFit>, FitError> {
    let materials = inputs.materials;
    validate_options(options)?;
    refuse_law_of_one_wavelength(&materials, options)?;
    super::cost::check_costs(&materials, options)?;

    progress.begin("fitting", materials.len() as u64);
    let mut outcomes = Vec::with_capacity(materials.len());
    for mut sets in materials {
        progress.message(&sets[0].material);
        let outcome = if sets.len() == 1 {
            // The set becomes the outcome's: no copy of its rows.
            let set = sets.pop().expect("one set");
            super::cross_validation::fit_grey_set(Cow::Owned(set), options)
                .map(|o| MaterialFit::Grey(Box::new(o)))
        } else {
            fit_spectral_choosing_terms(sets, options).map(|o| MaterialFit::Spectral(Box::new(o)))
        };
        progress.advance(1);
        let mut outcome = outcome.inspect_err(|_| progress.abandon())?;
        record_reading(&mut outcome, reading);
        outcomes.push(outcome);
    }
    progress.end();
    Ok(outcomes)
}

/// The joint fit of a spectral set (`fit_spectral`), with its terms chosen for the whole set
/// first when `options` ask for a choice (docs/design.md §1.10).
fn fit_spectral_choosing_terms(
    sets: Vec<MeasurementSet>,
    options: &FitOptions,
) -> Result<SpectralFitOutcome, FitError> {
    if options.term_candidates.is_empty() && options.cv_folds.is_none() {
        return fit_spectral(sets, options, options.dispersion);
    }
    let (choice, alone) = super::cross_validation::choose_spectral_terms(&sets, options)?;
    let options = options.with_terms(choice.scores[choice.chosen].terms);
    let mut outcome = fit_spectral_from(sets, &options, options.dispersion, Some(alone))?;
    choice.note_sample(&mut outcome.material);
    outcome.terms_choice = Some(choice);
    Ok(outcome)
}

/// Writes how the files were read into the fit record: the layout given (a layout the file
/// names itself is found again from the file) and the selection, when it keeps less than all.
fn record_reading(outcome: &mut MaterialFit, reading: &ReadOptions) {
    let material = match outcome {
        MaterialFit::Grey(o) => &mut o.material,
        MaterialFit::Spectral(o) => &mut o.material,
    };
    if let Some(record) = material.fit.as_mut() {
        record.layout = reading.layout.as_ref().map(|l| l.source.clone());
        record.selection = (!reading.selection.is_everything()).then(|| reading.selection.clone());
        record.angles = (reading.angles != AngleReading::Auto).then_some(reading.angles);
    }
}

/// Reads every input and checks that each set can be fitted, before any fitting starts: the
/// sets of each material, one per wavelength, ascending.
fn read_all(
    inputs: &[PathBuf],
    reading: &ReadOptions,
) -> Result<Vec<Vec<MeasurementSet>>, FitError> {
    if inputs.is_empty() {
        return Err(FitError::Options("no measurement file given".into()));
    }
    reading.selection.check()?;
    let mut sets = Vec::new();
    for input in inputs {
        let mut read = Vec::new();
        for file in collect_measurement_files(std::slice::from_ref(input))? {
            read.extend(reading.read(&file)?);
        }
        if input.is_dir() {
            check_folder_materials(input, &read)?;
        }
        sets.extend(read);
    }
    let materials = merge_materials(sets)?;
    for set in materials.iter().flatten() {
        MeasurementData::new(set)?;
    }
    Ok(materials)
}

/// Refuses a folder of several files where one has no `# material:` line: its material would be
/// its file name, so files of one material measured at different wavelengths would be fitted as
/// different materials (and files of different materials could not be told apart).
fn check_folder_materials(folder: &Path, sets: &[MeasurementSet]) -> Result<(), FitError> {
    let files: std::collections::BTreeSet<&Path> =
        sets.iter().map(|s| s.source.as_path()).collect();
    if files.len() < 2 {
        return Ok(());
    }
    match sets.iter().find(|s| !s.metadata.contains_key("material")) {
        Some(set) => Err(FitError::Measurement {
            file: set.source.clone(),
            message: format!(
                "has no '# material:' line, and the folder {} holds {} measurement files: add \
                 '# material: NAME' to each so that irpol knows which belong to one material",
                crate::text::path(folder),
                files.len()
            ),
        }),
        None => Ok(()),
    }
}

/// Builds the model spaces the options ask for, which checks bounds, free and fixed values.
/// A dispersion law (`--dispersion cauchy` or `lorentz:N`) needs a material measured at two
/// wavelengths or more: refused up front, naming the file and its one wavelength.
fn refuse_law_of_one_wavelength(
    materials: &[Vec<MeasurementSet>],
    options: &FitOptions,
) -> Result<(), FitError> {
    if matches!(
        options.dispersion,
        super::Dispersion::Table | super::Dispersion::Auto
    ) {
        return Ok(());
    }
    match materials.iter().find(|sets| sets.len() == 1) {
        Some(sets) => Err(FitError::Options(format!(
            "--dispersion {}: {} measures '{}' at one wavelength ({} µm); a dispersion law \
             relates several: fit it without --dispersion (or give its other wavelengths)",
            options.dispersion,
            sets[0].source.display(),
            sets[0].material,
            crate::text::number(sets[0].wavelength_um)
        ))),
        None => Ok(()),
    }
}

fn validate_options(options: &FitOptions) -> Result<(), FitError> {
    let free = options.free_parameters()?;
    for kind in options.distributions() {
        ModelSpace::new(
            kind,
            options.shadowing,
            options.terms,
            &free,
            options.base_values(),
            &options.bounds,
        )?;
    }
    Ok(())
}

/// The sets of each material, in the order the materials first appear: one per wavelength,
/// ascending, files of one material at one wavelength merged as repeat measurements (docs/design.md
/// §1.9). Files of one material must agree on what they measure (the Mueller convention and
/// any `# distribution:` they state).
fn merge_materials(sets: Vec<MeasurementSet>) -> Result<Vec<Vec<MeasurementSet>>, FitError> {
    let mut materials: Vec<Vec<Vec<MeasurementSet>>> = Vec::new();
    for set in sets {
        let Some(material) = materials
            .iter_mut()
            .find(|m| m[0][0].material == set.material)
        else {
            materials.push(vec![vec![set]]);
            continue;
        };
        check_consistent(&material[0][0], &set)?;
        match material
            .iter_mut()
            .find(|w| (w[0].wavelength_um - set.wavelength_um).abs() <= SAME_WAVELENGTH_UM)
        {
            Some(wavelength) => wavelength.push(set),
            None => material.push(vec![set]),
        }
    }
    let mut merged = Vec::with_capacity(materials.len());
    for wavelengths in materials {
        let mut sets = Vec::with_capacity(wavelengths.len());
        for group in wavelengths {
            sets.extend(merge_repeat_measurements(group)?);
        }
        sets.sort_by(|a, b| a.wavelength_um.total_cmp(&b.wavelength_um));
        merged.push(sets);
    }
    Ok(merged)
}

/// Refuses two files of one material that disagree on a header that says what was measured.
fn check_consistent(first: &MeasurementSet, other: &MeasurementSet) -> Result<(), FitError> {
    for key in ["mueller_convention", "distribution"] {
        let (a, b) = (first.metadata.get(key), other.metadata.get(key));
        if a.is_some() && b.is_some() && a != b {
            return Err(FitError::Measurement {
                file: other.source.clone(),
                message: format!(
                    "'# {key}: {}' disagrees with '# {key}: {}' of {}, another file of material \
                     '{}'",
                    crate::text::shown(b.map_or("", |v| v.as_str())),
                    crate::text::shown(a.map_or("", |v| v.as_str())),
                    crate::text::path(&first.source),
                    first.material
                ),
            });
        }
    }
    Ok(())
}
