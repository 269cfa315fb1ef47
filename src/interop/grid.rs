//! A `.pbsdf` grid that follows the material (docs/design.md §2.10): along each axis the nodes
//! are spaced so that linear interpolation between them stays within a tolerance, given the
//! material's own curvature there. Linear interpolation over a step h errs by about
//! h² |f''| / 8; with a monitor μ(x) = max(|f''|/(f·ε_rel) for m00, |r''|/ε_ratio for each
//! r = m_ij/m00), nodes placed at equal steps of ∫ √(μ/8) dx make every step's error about the
//! tolerance (equidistribution). The facet lobe (narrow for small σ, heavy-tailed for small q)
//! puts nodes in θ_h where it turns, Fresnel near grazing puts them in θ_d: both come from the
//! model itself, sampled on fine lines through the table's domain, so no rule per parameter is
//! needed and a term added to the model later is followed too.

use super::pbsdf::PbsdfGrid;
use super::tabulate::table_value;
use crate::pbrdf::Pbrdf;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// Relative m00 error and absolute m_ij/m00 error allowed per axis, per interpolation step.
/// Chosen (with [`MIN_NODES`]) so that every shipped material meets the bars of
/// docs/design.md §2.10 (median 1 %, 95th percentile 5 % of m00; 0.01 in m_ij/m00).
pub const M00_TOLERANCE: f64 = 0.015;
pub const RATIO_TOLERANCE: f64 = 0.004;

/// Fewest nodes per axis, and most (Mitsuba's tables have no limit; 1024 keeps a table of one
/// material below a few GB).
pub const MIN_NODES: usize = 9;
pub const MAX_NODES: usize = 1024;

/// Fine samples per axis on which the monitor is measured.
const FINE: usize = 1441;

/// Directions with a cosine below this are outside the domain the grid is made for (the bars
/// are checked at cosines ≥ 0.2; the margin keeps the last cell before it resolved).
const MIN_COSINE: f64 = 0.15;

/// The three axes, in the table's order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    PhiD,
    ThetaD,
    ThetaH,
}

impl Axis {
    pub fn range(self) -> (f64, f64) {
        match self {
            Axis::PhiD => (-PI, PI),
            Axis::ThetaD | Axis::ThetaH => (0.0, FRAC_PI_2),
        }
    }
}

/// Values at which the other two axes are held while one is sampled.
const THETA_SLICES: [f64; 9] = [0.0, 0.02, 0.06, 0.15, 0.3, 0.5, 0.75, 1.0, 1.25];
const PHI_SLICES: [f64; 5] = [0.0, 0.8, 1.6, 2.4, PI];

/// The grid for `models` (one per wavelength): node counts from the tolerances, or `counts`
/// (N_φd, N_θd, N_θh) when given, with the spacing following the material either way.
pub fn material_grid(models: &[Pbrdf], counts: Option<[usize; 3]>) -> PbsdfGrid {
    let axis = |axis: Axis, count: Option<usize>| {
        let density = monitor_density(models, axis);
        nodes_from_density(&density, axis.range(), count)
    };
    PbsdfGrid {
        phi_d: axis(Axis::PhiD, counts.map(|c| c[0])),
        theta_d: axis(Axis::ThetaD, counts.map(|c| c[1])),
        theta_h: axis(Axis::ThetaH, counts.map(|c| c[2])),
    }
}

/// (θ_h, θ_d, φ_d) of fine sample `x` of `axis` on the slice (a, b) of the other two axes.
fn angles(axis: Axis, x: f64, a: f64, b: f64) -> (f64, f64, f64) {
    match axis {
        Axis::ThetaH => (x, a, b),
        Axis::ThetaD => (a, x, b),
        Axis::PhiD => (a, b, x),
    }
}

/// √(μ/8) on the fine samples of `axis`: the largest over slices and models, spread over ±2
/// samples so that a feature between two slices is not missed by a hair.
fn monitor_density(models: &[Pbrdf], axis: Axis) -> Vec<f64> {
    let (lo, hi) = axis.range();
    let step = (hi - lo) / (FINE - 1) as f64;
    let xs: Vec<f64> = (0..FINE).map(|i| lo + step * i as f64).collect();
    let slices: Vec<(f64, f64)> = match axis {
        Axis::PhiD => THETA_SLICES
            .iter()
            .flat_map(|&a| THETA_SLICES.iter().map(move |&b| (a, b)))
            .collect(),
        _ => THETA_SLICES
            .iter()
            .flat_map(|&a| PHI_SLICES.iter().map(move |&b| (a, b)))
            .collect(),
    };
    let mu = slices
        .par_iter()
        .map(|&(a, b)| slice_monitor(models, axis, &xs, a, b, step))
        .reduce(
            || vec![0.0; FINE],
            |m, n| m.iter().zip(&n).map(|(x, y)| x.max(*y)).collect(),
        );
    (0..FINE)
        .map(|i| {
            let window = &mu[i.saturating_sub(2)..(i + 3).min(FINE)];
            (window.iter().cloned().fold(0.0, f64::max) / 8.0).sqrt()
        })
        .collect()
}

/// μ along one fine line (0 where the line leaves the domain).
fn slice_monitor(models: &[Pbrdf], axis: Axis, xs: &[f64], a: f64, b: f64, step: f64) -> Vec<f64> {
    let mut mu = vec![0.0; xs.len()];
    for model in models {
        let values: Vec<Option<nalgebra::Matrix4<f64>>> = xs
            .iter()
            .map(|&x| {
                let (th, td, pd) = angles(axis, x, a, b);
                in_domain(th, td, pd).then(|| table_value(model, th, td, pd))
            })
            .collect();
        for i in 1..xs.len() - 1 {
            let (Some(l), Some(c), Some(r)) = (values[i - 1], values[i], values[i + 1]) else {
                continue;
            };
            if !(l[(0, 0)] > 0.0 && c[(0, 0)] > 0.0 && r[(0, 0)] > 0.0) {
                continue;
            }
            let second = |f: &dyn Fn(&nalgebra::Matrix4<f64>) -> f64| {
                (f(&l) - 2.0 * f(&c) + f(&r)).abs() / (step * step)
            };
            let m00 = second(&|m| m[(0, 0)]) / (c[(0, 0)] * M00_TOLERANCE);
            let ratio = (1..16)
                .map(|k| second(&|m| m[(k / 4, k % 4)] / m[(0, 0)]))
                .fold(0.0, f64::max)
                / RATIO_TOLERANCE;
            mu[i] = f64::max(mu[i], m00.max(ratio));
        }
    }
    mu
}

/// Both directions of the angles have cosines of at least [`MIN_COSINE`].
fn in_domain(theta_h: f64, theta_d: f64, phi_d: f64) -> bool {
    let (light, view) = super::convention::node_directions(theta_h, theta_d, phi_d);
    light.z >= MIN_COSINE && view.z >= MIN_COSINE
}

/// Nodes over `range` at equal steps of ∫ (density + floor) dx, the floor giving
/// [`MIN_NODES`] nodes on a featureless axis; `count` nodes when given, else as many as the
/// integral asks (at least [`MIN_NODES`], at most [`MAX_NODES`]). The end nodes are the range's.
fn nodes_from_density(density: &[f64], (lo, hi): (f64, f64), count: Option<usize>) -> Vec<f64> {
    let step = (hi - lo) / (density.len() - 1) as f64;
    let floor = (MIN_NODES - 1) as f64 / (hi - lo);
    let max_density = 1.0 / (2.0 * step);
    let mut cumulative = vec![0.0; density.len()];
    for i in 1..density.len() {
        let mean = 0.5 * (density[i - 1].min(max_density) + density[i].min(max_density));
        cumulative[i] = cumulative[i - 1] + (mean + floor) * step;
    }
    let total = cumulative[density.len() - 1];
    let count = count
        .unwrap_or_else(|| ((total - 1e-9).ceil() as usize + 1).clamp(MIN_NODES, MAX_NODES))
        .max(2);
    let mut nodes: Vec<f64> = (0..count)
        .map(|k| {
            let target = total * k as f64 / (count - 1) as f64;
            let i = cumulative
                .partition_point(|&c| c < target)
                .clamp(1, density.len() - 1);
            let span = cumulative[i] - cumulative[i - 1];
            let f = if span > 0.0 {
                (target - cumulative[i - 1]) / span
            } else {
                0.0
            };
            lo + step * ((i - 1) as f64 + f)
        })
        .collect();
    nodes[0] = lo;
    nodes[count - 1] = hi;
    nodes
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_flat_density_gives_uniform_nodes_and_a_peak_draws_them() {
        let flat = vec![0.0; 101];
        let nodes = nodes_from_density(&flat, (0.0, 1.0), None);
        assert_eq!(nodes.len(), MIN_NODES);
        for (k, n) in nodes.iter().enumerate() {
            assert!((n - k as f64 / (MIN_NODES - 1) as f64).abs() < 1e-12);
        }
        let peaked: Vec<f64> = (0..101).map(|i| if i < 10 { 100.0 } else { 0.0 }).collect();
        let nodes = nodes_from_density(&peaked, (0.0, 1.0), Some(20));
        assert_eq!(nodes.len(), 20);
        // Uniform nodes would put 2 of 20 there; the capped peak draws about 9.
        assert!(nodes.iter().filter(|&&x| x < 0.1).count() >= 8);
        assert!(nodes.windows(2).all(|w| w[1] > w[0]));
    }
}
