//! Keeping part of a measurement file (docs/design.md §2.8): one wavelength of a file that holds
//! several, and the rows at chosen incidence angles, so that one file can be split into the
//! geometries a fit sees and those a validation predicts. A selection that matches nothing is
//! refused naming what the file holds, never silently empty.

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::MeasurementSet;
use crate::text::{counted, significant_trimmed};

/// A row is at a chosen θ_i when within this of it: instruments write angles rounded to 0.01°–0.1°,
/// and the grids worth selecting are whole degrees apart.
pub const THETA_I_TOLERANCE_DEG: f64 = 0.05;

/// A chosen wavelength is a file's when within this fraction of it: the digits a user types
/// (1.064) against the file's (1.0640).
const WAVELENGTH_RELATIVE_TOLERANCE: f64 = 1e-4;

/// Which rows of a measurement file to keep; the default keeps all. The fit records it
/// (`[fit.selection]`) so that `irpol report` rebuilds from the same rows.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RowSelection {
    /// Keep only the set at this wavelength, µm (the file must hold it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub wavelength_um: Option<f64>,
    /// Keep only rows whose θ_i is within [`THETA_I_TOLERANCE_DEG`] of one of these, degrees
    /// (each must match some row); empty keeps every θ_i.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub theta_i_deg: Vec<f64>,
}

/// Why a selection cannot be applied to a file.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SelectionError {
    #[error("selected wavelength {value}: {reason}")]
    BadWavelength { value: String, reason: &'static str },
    #[error("selected incidence angle {value}°: not a zenith angle in [0°, 90°)")]
    BadThetaI { value: String },
    #[error("{}: holds no rows at the selected wavelength {wanted} µm; it holds {present} µm: select one of those", crate::text::path(file))]
    WavelengthAbsent {
        file: PathBuf,
        wanted: String,
        present: String,
    },
    #[error("{}: no row has θ_i within {THETA_I_TOLERANCE_DEG}° of the selected {wanted}°; its rows have θ_i = {present}°: select among those", crate::text::path(file))]
    ThetaIAbsent {
        file: PathBuf,
        wanted: String,
        present: String,
    },
}

impl RowSelection {
    /// Keeps every row.
    pub fn is_everything(&self) -> bool {
        self.wavelength_um.is_none() && self.theta_i_deg.is_empty()
    }

    /// Refuses values that can select no row of any file (not finite, θ_i off the hemisphere).
    pub fn check(&self) -> Result<(), SelectionError> {
        if let Some(um) = self.wavelength_um {
            if !(um.is_finite() && um > 0.0) {
                return Err(SelectionError::BadWavelength {
                    value: crate::text::number(um),
                    reason: "not a positive number of micrometres",
                });
            }
        }
        match self
            .theta_i_deg
            .iter()
            .find(|t| !(t.is_finite() && (0.0..90.0).contains(*t)))
        {
            Some(t) => Err(SelectionError::BadThetaI {
                value: crate::text::number(*t),
            }),
            None => Ok(()),
        }
    }

    /// The sets of one file (as a reader returns them, one per wavelength) with only the selected
    /// rows, each set that lost rows noting it. Refuses a wavelength the file lacks and a θ_i no
    /// kept row has, naming what the file holds.
    pub fn apply(&self, sets: Vec<MeasurementSet>) -> Result<Vec<MeasurementSet>, SelectionError> {
        self.check()?;
        let Some(file) = sets.first().map(|s| s.source.clone()) else {
            return Ok(sets);
        };
        let sets = match self.wavelength_um {
            Some(um) => keep_wavelength(&file, sets, um)?,
            None => sets,
        };
        if self.theta_i_deg.is_empty() {
            return Ok(sets);
        }
        self.check_theta_present(&file, &sets)?;
        Ok(sets
            .into_iter()
            .map(|set| self.keep_theta(set))
            .filter(|set| !set.points.is_empty())
            .collect())
    }

    fn check_theta_present(
        &self,
        file: &Path,
        sets: &[MeasurementSet],
    ) -> Result<(), SelectionError> {
        let near = |wanted: f64, theta: f64| (theta - wanted).abs() <= THETA_I_TOLERANCE_DEG;
        let rows = || sets.iter().flat_map(|s| &s.points);
        for &wanted in &self.theta_i_deg {
            if !rows().any(|p| near(wanted, p.theta_i_deg)) {
                let mut present: Vec<f64> = Vec::new();
                for point in rows() {
                    if !present.iter().any(|&t| near(t, point.theta_i_deg)) {
                        present.push(point.theta_i_deg);
                    }
                }
                // To 0.1°, the tolerance's scale: -0.001 written for the normal reads as 0.
                present
                    .iter_mut()
                    .for_each(|t| *t = (*t * 10.0).round() / 10.0);
                present.sort_by(f64::total_cmp);
                return Err(SelectionError::ThetaIAbsent {
                    file: file.to_path_buf(),
                    wanted: short(wanted),
                    present: listed(&present),
                });
            }
        }
        Ok(())
    }

    fn keep_theta(&self, mut set: MeasurementSet) -> MeasurementSet {
        let before = set.points.len();
        set.points.retain(|p| {
            self.theta_i_deg
                .iter()
                .any(|&t| (p.theta_i_deg - t).abs() <= THETA_I_TOLERANCE_DEG)
        });
        set.notes.push(format!(
            "{} at {} µm: kept {} of {} with θ_i = {}°",
            set.source.display(),
            short(set.wavelength_um),
            counted(set.points.len(), "row"),
            before,
            listed(&self.theta_i_deg)
        ));
        set
    }
}

/// The one set of `sets` at `um` (with the file's notes, which every set carries).
fn keep_wavelength(
    file: &Path,
    sets: Vec<MeasurementSet>,
    um: f64,
) -> Result<Vec<MeasurementSet>, SelectionError> {
    let same = |w: f64| (w - um).abs() <= WAVELENGTH_RELATIVE_TOLERANCE * um;
    let total = sets.len();
    let present: Vec<f64> = sets.iter().map(|s| s.wavelength_um).collect();
    let Some(mut set) = sets.into_iter().find(|s| same(s.wavelength_um)) else {
        return Err(SelectionError::WavelengthAbsent {
            file: file.to_path_buf(),
            wanted: short(um),
            present: listed(&present),
        });
    };
    if total > 1 {
        set.notes.push(format!(
            "{}: kept the rows at {} µm, one of its {total} wavelengths",
            crate::text::path(file),
            short(set.wavelength_um)
        ));
    }
    Ok(vec![set])
}

/// `value` to 6 significant digits without trailing zeros (75, 1.064, 1e-300).
fn short(value: f64) -> String {
    significant_trimmed(value, 6)
}

fn listed(values: &[f64]) -> String {
    values
        .iter()
        .map(|&v| short(v))
        .collect::<Vec<_>>()
        .join(", ")
}
