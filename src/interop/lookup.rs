//! A table's value between its nodes as Mitsuba's `measured_polarized` finds it (docs/design.md
//! §2.10): multilinear interpolation in (φ_d, θ_d, θ_h) on the stored, possibly non-uniform,
//! grids, clamped to the end nodes outside them. irpol uses it to measure how well a grid
//! holds a material ([`super::grid`]) without running Mitsuba.

use super::convention::{half_difference_angles, psps_from_table};
use super::pbsdf::PbsdfTable;
use crate::optics::Mueller;
use nalgebra::Vector3;

/// The cell of `x` in increasing `nodes` and the weight of its upper node, clamped outside.
fn cell(nodes: &[f64], x: f64) -> (usize, f64) {
    let last = nodes.len() - 1;
    if x <= nodes[0] {
        return (0, 0.0);
    }
    if x >= nodes[last] {
        return (last - 1, 1.0);
    }
    let upper = nodes.partition_point(|&n| n <= x).min(last);
    let lower = upper - 1;
    (lower, (x - nodes[lower]) / (nodes[upper] - nodes[lower]))
}

/// The table's matrix (its own frames) at angles (θ_h, θ_d, φ_d) and wavelength index `l`.
pub fn interpolate(
    table: &PbsdfTable,
    theta_h: f64,
    theta_d: f64,
    phi_d: f64,
    l: usize,
) -> Mueller {
    let grid = &table.grid;
    let (p, wp) = cell(&grid.phi_d, phi_d);
    let (d, wd) = cell(&grid.theta_d, theta_d);
    let (h, wh) = cell(&grid.theta_h, theta_h);
    let mut sum = Mueller::zeros();
    for (dp, fp) in [(0, 1.0 - wp), (1, wp)] {
        for (dd, fd) in [(0, 1.0 - wd), (1, wd)] {
            for (dh, fh) in [(0, 1.0 - wh), (1, wh)] {
                let weight = fp * fd * fh;
                if weight != 0.0 {
                    sum += table.matrix(p + dp, d + dd, h + dh, l) * weight;
                }
            }
        }
    }
    sum
}

/// The interpolated psps Mueller BRDF for incident direction `light` and scattered `view`
/// (unit vectors in the surface frame, ẑ the normal), at wavelength index `l`.
pub fn psps_at(table: &PbsdfTable, light: &Vector3<f64>, view: &Vector3<f64>, l: usize) -> Mueller {
    let (theta_h, theta_d, phi_d) = half_difference_angles(light, view);
    psps_from_table(&interpolate(table, theta_h, theta_d, phi_d, l), light, view)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_clamp_outside_and_weigh_inside() {
        let nodes = [0.0, 1.0, 3.0];
        assert_eq!(cell(&nodes, -1.0), (0, 0.0));
        assert_eq!(cell(&nodes, 0.5), (0, 0.5));
        assert_eq!(cell(&nodes, 1.0), (1, 0.0));
        assert_eq!(cell(&nodes, 2.5), (1, 0.75));
        assert_eq!(cell(&nodes, 4.0), (1, 1.0));
    }
}
