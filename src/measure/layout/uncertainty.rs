//! Uncertainties of a table that has none (docs/design.md §2.8, `[uncertainty] model`).
//!
//! `estimate` takes them from the data's own scatter, as a fraction of each row's m00 per
//! element (a polarimeter's error scales with the signal, as the fit's fixed rule assumes):
//! - **mirror pairs**: an isotropic sample scatters the same into relative azimuths Δ and −Δ
//!   (Δ = φ_r − φ_i − 180°), with m02, m03, m12, m13, m20, m21, m30, m31 changing sign (the mirror
//!   through the plane of incidence is diag(1, 1, −1, −1) on both sides). The difference of a
//!   pair is noise alone.
//! - otherwise **smoothness along θ_r**: the residual of each row from the line through its
//!   neighbours in a scan of θ_r at fixed incidence and azimuth (an overestimate where the BRDF
//!   curves, so it is the second choice).
//!
//! Both use the median absolute value (scaled to a Gaussian σ), so a few outliers or a true
//! anisotropy near the specular peak do not set the weights of the whole file. A floor keeps
//! any weight finite. `fixed` records none: the fit's 3 % / 1 % of m00 rule applies.

use std::collections::HashMap;

use super::UncertaintyModel;
use crate::measure::{MeasurementRow, MeasurementRows};

/// Fewest mirror pairs or θ_r triples an estimate is made from.
const MIN_SAMPLES: usize = 8;
/// Smallest estimated 1-σ, relative to the row's m00: 0.1 %, below any goniometer's repeatability.
const RELATIVE_FLOOR: f64 = 1e-3;
/// Smallest 1-σ relative to the set's largest m00, as the fit's default model (a row with
/// m00 = 0 gets a finite weight).
const ABSOLUTE_FLOOR: f64 = 1e-6;
/// Median |x| of a zero-mean Gaussian over its σ.
const MEDIAN_ABS_PER_SIGMA: f64 = 0.674_489_750_196_081_7;
/// Angles equal within 0.001° are the same geometry.
const ANGLE_KEY_PER_DEGREE: f64 = 1000.0;

/// Which model applied to a set, for its metadata and the note the user reads.
pub(super) struct Applied {
    pub label: String,
    pub note: String,
}

/// Sets the uncertainties of `points` (whose values follow `elements`) under `model`.
pub(super) fn apply_uncertainty_model(
    model: UncertaintyModel,
    points: &mut MeasurementRows,
    elements: &[usize],
) -> Applied {
    let estimated = match model {
        UncertaintyModel::Fixed => None,
        UncertaintyModel::Estimate => mirror_scatter(points, elements)
            .map(|s| (s, "mirror pairs"))
            .or_else(|| smoothness_scatter(points).map(|s| (s, "smoothness along θ_r"))),
    };
    let Some((scatter, method)) = estimated else {
        let why = match model {
            UncertaintyModel::Fixed => "the layout's uncertainty model is \"fixed\"",
            UncertaintyModel::Estimate => {
                "too few mirror pairs or θ_r scans to estimate them from the data"
            }
        };
        return Applied {
            label: "fixed".to_string(),
            note: format!(
                "no uncertainty columns and {why}: the fit's fixed 3 % of m00 on m00 and 1 % of \
                 m00 on the other elements applies"
            ),
        };
    };
    let relative: Vec<f64> = scatter
        .relative
        .iter()
        .map(|r| r.max(RELATIVE_FLOOR))
        .collect();
    let m00_max = points.iter().map(|p| p.values[0]).fold(0.0, f64::max);
    let floor = ABSOLUTE_FLOOR * m00_max.max(f64::MIN_POSITIVE);
    points.set_uncertainties(|point| {
        let m00 = point.values[0];
        relative.iter().map(|r| (r * m00).max(floor)).collect()
    });
    Applied {
        label: format!("estimate ({method})"),
        note: estimate_note(&relative, method, scatter.samples),
    }
}

fn estimate_note(relative: &[f64], method: &str, samples: usize) -> String {
    let percent = |r: f64| format!("{:.2} %", 100.0 * r);
    let others = &relative[1..];
    let spread = match (
        others.iter().copied().reduce(f64::min),
        others.iter().copied().reduce(f64::max),
    ) {
        (Some(low), Some(high)) => format!(
            ", of the other elements {}–{} of m00",
            percent(low),
            percent(high)
        ),
        _ => String::new(),
    };
    let source = match method {
        "mirror pairs" => format!("{samples} mirror pairs (Δφ ↔ −Δφ of an isotropic sample)"),
        _ => format!("{samples} rows' residuals from their θ_r neighbours"),
    };
    format!(
        "no uncertainty columns: 1-σ estimated from {source}: m00 {} of m00{spread} \
         (floor {})",
        percent(relative[0]),
        percent(RELATIVE_FLOOR)
    )
}

/// Each element's relative 1-σ and how many samples it came from.
struct Scatter {
    relative: Vec<f64>,
    samples: usize,
}

fn angle_key(degrees: f64) -> i64 {
    (degrees * ANGLE_KEY_PER_DEGREE).round() as i64
}

/// The relative azimuth Δ = φ_r − φ_i − 180° in [0°, 360°).
fn relative_azimuth(point: MeasurementRow<'_>) -> f64 {
    (point.phi_r_deg - point.phi_i_deg - 180.0).rem_euclid(360.0)
}

/// Whether element `index` changes sign under the mirror through the plane of incidence.
fn mirror_odd(index: usize) -> bool {
    (index / 4 >= 2) != (index % 4 >= 2)
}

fn mirror_scatter(points: &MeasurementRows, elements: &[usize]) -> Option<Scatter> {
    let full_turn = angle_key(360.0);
    let key = |p: MeasurementRow<'_>, azimuth_key: i64| {
        (
            angle_key(p.theta_i_deg),
            angle_key(p.phi_i_deg.rem_euclid(360.0)),
            angle_key(p.theta_r_deg),
            azimuth_key.rem_euclid(full_turn),
        )
    };
    let mut by_geometry = HashMap::new();
    for (index, point) in points.iter().enumerate() {
        by_geometry
            .entry(key(point, angle_key(relative_azimuth(point))))
            .or_insert(index);
    }
    let mut differences = vec![Vec::new(); elements.len()];
    let mut pairs = 0;
    for point in points {
        let azimuth = angle_key(relative_azimuth(point)).rem_euclid(full_turn);
        let mirrored = (full_turn - azimuth).rem_euclid(full_turn);
        // Each pair once; in-plane rows (Δ = 0° or 180°) are their own mirror.
        if mirrored <= azimuth {
            continue;
        }
        let Some(&other) = by_geometry.get(&key(point, mirrored)) else {
            continue;
        };
        let other = points.row(other);
        let mean_m00 = 0.5 * (point.values[0] + other.values[0]);
        if mean_m00 <= 0.0 {
            continue;
        }
        pairs += 1;
        for (slot, &index) in elements.iter().enumerate() {
            let sign = if mirror_odd(index) { -1.0 } else { 1.0 };
            let difference = point.values[slot] - sign * other.values[slot];
            // Two independent errors: the difference has √2 times one row's σ.
            differences[slot].push(difference.abs() / (mean_m00 * std::f64::consts::SQRT_2));
        }
    }
    (pairs >= MIN_SAMPLES).then(|| Scatter {
        relative: differences.iter_mut().map(|d| robust_sigma(d)).collect(),
        samples: pairs,
    })
}

fn smoothness_scatter(points: &MeasurementRows) -> Option<Scatter> {
    let mut scans: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
    for (index, p) in points.iter().enumerate() {
        let scan = (
            angle_key(p.theta_i_deg),
            angle_key(p.phi_i_deg.rem_euclid(360.0)),
            angle_key(p.phi_r_deg.rem_euclid(360.0)),
        );
        scans.entry(scan).or_default().push(index);
    }
    let width = points.first()?.values.len();
    let mut residuals = vec![Vec::new(); width];
    let mut triples = 0;
    for scan in scans.values_mut() {
        scan.sort_by(|&a, &b| {
            let theta_r = |i: usize| points.row(i).theta_r_deg;
            theta_r(a).total_cmp(&theta_r(b))
        });
        for window in scan.windows(3) {
            let [a, b, c] = [window[0], window[1], window[2]].map(|i| points.row(i));
            let span = c.theta_r_deg - a.theta_r_deg;
            if !(span > 0.0 && b.values[0] > 0.0) {
                continue;
            }
            let w = (b.theta_r_deg - a.theta_r_deg) / span;
            // The residual's variance is σ²(1 + (1 − w)² + w²) for equal σ on the three rows.
            let scale = b.values[0] * (1.0 + (1.0 - w).powi(2) + w * w).sqrt();
            triples += 1;
            for (slot, slot_residuals) in residuals.iter_mut().enumerate() {
                let line = (1.0 - w) * a.values[slot] + w * c.values[slot];
                slot_residuals.push((b.values[slot] - line).abs() / scale);
            }
        }
    }
    (triples >= MIN_SAMPLES).then(|| Scatter {
        relative: residuals.iter_mut().map(|r| robust_sigma(r)).collect(),
        samples: triples,
    })
}

/// σ of zero-mean Gaussian samples from the median of their absolute values.
fn robust_sigma(absolute: &mut [f64]) -> f64 {
    absolute.sort_by(f64::total_cmp);
    let n = absolute.len();
    let median = if n % 2 == 1 {
        absolute[n / 2]
    } else {
        0.5 * (absolute[n / 2 - 1] + absolute[n / 2])
    };
    median / MEDIAN_ABS_PER_SIGMA
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measure::MeasurementPoint;

    fn point(theta_r: f64, phi_r: f64, values: Vec<f64>) -> MeasurementPoint {
        MeasurementPoint {
            theta_i_deg: 30.0,
            phi_i_deg: 0.0,
            theta_r_deg: theta_r,
            phi_r_deg: phi_r,
            uncertainties: vec![None; values.len()],
            values,
            line: 0,
        }
    }

    #[test]
    fn mirror_pairs_see_only_the_difference_and_odd_elements_flip() {
        // m00 and m02 (odd): pairs at Δ = ±40° with m02 of opposite sign are noise-free except
        // for m00, which differs by 2 % between the two rows of every pair.
        let mut pairs = Vec::new();
        for k in 0..10 {
            let theta = 10.0 + k as f64;
            pairs.push(point(theta, 220.0, vec![1.01, 0.3]));
            pairs.push(point(theta, 140.0, vec![0.99, -0.3]));
        }
        let mut points: MeasurementRows = pairs.into_iter().collect();
        let scatter = mirror_scatter(&points, &[0, 2]).unwrap();
        assert_eq!(scatter.samples, 10);
        let expected = 0.02 / std::f64::consts::SQRT_2 / MEDIAN_ABS_PER_SIGMA;
        assert!((scatter.relative[0] - expected).abs() < 1e-12);
        assert_eq!(scatter.relative[1], 0.0);

        let applied = apply_uncertainty_model(UncertaintyModel::Estimate, &mut points, &[0, 2]);
        assert_eq!(applied.label, "estimate (mirror pairs)");
        // The zero scatter of m02 is raised to the floor.
        assert_eq!(points.row(0).uncertainty(1), Some(RELATIVE_FLOOR * 1.01));
    }

    #[test]
    fn without_pairs_a_smooth_scan_falls_back_to_neighbours_then_to_the_fixed_rule() {
        let line: MeasurementRows = (0..12)
            .map(|k| point(5.0 * k as f64, 180.0, vec![1.0 + 0.01 * k as f64]))
            .collect();
        let scatter = smoothness_scatter(&line).unwrap();
        assert_eq!(scatter.samples, 10);
        assert!(scatter.relative[0] < 1e-12);
        let mut few = line.select(&[0, 1, 2, 3]);
        let applied = apply_uncertainty_model(UncertaintyModel::Estimate, &mut few, &[0]);
        assert_eq!(applied.label, "fixed");
        assert!(few.iter().all(|p| p.uncertainty(0).is_none()));
    }
}
