//! Which measured rows are not physically realizable (Cloude's test, [`coherency_eigenvalues`])
//! beyond their own uncertainty: noise makes a near-pure or weakly polarizing matrix dip below
//! zero a little, so only a dip larger than the row's noise can move says the data are wrong
//! (a misread basis, swapped columns, a normalization error).

use super::MeasurementSet;
use crate::optics::{coherency_eigenvalues, Mueller};

/// Relative size of the eigensolver's rounding error against ‖M‖.
const ROUNDING: f64 = 1e-12;

/// The outcome of testing every row of a set.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Realizability {
    /// Indices into [`MeasurementSet::points`] of the rows whose smallest coherency eigenvalue
    /// is below −sigmas × the row's eigenvalue noise.
    pub unrealizable: Vec<usize>,
    /// Rows tested (those with all sixteen elements).
    pub checked: usize,
    /// Rows that cannot be tested: the set lacks some of the sixteen elements.
    pub unchecked: usize,
}

/// Tests each row of `set` that has all sixteen Mueller elements. Perturbing M by ΔM moves H by
/// ΔH with ‖ΔH‖_F = ½‖ΔM‖_F (the basis of H is orthogonal, see [`crate::optics::coherency_matrix`]),
/// and no eigenvalue of a Hermitian matrix moves by more than the perturbation's norm (Weyl), so
/// ½ sqrt(Σ u_ij²) is the row's 1-σ scale of its smallest eigenvalue. An element without an
/// uncertainty adds nothing to it (the test is then stricter, never silently looser).
pub fn unrealizable_rows(set: &MeasurementSet, sigmas: f64) -> Realizability {
    if set.elements.len() < 16 {
        return Realizability {
            unchecked: set.points.len(),
            ..Realizability::default()
        };
    }
    let mut unrealizable = Vec::new();
    for (row, point) in set.points.iter().enumerate() {
        let mut m = Mueller::zeros();
        for (&index, &value) in set.elements.iter().zip(point.values) {
            m[(index / 4, index % 4)] = value;
        }
        let noise = 0.5
            * point
                .uncertainties()
                .map(|u| u.unwrap_or(0.0).powi(2))
                .sum::<f64>()
                .sqrt();
        // Rounding in the eigensolver, so that a pure matrix without uncertainties passes.
        let rounding = ROUNDING * m.norm();
        if coherency_eigenvalues(&m)[0] < -(sigmas * noise + rounding) {
            unrealizable.push(row);
        }
    }
    Realizability {
        unrealizable,
        checked: set.points.len(),
        unchecked: 0,
    }
}
