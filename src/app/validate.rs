//! `irpol validate MATERIAL.toml DATA...` (docs/design.md §4): how a material's model predicts
//! measurements it was not fitted to — one summary line per measurement set, and a report page
//! each (`<reports>/<material>_validation_<data>.png`), written atomically.

use super::{material_pbrdf, AppError};
use crate::atomic::OutputSet;
use crate::fit::{validate_model, Validation};
use crate::material::Material;
use crate::measure::{collect_measurement_files, MeasurementSet, ReadOptions};
use crate::report::fit_report::{encode_validation_report, validation_data_name};
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
    let material = Material::load(material)?;
    let mut sets = Vec::new();
    for file in collect_measurement_files(inputs)? {
        sets.extend(reading.read(&file)?);
    }
    validate_sets(&material, sets, reports_dir)
}

/// [`validate_and_report`] of sets already read (a layout or a row selection applied).
pub fn validate_sets(
    material: &Material,
    sets: Vec<MeasurementSet>,
    reports_dir: &Path,
) -> Result<Vec<SetValidation>, AppError> {
    if sets.is_empty() {
        return Err(AppError::invalid("no measurement to validate against"));
    }
    let mut outputs = OutputSet::new();
    let mut results = Vec::new();
    let sets_of = |source: &Path| sets.iter().filter(|s| s.source == source).count();
    let counts: Vec<usize> = sets.iter().map(|s| sets_of(&s.source)).collect();
    for (set, count) in sets.into_iter().zip(counts) {
        let wavelength = material.model.spectral().map(|_| set.wavelength_um);
        let model = material_pbrdf(material, wavelength, None)?;
        let validation = validate_model(&model, &set)?;
        let report = encode_validation_report(
            material,
            &set,
            &validation_summary(&validation),
            reports_dir,
            &validation_data_name(&set, count),
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

/// `m00 RMS 3.1 % · m_ij/m00 RMS 0.0123 · χ²/obs 4.2 (σ from the file) · max |r| 12.3`.
pub fn validation_summary(v: &Validation) -> String {
    let sigma = if v.uncertainties_from_file {
        "σ from the file"
    } else {
        "σ partly from the default noise model"
    };
    format!(
        "{} rows: m00 relative RMS {:.2} % · m_ij/m00 RMS {:.4} · χ²/obs {:.3} ({sigma}) · max |r| {:.1}",
        v.rows,
        100.0 * v.m00_relative_rms(),
        v.rms_normalized_elements,
        v.chi2_per_observation,
        v.max_abs_residual
    )
}
