//! Where a fit's source measurements are and whether they still hold the data that was fitted:
//! `irpol report` rebuilds a report from them, the library index checks them.

use super::super::ReportError;
use super::write_fit_report;
use crate::fit::FitError;
use crate::material::{FitRecord, Material};
use crate::measure::{
    file_sha256, hex, merge_repeat_measurements, parse_measurement_csv, read_bytes, Layout,
    MeasurementSet, ReadOptions, SourceData, LAYOUT_KEY,
};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// Rebuilds the report of a library entry from its recorded source CSVs (`irpol report
/// <material.toml>`; several when the fit merged repeat measurements), refusing when the
/// material has no fit, a CSV is gone or changed since the fit, or no longer reads.
pub fn rebuild_report(
    material_path: &Path,
    reports_dir: &Path,
) -> Result<Vec<PathBuf>, ReportError> {
    let material = Material::load(material_path)?;
    let fit = material.fit.as_ref().ok_or_else(|| ReportError::NoFit {
        material: material_path.to_owned(),
    })?;
    // A spectral report shows the joint fit's per-wavelength state, which the entry does not
    // hold: `irpol fit` (deterministic) writes it.
    if material.model.spectral().is_some() {
        return Err(ReportError::SpectralRebuild {
            material: material_path.to_owned(),
            csv: fit.source.clone(),
        });
    }
    let sets = verified_source(material_path, fit)?;
    let set = merge_repeat_measurements(sets)
        .map_err(crate::fit::FitError::from)?
        .ok_or_else(|| ReportError::NoFit {
            material: material_path.to_owned(),
        })?;
    write_fit_report(&material, &set, reports_dir)
}

/// Where the fit's source CSV may be: as recorded (relative to the working directory, where
/// `irpol fit` was run), then relative to the library's parent folder (`fits/x.toml` →
/// `<project>/…`), so that a project can be rebuilt from another directory.
fn source_candidates(material_path: &Path, source: &Path) -> Vec<PathBuf> {
    let mut candidates = vec![source.to_owned()];
    if source.is_relative() {
        if let Some(project) = material_path.parent().and_then(Path::parent) {
            let beside = project.join(source);
            if !candidates.contains(&beside) {
                candidates.push(beside);
            }
        }
    }
    candidates
}

/// Finds each of the fit's source CSVs (the source, then any merged with it) and checks it holds
/// the data that was fitted; returns each one's parsed data, in that order, read as the fit read
/// it (through the recorded layout, the recorded rows only).
fn verified_source(
    material_path: &Path,
    fit: &FitRecord,
) -> Result<Vec<MeasurementSet>, ReportError> {
    let reading = recorded_reading(material_path, fit)?;
    let one_set = |csv: &Path, bytes: &[u8]| parse_source(csv, bytes, &reading).map(|s| vec![s]);
    Ok(verified_files(material_path, fit, Wanted::Sets, one_set)?
        .into_iter()
        .flatten()
        .collect())
}

/// Whether each of the fit's source files still holds the data that was fitted (the library
/// index's check), each read as the fit read it (a spectral material's files may hold several
/// wavelengths each), except that a file of the very bytes fitted is not read again: a dense
/// scan is hundreds of megabytes of text and rows, which `irpol fit` would otherwise hold
/// beside the fit it just made.
pub(crate) fn source_unchanged(
    material_path: &Path,
    fit: &FitRecord,
    spectral: bool,
) -> Result<(), ReportError> {
    let reading = recorded_reading(material_path, fit)?;
    let parse = |csv: &Path, bytes: &[u8]| -> Result<Vec<MeasurementSet>, ReportError> {
        if spectral {
            Ok(reading.parse(csv, bytes).map_err(FitError::from)?)
        } else {
            parse_source(csv, bytes, &reading).map(|s| vec![s])
        }
    };
    verified_files(material_path, fit, Wanted::Verdict, parse).map(|_| ())
}

/// What a check of the sources returns: the sets read from them, or only whether they hold
/// the fitted data.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Wanted {
    Sets,
    Verdict,
}

/// How the fit read its files: the recorded layout and row selection.
fn recorded_reading(material_path: &Path, fit: &FitRecord) -> Result<ReadOptions, ReportError> {
    Ok(ReadOptions {
        layout: recorded_layout(material_path, fit)?,
        selection: fit.selection.clone().unwrap_or_default(),
        angles: fit.angles.unwrap_or_default(),
    })
}

/// Each of the fit's source files checked by [`verified_file`], read with `parse`.
fn verified_files(
    material_path: &Path,
    fit: &FitRecord,
    wanted: Wanted,
    parse: impl Fn(&Path, &[u8]) -> Result<Vec<MeasurementSet>, ReportError>,
) -> Result<Vec<Vec<MeasurementSet>>, ReportError> {
    std::iter::once((&fit.source, &fit.source_sha256, &fit.source_data))
        .chain(
            fit.merged_sources
                .iter()
                .map(|m| (&m.source, &m.source_sha256, &m.source_data)),
        )
        .map(|(source, sha256, data)| {
            verified_file(material_path, source, sha256, data.as_ref(), wanted, &parse)
        })
        .collect()
}

/// The layout the fit was given, found where its sources are looked for.
fn recorded_layout(material_path: &Path, fit: &FitRecord) -> Result<Option<Layout>, ReportError> {
    let Some(layout) = &fit.layout else {
        return Ok(None);
    };
    let candidates = source_candidates(material_path, layout);
    match candidates.iter().find(|p| p.is_file()) {
        Some(path) => Ok(Some(Layout::read(path)?)),
        None => Err(ReportError::LayoutMissing {
            material: material_path.to_owned(),
            layout: layout.clone(),
            tried: candidates
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        }),
    }
}

/// The one set a source holds once read as the fit read it; a file of several wavelengths
/// without a recorded wavelength is refused by the one-wavelength reader's own message when it
/// is a docs/design.md §2.1 file.
fn parse_source(
    csv: &Path,
    bytes: &[u8],
    reading: &ReadOptions,
) -> Result<MeasurementSet, ReportError> {
    let mut sets = reading.parse(csv, bytes).map_err(FitError::from)?;
    if sets.len() == 1 {
        return Ok(sets.remove(0));
    }
    if reading.layout.is_none() && !sets.iter().any(|s| s.metadata.contains_key(LAYOUT_KEY)) {
        parse_measurement_csv(csv, bytes)?;
    }
    let wavelengths: Vec<String> = sets.iter().map(|s| s.wavelength_um.to_string()).collect();
    Err(FitError::Measurement {
        file: csv.to_owned(),
        message: format!(
            "holds {} wavelengths ({} µm) and the fit record selects none of them",
            sets.len(),
            wavelengths.join(", ")
        ),
    }
    .into())
}

/// One source CSV, checked against its recorded hash and data fingerprint. The bytes may differ
/// (a comment, blank lines, number spelling) when the record has the data's fingerprint and the
/// parsed data match it; a record without one (written before fingerprints, or by a spectral
/// fit) needs the very bytes. Of several candidates the first that matches wins (a same-named
/// file elsewhere is not the source); if none does, the first existing one is reported changed.
fn verified_file(
    material_path: &Path,
    source: &Path,
    recorded_sha256: &str,
    recorded_data: Option<&SourceData>,
    wanted: Wanted,
    parse: &impl Fn(&Path, &[u8]) -> Result<Vec<MeasurementSet>, ReportError>,
) -> Result<Vec<MeasurementSet>, ReportError> {
    let candidates = source_candidates(material_path, source);
    let mut first_changed = None;
    for csv in candidates.iter().filter(|p| p.is_file()) {
        let recorded_bytes = |sha256: String| sha256.eq_ignore_ascii_case(recorded_sha256.trim());
        // The verdict on the very bytes needs only their hash: `irpol fit` asks it of a file it
        // has just parsed, and must not hold a second copy of it (83 MB for a 2e5-row scan).
        if wanted == Wanted::Verdict && recorded_bytes(file_sha256(csv)?) {
            return Ok(Vec::new());
        }
        let bytes = read_bytes(csv)?;
        let same_bytes = recorded_bytes(hex(&Sha256::digest(&bytes)));
        let error = match (recorded_data, same_bytes) {
            (_, true) => return parse(csv, &bytes),
            (Some(recorded), false) => {
                let sets = parse(csv, &bytes)?;
                // A fingerprint is recorded for a file of one wavelength only: of several sets
                // (a hand-edited record) only the very bytes would do.
                let [set] = sets.as_slice() else {
                    first_changed.get_or_insert(ReportError::SourceChanged {
                        csv: csv.clone(),
                        recorded: recorded_sha256.to_owned(),
                        material: material_path.to_owned(),
                    });
                    continue;
                };
                let now = set.source_data(recorded.rows_per_digest);
                if now.sha256 == recorded.sha256 {
                    return Ok(sets);
                }
                ReportError::SourceDataChanged {
                    csv: csv.clone(),
                    what: recorded.describe_change(&now),
                    material: material_path.to_owned(),
                }
            }
            (None, false) => ReportError::SourceChanged {
                csv: csv.clone(),
                recorded: recorded_sha256.to_owned(),
                material: material_path.to_owned(),
            },
        };
        first_changed.get_or_insert(error);
    }
    Err(first_changed.unwrap_or_else(|| ReportError::SourceMissing {
        material: material_path.to_owned(),
        csv: source.to_owned(),
        tried: candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_source_is_looked_for_as_recorded_then_beside_the_library() {
        let fits = Path::new("/project/fits/paint.toml");
        assert_eq!(
            source_candidates(fits, Path::new("measurements/paint.csv")),
            [
                PathBuf::from("measurements/paint.csv"),
                PathBuf::from("/project/measurements/paint.csv")
            ]
        );
        assert_eq!(
            source_candidates(fits, Path::new("/data/paint.csv")),
            [PathBuf::from("/data/paint.csv")]
        );
        // fits/paint.toml relative to the working directory: both readings coincide.
        assert_eq!(
            source_candidates(Path::new("fits/paint.toml"), Path::new("m/p.csv")),
            [PathBuf::from("m/p.csv")]
        );
    }
}
