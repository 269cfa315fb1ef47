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

/// A turn of the Stokes reference frame by η, from the old s axis toward the old p, kept as
/// (cos 2η, sin 2η): the renderer compares frames by dot products, which give η as a vector
/// (|r| cos η, |r| sin η), and the double angle follows by algebra where an angle would cost an
/// atan2 and a sin_cos per bounce.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameTurn {
    cos_2eta: f64,
    sin_2eta: f64,
}

impl FrameTurn {
    pub fn from_angle(eta: f64) -> FrameTurn {
        let (sin_2eta, cos_2eta) = (2.0 * eta).sin_cos();
        FrameTurn { cos_2eta, sin_2eta }
    }

    /// The turn by the angle of the plane vector (`c`, `s`) = |r| (cos η, sin η):
    /// cos 2η = 1 − 2s²/r² = 2c²/r² − 1 (the form with the smaller square, so that a turn by a
    /// multiple of 90° gives ±1 exactly, as sin_cos does), sin 2η = 2cs/r². (0, 0) gives no
    /// turn, as atan2(0, 0) = 0 would.
    #[inline]
    pub fn from_cos_sin(c: f64, s: f64) -> FrameTurn {
        let r2 = c * c + s * s;
        if r2 == 0.0 {
            return FrameTurn::from_angle(0.0);
        }
        let cos_2eta = if c.abs() >= s.abs() {
            1.0 - 2.0 * s * s / r2
        } else {
            2.0 * c * c / r2 - 1.0
        };
        FrameTurn {
            cos_2eta,
            sin_2eta: 2.0 * c * s / r2,
        }
    }

    /// η in (−π/2, π/2] (a Stokes frame is the same after a half turn).
    pub fn angle(&self) -> f64 {
        0.5 * self.sin_2eta.atan2(self.cos_2eta)
    }

    /// The turn back, by −η.
    pub fn inverse(&self) -> FrameTurn {
        FrameTurn {
            cos_2eta: self.cos_2eta,
            sin_2eta: -self.sin_2eta,
        }
    }

    /// S re-expressed in the turned frame: S1' = cos2η S1 + sin2η S2, S2' = −sin2η S1 + cos2η S2.
    #[inline]
    pub fn apply(&self, stokes: &Stokes) -> Stokes {
        let (c, s) = (self.cos_2eta, self.sin_2eta);
        Stokes::new(
            stokes[0],
            c * stokes[1] + s * stokes[2],
            -s * stokes[1] + c * stokes[2],
            stokes[3],
        )
    }

    /// The frame rotator L(η) = `[[1,0,0,0],[0,c,s,0],[0,−s,c,0],[0,0,0,1]]`, c = cos2η,
    /// s = sin2η: the Mueller matrix of [`FrameTurn::apply`] (Jones [[cosη, sinη], [−sinη, cosη]]).
    pub fn mueller(&self) -> Mueller {
        let (c, s) = (self.cos_2eta, self.sin_2eta);
        Mueller::new(
            1.0, 0.0, 0.0, 0.0, //
            0.0, c, s, 0.0, //
            0.0, -s, c, 0.0, //
            0.0, 0.0, 0.0, 1.0,
        )
    }
}

/// L(η) applied to a Stokes vector ([`FrameTurn::apply`]).
/// (docs/design.md §1.6's rotation into the pixel frame by ψ is `rotate_stokes(s, −ψ)`.)
#[inline]
pub fn rotate_stokes(stokes: &Stokes, eta: f64) -> Stokes {
    FrameTurn::from_angle(eta).apply(stokes)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::{fresnel_amplitudes, RefractiveIndex};

    /// A turn known from a frame comparison's (|r| cos η, |r| sin η) is the turn by η, for any
    /// |r|; quarter and half turns have cos 2η = ∓1 exactly (the report relies on m10' = −m10 at 90°), the
    /// inverse undoes it, and (0, 0) is no turn.
    #[test]
    fn a_frame_turn_from_a_vector_is_the_turn_by_its_angle() {
        let stokes = Stokes::new(1.0, 0.3, -0.5, 0.2);
        for i in 0..200 {
            let eta = -3.2 + 6.4 * (i as f64 + 0.37) / 200.0;
            let radius = 0.1 + 3.0 * (i % 7) as f64;
            let turn = FrameTurn::from_cos_sin(radius * eta.cos(), radius * eta.sin());
            let by_angle = FrameTurn::from_angle(eta);
            assert!(
                (turn.apply(&stokes) - by_angle.apply(&stokes)).norm() < 2e-15,
                "{eta}"
            );
            assert!((turn.inverse().apply(&turn.apply(&stokes)) - stokes).norm() < 2e-15);
            let wrapped = (eta + std::f64::consts::FRAC_PI_2).rem_euclid(std::f64::consts::PI)
                - std::f64::consts::FRAC_PI_2;
            assert!((turn.angle() - wrapped).abs() < 1e-14, "{eta}");
        }
        let quarter = std::f64::consts::FRAC_PI_2;
        assert_eq!(
            FrameTurn::from_cos_sin(quarter.cos(), quarter.sin()).cos_2eta,
            -1.0
        );
        assert_eq!(FrameTurn::from_cos_sin(-2.0, 1e-17).cos_2eta, 1.0);
        assert_eq!(FrameTurn::from_cos_sin(0.0, 0.0).apply(&stokes), stokes);
    }

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
        assert!(
            (jones_to_mueller(&jones) - FrameTurn::from_angle(eta).mueller())
                .abs()
                .max()
                < 1e-15
        );
        let stokes = Stokes::new(1.0, 0.3, -0.2, 0.1);
        assert!(
            (rotate_stokes(&stokes, eta) - FrameTurn::from_angle(eta).mueller() * stokes).norm()
                < 1e-15
        );
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
