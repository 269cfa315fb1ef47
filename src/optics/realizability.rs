//! Physical realizability of a Mueller matrix (Cloude 1986): a matrix is an ensemble average of
//! pure (Jones) Mueller matrices — what any passive scatterer produces — iff its coherency matrix
//! is positive semidefinite. The test is an eigenvalue check, so a measured matrix can be tested
//! against its own noise.
//!
//! The coherency (Gil & Ossikovski's "covariance") matrix is H = ¼ Σ_ij m_ij (σ_i ⊗ σ_j*), with
//! the Pauli matrices in the order of [`super::jones_to_mueller`]'s psps Stokes definition
//! (σ0 = I, σ1 = diag(1,−1), σ2 = `[[0,1],[1,0]]`, σ3 = `[[0,−i],[i,0]]`). For M of a Jones
//! matrix J, H = |j⟩⟨j| with j = vec(J) (rank one, eigenvalues m00, 0, 0, 0); a sum of pure
//! matrices gives a sum of such projectors. Cloude's T differs from H by a unitary change of
//! basis, so the eigenvalues are the same. tr H = m00, and since the E_ij = σ_i ⊗ σ_j* are
//! orthogonal with tr(E_ij† E_kl) = 4 δ_ik δ_jl, ‖H‖_F = ½‖M‖_F.

use nalgebra::{Matrix2, Matrix4};
use num_complex::Complex64;

use super::Mueller;

/// The 4×4 Hermitian coherency matrix of a Mueller matrix.
pub type Coherency = Matrix4<Complex64>;

/// The Pauli matrices in the psps order (as [`super::jones_to_mueller`] uses them).
fn pauli() -> [Matrix2<Complex64>; 4] {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    let i = Complex64::new(0.0, 1.0);
    [
        Matrix2::new(one, zero, zero, one),
        Matrix2::new(one, zero, zero, -one),
        Matrix2::new(zero, one, one, zero),
        Matrix2::new(zero, -i, i, zero),
    ]
}

/// H = ¼ Σ_ij m_ij (σ_i ⊗ σ_j*).
pub fn coherency_matrix(m: &Mueller) -> Coherency {
    let sigma = pauli();
    let mut h = Coherency::zeros();
    for (i, si) in sigma.iter().enumerate() {
        for (j, sj) in sigma.iter().enumerate() {
            let weight = Complex64::new(0.25 * m[(i, j)], 0.0);
            h += si.kronecker(&sj.conjugate()) * weight;
        }
    }
    h
}

/// The eigenvalues of the coherency matrix, ascending; they sum to m00. All ≥ 0 iff `m` is
/// physically realizable (a sum of pure Mueller matrices); for a pure matrix they are
/// (0, 0, 0, m00).
pub fn coherency_eigenvalues(m: &Mueller) -> [f64; 4] {
    let h = coherency_matrix(m);
    // nalgebra's symmetric eigendecomposition is the Hermitian one for complex fields, so the
    // eigenvalues come back real.
    let eigen = nalgebra::SymmetricEigen::new(h);
    let mut values = [0.0; 4];
    for (slot, value) in values.iter_mut().zip(eigen.eigenvalues.iter()) {
        *slot = *value;
    }
    values.sort_by(f64::total_cmp);
    values
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::{fresnel_mueller, jones_to_mueller, FrameTurn};

    fn c(re: f64, im: f64) -> Complex64 {
        Complex64::new(re, im)
    }

    fn assert_eigenvalues(m: &Mueller, expected: [f64; 4]) {
        let got = coherency_eigenvalues(m);
        for (g, e) in got.iter().zip(&expected) {
            assert!((g - e).abs() < 1e-12, "{got:?} vs {expected:?} for {m}");
        }
    }

    #[test]
    fn the_coherency_matrix_is_hermitian_with_trace_m00_and_half_the_norm() {
        let m = Mueller::from_fn(|i, j| ((i * 4 + j) as f64 * 0.37).sin());
        let h = coherency_matrix(&m);
        assert!((h - h.adjoint()).norm() < 1e-15);
        assert!((h.trace() - c(m[(0, 0)], 0.0)).norm() < 1e-15);
        assert!((h.norm() - 0.5 * m.norm()).abs() < 1e-14);
    }

    #[test]
    fn pure_matrices_have_one_eigenvalue_m00() {
        assert_eigenvalues(&Mueller::identity(), [0.0, 0.0, 0.0, 1.0]);
        // An ideal polarizer along s (m00 = ½).
        let polarizer = jones_to_mueller(&Matrix2::new(
            c(1.0, 0.0),
            c(0.0, 0.0),
            c(0.0, 0.0),
            c(0.0, 0.0),
        ));
        assert_eigenvalues(&polarizer, [0.0, 0.0, 0.0, 0.5]);
        // The polarizer along p, written out.
        let p_polarizer = Mueller::new(
            1.0, -1.0, 0.0, 0.0, //
            -1.0, 1.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0,
        ) * 0.5;
        assert_eigenvalues(&p_polarizer, [0.0, 0.0, 0.0, 0.5]);
        // A quarter-wave retarder turned by 0.4 rad, and a metal's reflection, scaled.
        let retarder = FrameTurn::from_angle(-0.4).mueller()
            * fresnel_mueller(c(1.0, 0.0), c(0.0, 1.0))
            * FrameTurn::from_angle(0.4).mueller();
        assert_eigenvalues(&retarder, [0.0, 0.0, 0.0, 1.0]);
        let metal = fresnel_mueller(c(-0.8, 0.3), c(0.6, -0.2)) * 3.0;
        assert_eigenvalues(&metal, [0.0, 0.0, 0.0, metal[(0, 0)]]);
        // An arbitrary Jones matrix.
        let jones = Matrix2::new(c(0.3, -0.7), c(0.1, 0.4), c(-0.5, 0.2), c(0.9, 0.05));
        let m = jones_to_mueller(&jones);
        assert_eigenvalues(&m, [0.0, 0.0, 0.0, m[(0, 0)]]);
    }

    #[test]
    fn the_ideal_depolarizer_has_four_equal_eigenvalues() {
        let m = Mueller::from_diagonal(&nalgebra::Vector4::new(2.0, 0.0, 0.0, 0.0));
        assert_eigenvalues(&m, [0.5, 0.5, 0.5, 0.5]);
    }

    #[test]
    fn a_partial_depolarizer_is_realizable_only_from_minus_a_third_to_one() {
        // diag(1, d, −d, −d): eigenvalues (1+3d)/4 and (1−d)/4 (three times).
        let realizable = |d: f64| {
            let m = Mueller::from_diagonal(&nalgebra::Vector4::new(1.0, d, -d, -d));
            let values = coherency_eigenvalues(&m);
            let mut expected = [
                (1.0 + 3.0 * d) / 4.0,
                (1.0 - d) / 4.0,
                (1.0 - d) / 4.0,
                (1.0 - d) / 4.0,
            ];
            expected.sort_by(f64::total_cmp);
            for (g, e) in values.iter().zip(&expected) {
                assert!((g - e).abs() < 1e-12, "d = {d}: {values:?}");
            }
            values[0] >= -1e-12
        };
        for d in [-1.0 / 3.0, -0.2, 0.0, 0.5, 1.0] {
            assert!(realizable(d), "d = {d}");
        }
        for d in [-0.34, -0.6, 1.01, 1.5] {
            assert!(!realizable(d), "d = {d}");
        }
    }

    #[test]
    fn a_matrix_that_maps_stokes_vectors_to_stokes_vectors_can_still_be_unrealizable() {
        // diag(1, 1, 1, −1) (the "mirror" of circular polarization only) keeps every Stokes
        // vector physical but is no ensemble of Jones matrices: eigenvalues (−½, ½, ½, ½).
        let m = Mueller::from_diagonal(&nalgebra::Vector4::new(1.0, 1.0, 1.0, -1.0));
        assert_eigenvalues(&m, [-0.5, 0.5, 0.5, 0.5]);
        // m00 < |m01| creates polarized light from nothing.
        let overpolarizing = Mueller::new(
            1.0, 1.2, 0.0, 0.0, //
            1.2, 1.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0, //
            0.0, 0.0, 0.0, 0.0,
        );
        assert!(coherency_eigenvalues(&overpolarizing)[0] < -0.05);
    }

    #[test]
    fn sums_of_pure_matrices_are_realizable() {
        let jones = [
            Matrix2::new(c(0.3, -0.7), c(0.1, 0.4), c(-0.5, 0.2), c(0.9, 0.05)),
            Matrix2::new(c(1.0, 0.0), c(0.0, 0.0), c(0.0, 0.0), c(-0.2, 0.6)),
            Matrix2::new(c(0.0, 0.3), c(0.8, 0.0), c(0.2, -0.1), c(0.0, 0.0)),
        ];
        let parts: Vec<Mueller> = jones.iter().map(jones_to_mueller).collect();
        let sum = parts[0] * 0.5 + parts[1] * 1.5 + parts[2] * 0.25;
        let values = coherency_eigenvalues(&sum);
        assert!(values[0] > -1e-12, "{values:?}");
        assert!(
            values[1] > 1e-3,
            "three independent parts give three positive eigenvalues"
        );
        assert!((values.iter().sum::<f64>() - sum[(0, 0)]).abs() < 1e-12);
    }
}
