//! `irpol validate MATERIAL.toml DATA...` (docs/design.md §4): how a material's model predicts
//! measurements it was not fitted to — one summary line per measurement set, and a report page
//! each (`<reports>/<material>_validation_<data>.png`, `<data>_<λ>um` for each wavelength of a
//! file that holds several), written atomically.

use super::{material_pbrdf_from, AppError, WavelengthOrigin};
use crate::atomic::OutputSet;
use crate::fit::{validate_model, Validation};
use crate::material::{Material, MaterialModel};
use crate::measure::{collect_measurement_files, MeasurementSet, ReadOptions};
use crate::report::fit_report::encode_validation_report;
use std::path::{Path, PathBuf};

/// One measurement set as `validate` scored it.
pub struct SetValidation {
    pub set: MeasurementSet,
    pub validation: Validation,
    /// The report page written for it.
    pub report: PathBuf,
}

/// Scores the model of `material` on every set of `inputs` (files or folders, read as
/// `reading` says: a layout, a row selection) and writes a report page per set into
/// `reports_dir`, all or nothing.
pub fn validate_and_report(
    material: &Path,
    inputs: &[PathBuf],
    reading: &ReadOptions,
    reports_dir: &Path,
) -> Result<Vec<SetValidation>, AppError> {
    let material_path = material;
    let material = Material::load(material)?;
    let mut sets = Vec::new();
    for file in collect_measurement_files(inputs)? {
        sets.extend(reading.read(&file)?);
    }
    validate_sets(&material, material_path, sets, reports_dir)
}

/// [`validate_and_report`] of sets already read (a layout or a row selection applied);
/// `material_path` is the material's file, which messages name.
pub fn validate_sets(
    material: &Material,
    material_path: &Path,
    sets: Vec<MeasurementSet>,
    reports_dir: &Path,
) -> Result<Vec<SetValidation>, AppError> {
    if sets.is_empty() {
        return Err(AppError::invalid("no measurement to validate against"));
    }
    let mut outputs = OutputSet::new();
    let mut results = Vec::new();
    let names = page_names(&sets);
    for (set, data_name) in sets.into_iter().zip(names) {
        let wavelength = material.model.spectral().map(|_| {
            (
                set.wavelength_um,
                WavelengthOrigin::Data(set.source.clone()),
            )
        });
        let model = material_pbrdf_from(material, material_path, wavelength, None)?;
        let validation = validate_model(&model, &set)?;
        // A spectral material's page shows its model at the set's wavelength.
        let at_wavelength = Material {
            model: MaterialModel::Grey(material.at(set.wavelength_um)?),
            ..material.clone()
        };
        let report = encode_validation_report(
            &at_wavelength,
            &set,
            &data_name,
            &validation_summary(&validation),
            reports_dir,
        )?;
        let mut report_path = PathBuf::new();
        for (path, bytes) in report.files {
            outputs
                .stage(&path, &bytes)
                .map_err(|source| AppError::Write {
                    path: path.clone(),
                    source,
                })?;
            report_path = path;
        }
        results.push(SetValidation {
            set,
            validation,
            report: report_path,
        });
    }
    outputs.commit().map_err(|source| AppError::Write {
        path: reports_dir.to_owned(),
        source,
    })?;
    Ok(results)
}

/// The data part of each set's page name, one distinct name per set: the file's stem, with the
/// set's wavelength where several sets share the stem (a file of several wavelengths, docs/
/// design.md §1.9), and a count where even that is shared (two folders' files of one name).
fn page_names(sets: &[MeasurementSet]) -> Vec<String> {
    let stem = |set: &MeasurementSet| {
        set.source
            .file_stem()
            .map_or_else(|| "data".into(), |s| s.to_string_lossy().into_owned())
    };
    let stems: Vec<String> = sets.iter().map(stem).collect();
    let mut names: Vec<String> = sets
        .iter()
        .zip(&stems)
        .map(
            |(set, stem)| match stems.iter().filter(|s| *s == stem).count() {
                1 => stem.clone(),
                _ => format!("{stem}_{}um", crate::text::number(set.wavelength_um)),
            },
        )
        .collect();
    for k in 0..names.len() {
        let repeats = names[..k].iter().filter(|n| **n == names[k]).count();
        if repeats > 0 {
            names[k] = format!("{}_{}", names[k], repeats + 1);
        }
    }
    names
}

/// `m00 RMS 3.1 % · m_ij/m00 RMS 0.0123 · χ²/obs 4.2 (σ from the file's u_ columns) · max |r|
/// 12.3`.
pub fn validation_summary(v: &Validation) -> String {
    let sigma = &v.sigma_origin;
    format!(
        "{} rows: m00 relative RMS {:.2} % · m_ij/m00 RMS {:.4} · χ²/obs {:.3} ({sigma}) · max |r| {:.1}",
        v.rows,
        100.0 * v.m00_relative_rms(),
        v.rms_normalized_elements,
        v.chi2_per_observation,
        v.max_abs_residual
    )
}
