//! Jones → Mueller conversion, Mueller/Stokes rotations and the Fresnel Mueller matrix, all in the
//! SCATMECH "psps" Stokes convention (docs/design.md §1.3): S0 = |E_s|²+|E_p|², S1 = |E_s|²−|E_p|²,
//! S2 = 2 Re(E_s* E_p) (+45° from s toward p), S3 = 2 Im(E_s* E_p).

use nalgebra::{Matrix2, Matrix4, Vector4};
use num_complex::Complex64;

/// A 4×4 Mueller matrix (BRDF Mueller matrices carry sr⁻¹).
pub type Mueller = Matrix4<f64>;
/// A Stokes vector (S0, S1, S2, S3).
pub type Stokes = Vector4<f64>;

/// Mueller matrix of a Jones matrix J acting on (E_s, E_p): M_ij = ½ Re tr(σ_i J σ_j J†), with the
/// Pauli basis ordered to the psps Stokes definition above (σ0 = I, σ1 = diag(1,−1),
/// σ2 = `[[0,1],[1,0]]`, σ3 = `[[0,−i],[i,0]]`), so that S_i = tr(σ_i E E†).
pub fn jones_to_mueller(jones: &Matrix2<Complex64>) -> Mueller {
    let zero = Complex64::new(0.0, 0.0);
    let one = Complex64::new(1.0, 0.0);
    let i = Complex64::new(0.0, 1.0);
    let pauli = [
        Matrix2::new(one, zero, zero, one),
        Matrix2::new(one, zero, zero, -one),
        Matrix2::new(zero, one, one, zero),
        Matrix2::new(zero, -i, i, zero),
    ];
    let adjoint = jones.adjoint();
    Mueller::from_fn(|row, col| 0.5 * (pauli[row] * jones * pauli[col] * adjoint).trace().re)
}

/// Mueller matrix of a reflection with amplitude coefficients (r_s, r_p) in its own s/p frame:
/// `[[A,B,0,0],[B,A,0,0],[0,0,C,−S],[0,0,S,C]]` with A = (|r_s|²+|r_p|²)/2, B = (|r_s|²−|r_p|²)/2,
/// C = Re(r_s* r_p), S = Im(r_s* r_p) (docs/design.md §1.3; `jones_to_mueller` of diag(r_s, r_p)).
#[inline]
pub fn fresnel_mueller(r_s: Complex64, r_p: Complex64) -> Mueller {
    let (rs2, rp2) = (r_s.norm_sqr(), r_p.norm_sqr());
    let (a, b) = (0.5 * (rs2 + rp2), 0.5 * (rs2 - rp2));
    let cross = r_s.conj() * r_p;
    let (c, s) = (cross.re, cross.im);
    Mueller::new(
        a, b, 0.0, 0.0, //
        b, a, 0.0, 0.0, //
        0.0, 0.0, c, -s, //
        0.0, 0.0, s, c,
    )
}

/// The frame rotator L(η) = `[[1,0,0,0],[0,c,s,0],[0,−s,c,0],[0,0,0,1]]`, c = cos2η, s = sin2η: the
/// Mueller matrix of re-expressing a Stokes vector in s/p axes rotated by η (Jones [[cosη, sinη],
/// [−sinη, cosη]]).
pub fn stokes_rotator(eta: f64) -> Mueller {
    let (s, c) = (2.0 * eta).sin_cos();
    Mueller::new(
        1.0, 0.0, 0.0, 0.0, //
        0.0, c, s, 0.0, //
        0.0, -s, c, 0.0, //
        0.0, 0.0, 0.0, 1.0,
    )
}

/// Applies L(η) to a Stokes vector: S1' = cos2η S1 + sin2η S2, S2' = −sin2η S1 + cos2η S2.
/// (docs/design.md §1.6's rotation into the pixel frame by ψ is `rotate_stokes(s, −ψ)`.)
#[inline]
pub fn rotate_stokes(stokes: &Stokes, eta: f64) -> Stokes {
    let (s, c) = (2.0 * eta).sin_cos();
    Stokes::new(
        stokes[0],
        c * stokes[1] + s * stokes[2],
        -s * stokes[1] + c * stokes[2],
        stokes[3],
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::{fresnel_amplitudes, RefractiveIndex};

    #[test]
    fn fresnel_mueller_is_the_jones_conversion_of_a_diagonal_reflection() {
        let eps = RefractiveIndex::new(1.2, 0.2).permittivity();
        for deg in [0.0f64, 20.0, 55.0, 80.0] {
            let (rs, rp) = fresnel_amplitudes(deg.to_radians().cos(), eps);
            let zero = Complex64::new(0.0, 0.0);
            let general = jones_to_mueller(&Matrix2::new(rs, zero, zero, rp));
            assert!((general - fresnel_mueller(rs, rp)).abs().max() < 1e-15);
        }
    }

    #[test]
    fn rotator_matches_a_rotated_jones_frame() {
        let eta = 0.37f64;
        let (s, c) = eta.sin_cos();
        let re = |x: f64| Complex64::new(x, 0.0);
        let jones = Matrix2::new(re(c), re(s), re(-s), re(c));
        assert!((jones_to_mueller(&jones) - stokes_rotator(eta)).abs().max() < 1e-15);
        let stokes = Stokes::new(1.0, 0.3, -0.2, 0.1);
        assert!((rotate_stokes(&stokes, eta) - stokes_rotator(eta) * stokes).norm() < 1e-15);
    }

    #[test]
    fn s_polarized_light_stays_s_polarized_and_quarter_turn_swaps_s_and_p() {
        let s_pol = Stokes::new(1.0, 1.0, 0.0, 0.0);
        let turned = rotate_stokes(&s_pol, std::f64::consts::FRAC_PI_2);
        assert!((turned - Stokes::new(1.0, -1.0, 0.0, 0.0)).norm() < 1e-15);
        // Jones matrix of a pure phase delay on p: S3 = 2 Im(E_s* E_p) picks up the phase.
        let i = Complex64::new(0.0, 1.0);
        let one = Complex64::new(1.0, 0.0);
        let zero = Complex64::new(0.0, 0.0);
        let quarter_wave = jones_to_mueller(&Matrix2::new(one, zero, zero, i));
        let plus45 = Stokes::new(1.0, 0.0, 1.0, 0.0);
        assert!((quarter_wave * plus45 - Stokes::new(1.0, 0.0, 0.0, 1.0)).norm() < 1e-15);
    }
}
