//! Several files of one material at one wavelength as one measurement set: repeat measurements
//! (docs/design.md §1.9), concatenated in the order given, with a note saying so. Files that cannot be one
//! set (another wavelength, other columns) are refused with a message naming both.

use std::path::PathBuf;

use super::{MeasurementSet, SourceFile, MUELLER_ELEMENT_NAMES};

/// Two wavelengths closer than this (µm) are one wavelength (docs/design.md §1.9).
pub const SAME_WAVELENGTH_UM: f64 = 1e-6;

/// Why two files of one material cannot be merged into one set.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{} and {} both hold material '{material}' but cannot be merged as repeat measurements: {reason}", crate::text::path(first), crate::text::path(second))]
pub struct MergeError {
    pub material: String,
    pub first: PathBuf,
    pub second: PathBuf,
    pub reason: String,
}

/// Merges `sets` (at least one, all of one material and wavelength) into one set: the first file's source,
/// hash, metadata and wavelength, every file's rows in the order given, the later files listed
/// in [`MeasurementSet::merged`], every file's notes plus one saying what was merged. One set is
/// returned as it is. Every file that reads is in the psps convention (the reader refuses any
/// other), so the convention cannot disagree; the wavelength, the Mueller elements and which of
/// them have `u_` columns must.
pub fn merge_repeat_measurements(
    mut sets: Vec<MeasurementSet>,
) -> Result<Option<MeasurementSet>, MergeError> {
    if sets.len() <= 1 {
        return Ok(sets.pop());
    }
    let mut rest = sets.split_off(1);
    let mut merged = sets.remove(0);
    let mut sources = vec![describe(&merged.source, merged.points.len())];
    for set in &mut rest {
        check_mergeable(&merged, set)?;
        sources.push(describe(&set.source, set.points.len()));
        merged.merged.push(SourceFile {
            path: set.source.clone(),
            sha256: set.sha256.clone(),
            rows: set.points.len(),
            data: set.source_data(0),
        });
        // Taken out, so that each file's columns are freed once copied.
        merged.points.append(&std::mem::take(&mut set.points));
        merged.notes.append(&mut set.notes);
    }
    let last = sources.pop().unwrap_or_default();
    merged.notes.push(format!(
        "{}: merged {} and {last} as repeat measurements",
        merged.material,
        sources.join(", ")
    ));
    Ok(Some(merged))
}

fn describe(path: &std::path::Path, rows: usize) -> String {
    format!(
        "{} ({})",
        crate::text::path(path),
        crate::text::counted(rows, "row")
    )
}

/// Refuses a set that cannot be concatenated with `first`.
fn check_mergeable(first: &MeasurementSet, other: &MeasurementSet) -> Result<(), MergeError> {
    let refuse = |reason: String| MergeError {
        material: first.material.clone(),
        first: first.source.clone(),
        second: other.source.clone(),
        reason,
    };
    if (first.wavelength_um - other.wavelength_um).abs() > SAME_WAVELENGTH_UM {
        return Err(refuse(format!(
            "their wavelengths differ ({} µm and {} µm): they are a spectral set (which `irpol \
             fit` reads as one material), not repeat measurements",
            first.wavelength_um, other.wavelength_um
        )));
    }
    if first.sha256 == other.sha256 {
        return Err(refuse(
            "they are the same bytes (equal SHA-256): the same file given twice".into(),
        ));
    }
    let columns = |set: &MeasurementSet| -> String {
        let first = set.points.first();
        set.elements
            .iter()
            .enumerate()
            .map(|(slot, &e)| {
                let name = MUELLER_ELEMENT_NAMES[e];
                match first.and_then(|p| p.uncertainty(slot)) {
                    Some(_) => format!("{name} u_{name}"),
                    None => name.to_owned(),
                }
            })
            .collect::<Vec<_>>()
            .join(" ")
    };
    let (a, b) = (columns(first), columns(other));
    if a != b {
        return Err(refuse(format!(
            "their Mueller columns differ ({a} against {b}); give both files the same columns"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::parse_measurement_csv;
    use std::path::Path;

    fn set(name: &str, text: &str) -> MeasurementSet {
        parse_measurement_csv(Path::new(name), text.as_bytes()).unwrap()
    }

    const HEADER: &str = "# material: paint\n# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n";

    #[test]
    fn repeat_files_are_concatenated_with_a_note() {
        let a = set("a.csv", &format!("{HEADER}30,30,0.5\n30,40,0.2\n"));
        let b = set("b.csv", &format!("{HEADER}30,-30,0.01\n"));
        let merged = merge_repeat_measurements(vec![a.clone(), b.clone()])
            .unwrap()
            .unwrap();
        assert_eq!(merged.points.len(), 3);
        assert_eq!(merged.points.row(2), b.points.row(0));
        assert_eq!(
            (merged.source.clone(), merged.sha256.clone()),
            (a.source, a.sha256)
        );
        assert_eq!(
            merged.merged,
            vec![SourceFile {
                path: "b.csv".into(),
                sha256: b.sha256.clone(),
                rows: 1,
                data: b.source_data(0),
            }]
        );
        assert_eq!(
            merged.notes,
            [
                "b.csv: 1 row with θ_r < 0 read as (|θ_r|, φ_r + 180°)",
                "paint: merged a.csv (2 rows) and b.csv (1 row) as repeat measurements"
            ]
        );
    }

    #[test]
    fn other_wavelengths_columns_or_the_same_file_are_refused() {
        let a = set("a.csv", &format!("{HEADER}30,30,0.5\n"));
        let far = set(
            "b.csv",
            &format!("{}30,30,0.5\n", HEADER.replace("10\n", "10.5\n")),
        );
        let message = merge_repeat_measurements(vec![a.clone(), far])
            .unwrap_err()
            .to_string();
        assert!(
            message.starts_with("a.csv and b.csv both hold material 'paint'")
                && message.contains("10 µm and 10.5 µm")
                && message.contains("a spectral set"),
            "{message}"
        );
        let near = set(
            "b.csv",
            &format!("{}30,30,0.5\n", HEADER.replace("10\n", "10.0000005\n")),
        );
        assert!(merge_repeat_measurements(vec![a.clone(), near]).is_ok());
        let columns = set(
            "b.csv",
            "# material: paint\n# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00,u_m00\n30,30,0.5,0.01\n",
        );
        let message = merge_repeat_measurements(vec![a.clone(), columns])
            .unwrap_err()
            .to_string();
        assert!(message.contains("(m00 against m00 u_m00)"), "{message}");
        let same = set("copy.csv", &format!("{HEADER}30,30,0.5\n"));
        assert!(merge_repeat_measurements(vec![a, same])
            .unwrap_err()
            .to_string()
            .contains("same bytes"));
    }
}
