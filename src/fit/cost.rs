//! What a fit will cost, estimated before any work starts, as a render's is (docs/design.md
//! §2.7): a fit is refused up front when its estimate exceeds a limit the user can raise
//! ([`FitOptions::max_minutes`], `fit --max-minutes`), with the estimate and its factors — rows,
//! the candidate models (sets of terms × slope laws), the cross-validation folds and, for a
//! spectral set, the coordinates of the joint problem — so that a table of thousands of
//! wavelengths is not started without a word.
//!
//! The model is a sum of measured costs (release build, two cores): every candidate fit costs
//! ≈ 0.05 ms a row and ≈ 17 ms a wavelength (its own search), each fold refit ≈ 10 % of that
//! (fitted to a table of 200 wavelengths × 51 rows, 35.7 s for six candidates in 5 folds, and
//! to the shipped glass, 9 wavelengths × 409 rows, 3.1 s); a joint spectral fit of P coordinates
//! solves a dense P × P system at each of its ≈ 30 Levenberg–Marquardt iterations (≈ 1e-8 P³ s
//! in all).
//! It is meant to within a factor of a few, enough to tell minutes from days.
//!
//! The joint coordinates are also bounded outright ([`MAX_JOINT_COORDINATES`]): the material
//! records their correlation matrix, which grows with their square.

use super::cross_validation::{candidates, DEFAULT_FOLDS};
use super::{FitError, FitOptions};
use crate::measure::MeasurementSet;
use crate::text::{about, counted, duration, number};

pub use super::options::DEFAULT_MAX_MINUTES;

/// The most coordinates (shared ones plus each wavelength's own) a joint spectral fit takes: its
/// correlation matrix, written into the material, has their square of entries (1e6 here, ≈ 25 MB
/// of TOML), and each iteration factors a dense matrix of that size.
pub const MAX_JOINT_COORDINATES: usize = 1000;

/// Seconds per row, and per wavelength, of a candidate fit.
const ROW_S: f64 = 5.0e-5;
const WAVELENGTH_S: f64 = 0.017;
/// Seconds per cubed joint coordinate (≈ 30 Cholesky factorizations of P³/3 flops at 1 GFLOP/s).
const JOINT_CUBE_S: f64 = 1.0e-8;
/// Coordinates of one wavelength in a joint table fit (n, k and a body reflectance).
const PER_WAVELENGTH_COORDINATES: usize = 3;
/// Shared coordinates of a joint fit (σ, q and a dispersion law's or a subsurface term's).
const SHARED_COORDINATES: usize = 6;
/// The cores the constants were measured on.
const MEASURED_CORES: f64 = 2.0;

/// A material's estimated fit cost and its factors.
#[derive(Clone, Debug, PartialEq)]
pub struct FitEstimate {
    pub rows: usize,
    pub wavelengths: usize,
    /// Candidate models fitted: sets of terms × slope laws.
    pub candidates: usize,
    /// Cross-validation folds each candidate is refitted on (0: none).
    pub folds: usize,
    /// Coordinates of the joint problem of a spectral set (0 for one wavelength).
    pub joint_coordinates: usize,
    /// Seconds on this machine.
    pub seconds: f64,
}

/// The estimate of fitting the measurement `sets` of one material (one set per wavelength).
pub fn estimate(sets: &[MeasurementSet], options: &FitOptions) -> FitEstimate {
    let rows: usize = sets.iter().map(|s| s.points.len()).sum();
    let laws = options.distributions().len();
    // The sets of terms the fit will score: `--terms auto` puts every admissible set in
    // `term_candidates` (less those without a parameter --free/--fix name).
    let terms = candidates(options).len();
    let folds = match options.cv_folds {
        Some(k) => k,
        None if options.choose_terms => DEFAULT_FOLDS,
        None => 0,
    };
    let joint_coordinates = match sets.len() {
        0 | 1 => 0,
        w => SHARED_COORDINATES + PER_WAVELENGTH_COORDINATES * w,
    };
    let cores = std::thread::available_parallelism().map_or(1.0, |n| n.get() as f64);
    // A fold refits from the whole data's optimum, a fraction of a fit; folds add ≈ 10 % each.
    let fold_factor = 1.0 + 0.1 * folds as f64;
    let one_candidate = rows as f64 * ROW_S + sets.len() as f64 * WAVELENGTH_S;
    let fitting = one_candidate * (laws * terms) as f64 * fold_factor;
    let joint = JOINT_CUBE_S * (joint_coordinates as f64).powi(3);
    FitEstimate {
        rows,
        wavelengths: sets.len(),
        candidates: laws * terms,
        folds,
        joint_coordinates,
        seconds: (fitting + joint) * MEASURED_CORES / cores,
    }
}

/// [`estimate`] of every material, refused when one is over `options.max_minutes` or has more
/// joint coordinates than [`MAX_JOINT_COORDINATES`], naming its file and the factors.
pub(super) fn check_costs(
    materials: &[Vec<MeasurementSet>],
    options: &FitOptions,
) -> Result<(), FitError> {
    let limit = options.max_minutes;
    if !(limit.is_finite() && limit > 0.0) {
        return Err(FitError::Options(format!(
            "--max-minutes {} must be a positive number of minutes",
            number(limit)
        )));
    }
    for sets in materials {
        let e = estimate(sets, options);
        let file = crate::text::path(&sets[0].source);
        if e.joint_coordinates > MAX_JOINT_COORDINATES {
            return Err(FitError::Cost(format!(
                "{file}: {} make a joint fit of {} coordinates, more than the {} irpol fits \
                 jointly (their correlation matrix, written into the material, grows with the \
                 square): resample the table to at most {} wavelengths, or fit bands of it as \
                 separate files",
                counted(e.wavelengths, "wavelength"),
                e.joint_coordinates,
                MAX_JOINT_COORDINATES,
                (MAX_JOINT_COORDINATES - SHARED_COORDINATES) / PER_WAVELENGTH_COORDINATES,
            )));
        }
        if e.seconds > limit * 60.0 {
            return Err(FitError::Cost(too_long(&file, &e, limit)));
        }
    }
    Ok(())
}

/// The refusal of a fit estimated over `limit` minutes.
fn too_long(file: &str, e: &FitEstimate, limit: f64) -> String {
    let folds = match e.folds {
        0 => String::new(),
        k => format!(" × (1 + {k} folds)"),
    };
    format!(
        "{file}: this fit is estimated at {} ({} rows × {} candidate models{folds}{}), more than \
         --max-minutes {}: give --max-minutes {} to fit it anyway, or fit fewer candidates \
         (--terms, --distribution), folds (--cv) or rows (--wavelength, --theta-i)",
        duration(e.seconds),
        e.rows,
        e.candidates,
        match e.joint_coordinates {
            0 => String::new(),
            p => format!(", a joint problem of {p} coordinates"),
        },
        number(limit),
        about((e.seconds / 60.0).ceil()),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The factors of the shipped silicate glass's default fit: 9 wavelengths, 6 candidates
    /// cross-validated in 5 folds, 33 joint coordinates; a few seconds, far under the limit.
    #[test]
    fn the_default_fit_counts_candidates_folds_and_joint_coordinates() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let sets =
            crate::measure::read_measurement_sets(&root.join("measurements/silicate_glass.csv"))
                .unwrap();
        let options = FitOptions {
            choose_terms: true,
            term_candidates: crate::pbrdf::ModelTerms::ALL.to_vec(),
            ..FitOptions::default()
        };
        let e = estimate(&sets, &options);
        assert_eq!((e.wavelengths, e.candidates, e.folds), (9, 6, 5));
        assert_eq!(e.joint_coordinates, 33);
        assert!(e.seconds > 0.5 && e.seconds < 60.0, "{e:?}");
    }
}
