//! Fresnel amplitude reflection coefficients for a complex refractive index (docs/design.md §1.3).

use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// Complex refractive index N = n + ik of the substrate relative to the incident medium (air).
/// k ≥ 0 absorbs (time dependence exp(−iωt)); metals have k > n.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RefractiveIndex {
    pub n: f64,
    pub k: f64,
}

impl RefractiveIndex {
    pub fn new(n: f64, k: f64) -> Self {
        Self { n, k }
    }

    /// Relative permittivity ε = N².
    pub fn permittivity(&self) -> Complex64 {
        let index = Complex64::new(self.n, self.k);
        index * index
    }
}

/// The numerators and denominators of the Fresnel amplitude coefficients at local incidence angle
/// β, for permittivity ε (docs/design.md §1.3), with w = √(ε − sin²β):
/// r_s = (cosβ − w)/(cosβ + w), r_p = (ε cosβ − w)/(ε cosβ + w).
///
/// With k ≥ 0, Im(ε − sin²β) = 2nk ≥ 0, so the principal square root has Re ≥ 0 and Im ≥ 0: the
/// transmitted wave decays into the substrate, which is the physical branch for metals too.
/// Kept as fractions so that the Mueller coefficients need no complex division; numerators and
/// denominators carry a common positive factor (see [`FresnelFractions::from_cos2`]).
#[derive(Clone, Copy, Debug)]
pub struct FresnelFractions {
    pub s_num: Complex64,
    pub s_den: Complex64,
    pub p_num: Complex64,
    pub p_den: Complex64,
}

impl FresnelFractions {
    #[inline]
    pub fn new(cos_beta: f64, permittivity: Complex64) -> Self {
        Self::from_cos2(cos_beta * cos_beta, permittivity)
    }

    /// [`FresnelFractions::new`] from cos²β: the pBRDF has |ω_i + ω_r|² = 4cos²β, and cos β itself
    /// would cost a square root.
    ///
    /// The fractions are multiplied through by s > 0, where s√z = (|z| + Re z, Im z) or
    /// (|Im z|, ±(|z| − Re z)) (see `scaled_principal_sqrt`): s·w needs no division,
    /// s cosβ = √(s² cos²β) one square root, and the ratios are unchanged. This is the hot path of
    /// every BRDF evaluation, so the chain from cos²β to the fractions is kept short: z is formed
    /// with one addition from ε − 1, which does not wait for cos²β.
    #[inline]
    pub fn from_cos2(cos2_beta: f64, permittivity: Complex64) -> Self {
        let z = Complex64::new((permittivity.re - 1.0) + cos2_beta, permittivity.im);
        let (scaled_w, half_s2) = scaled_principal_sqrt(z);
        let scaled_cos = (half_s2 * (2.0 * cos2_beta)).sqrt();
        let scaled_eps_cos = permittivity * scaled_cos;
        FresnelFractions {
            s_num: scaled_cos - scaled_w,
            s_den: scaled_cos + scaled_w,
            p_num: scaled_eps_cos - scaled_w,
            p_den: scaled_eps_cos + scaled_w,
        }
    }

    /// (r_s, r_p).
    pub fn amplitudes(&self) -> (Complex64, Complex64) {
        (self.s_num / self.s_den, self.p_num / self.p_den)
    }

    /// (|r_s|², |r_p|², r_s* r_p): what the Mueller matrix of the reflection needs.
    #[inline]
    pub fn reflectances_and_cross(&self) -> (f64, f64, Complex64) {
        let (rs2, rp2, cross, inverse) = self.reflectances_and_cross_unnormalized();
        (rs2 * inverse, rp2 * inverse, cross * inverse)
    }

    /// [`FresnelFractions::reflectances_and_cross`] times the common denominator
    /// |s_den|² |p_den|², and its inverse last: a caller that scales the three anyway folds the
    /// inverse into its own factor, one multiplication after the division instead of one each.
    #[inline]
    pub fn reflectances_and_cross_unnormalized(&self) -> (f64, f64, Complex64, f64) {
        let (s_den2, p_den2) = (self.s_den.norm_sqr(), self.p_den.norm_sqr());
        // One division for all three (divisions dominate this hot path).
        let inverse = 1.0 / (s_den2 * p_den2);
        // r_s* r_p = (s_num* p_num)(s_den p_den*) / (|s_den|² |p_den|²)
        let cross = self.s_num.conj() * self.p_num * (self.s_den * self.p_den.conj());
        (
            self.s_num.norm_sqr() * p_den2,
            self.p_num.norm_sqr() * s_den2,
            cross,
            inverse,
        )
    }
}

/// The principal square root (Re ≥ 0) of z in algebraic form, returned as (s√z, s²/2) with
/// s = 2t > 0: √z = (t, Im z/(2t)) with 2t² = |z| + Re z when Re z ≥ 0, else (|Im z|/(2t), ±t)
/// with 2t² = |z| − Re z — the forms without cancellation. Scaled by s, √z needs neither a
/// division nor the square root of t², and neither half. num-complex's `sqrt` goes through the
/// polar form (atan2, hypot, sin, cos) and costs about four times as much; this is on the hot path
/// of every BRDF evaluation. At z = 0 it returns (0, ½), i.e. s = 1.
#[inline]
fn scaled_principal_sqrt(z: Complex64) -> (Complex64, f64) {
    // |z| without hypot's overflow guard: here |z| ≤ |ε| + 1, far from overflow, and hypot is slow.
    let modulus = (z.re * z.re + z.im * z.im).sqrt();
    if z.re >= 0.0 {
        let half_s2 = modulus + z.re;
        if half_s2 == 0.0 {
            return (Complex64::new(0.0, 0.0), 0.5);
        }
        (Complex64::new(half_s2, z.im), half_s2)
    } else {
        let half_s2 = modulus - z.re;
        (Complex64::new(z.im.abs(), half_s2.copysign(z.im)), half_s2)
    }
}

/// Amplitude reflection coefficients (r_s, r_p) at local incidence cos β (see [`FresnelFractions`]).
pub fn fresnel_amplitudes(cos_beta: f64, permittivity: Complex64) -> (Complex64, Complex64) {
    FresnelFractions::new(cos_beta, permittivity).amplitudes()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn reflectances(theta_deg: f64, n: f64, k: f64) -> (f64, f64) {
        let (rs, rp) = fresnel_amplitudes(
            theta_deg.to_radians().cos(),
            RefractiveIndex::new(n, k).permittivity(),
        );
        (rs.norm_sqr(), rp.norm_sqr())
    }

    #[test]
    fn normal_incidence_matches_closed_form() {
        // R = ((n−1)² + k²) / ((n+1)² + k²) for both polarizations.
        for &(n, k) in &[(1.5, 0.0), (1.2, 0.2), (10.0, 30.0), (0.2, 5.0)] {
            let (rs, rp) = reflectances(0.0, n, k);
            let expect = ((n - 1.0f64).powi(2) + k * k) / ((n + 1.0f64).powi(2) + k * k);
            assert!((rs - expect).abs() < 1e-14, "{n} {k}: {rs} vs {expect}");
            assert!((rp - expect).abs() < 1e-14);
        }
    }

    #[test]
    fn brewster_angle_zeroes_p_for_a_dielectric() {
        let n = 1.5f64;
        let (rs, rp) = reflectances(n.atan().to_degrees(), n, 0.0);
        assert!(rp < 1e-28, "R_p at Brewster = {rp}");
        assert!(
            (rs - 0.1479289940828402).abs() < 1e-12,
            "R_s at Brewster = {rs}"
        );
    }

    #[test]
    fn reflectances_and_cross_term_match_the_amplitudes() {
        let eps = RefractiveIndex::new(10.0, 30.0).permittivity();
        for deg in [0.0f64, 33.0, 71.0, 89.0] {
            let fractions = FresnelFractions::new(deg.to_radians().cos(), eps);
            let (rs, rp) = fractions.amplitudes();
            let (rs2, rp2, cross) = fractions.reflectances_and_cross();
            assert!((rs2 - rs.norm_sqr()).abs() < 1e-15 && (rp2 - rp.norm_sqr()).abs() < 1e-15);
            assert!((cross - rs.conj() * rp).norm() < 1e-15);
        }
    }

    #[test]
    fn scaled_principal_sqrt_matches_num_complex() {
        for &(re, im) in &[
            (2.0, 0.5),
            (-3.0, 0.2),
            (-3.0, -0.2),
            (0.0, 1.0),
            (4.0, 0.0),
            (-4.0, 0.0),
            (3600.0, 1200.0), // a metal's ε − sin²β; |z| stays far from under/overflow
        ] {
            let z = Complex64::new(re, im);
            let (scaled, half_s2) = scaled_principal_sqrt(z);
            assert!(half_s2 > 0.0);
            assert!(
                (scaled / (2.0 * half_s2).sqrt() - z.sqrt()).norm() <= 1e-15 * z.norm().sqrt(),
                "{z}"
            );
        }
    }

    #[test]
    fn critical_angle_of_a_thinner_medium_reflects_everything() {
        // n = 0.5, k = 0: ε − sin²β = 0 exactly at cos²β = 3/4, where √ of zero must not divide
        // by zero.
        let (rs, rp) = FresnelFractions::from_cos2(0.75, Complex64::new(0.25, 0.0)).amplitudes();
        assert!((rs.norm_sqr() - 1.0).abs() < 1e-12 && (rp.norm_sqr() - 1.0).abs() < 1e-12);
        assert_eq!(
            scaled_principal_sqrt(Complex64::new(0.0, 0.0)),
            (Complex64::new(0.0, 0.0), 0.5)
        );
    }

    /// Weak reflections keep their relative accuracy: a nearly index-matched medium (R ~ 1e-7, and
    /// R_p through zero near Brewster's angle). Squaring the fractions in real arithmetic,
    /// cos²β + |w|² ∓ 2u cosβ, cancels quadratically and was 7e-5 off here; the complex
    /// numerators cancel only linearly.
    #[test]
    fn weak_reflections_keep_relative_accuracy() {
        let eps = RefractiveIndex::new(1.001, 0.0).permittivity();
        for step in 0..90 {
            let c = (step as f64).to_radians().cos();
            let w = (eps - (1.0 - c * c)).sqrt();
            let (rs, rp) = ((c - w) / (c + w), (eps * c - w) / (eps * c + w));
            let (rs2, rp2, _) = FresnelFractions::new(c, eps).reflectances_and_cross();
            assert!((rs2 / rs.norm_sqr() - 1.0).abs() < 1e-9, "{step}°: R_s");
            assert!((rp2 / rp.norm_sqr() - 1.0).abs() < 1e-9, "{step}°: R_p");
        }
    }

    #[test]
    fn grazing_incidence_reflects_everything() {
        let (rs, rp) = reflectances(90.0, 1.5, 0.1);
        assert!((rs - 1.0).abs() < 1e-14 && (rp - 1.0).abs() < 1e-14);
    }

    #[test]
    fn absorbing_medium_stays_below_unity() {
        // Metals: 0 ≤ R ≤ 1 at every angle, R_p ≤ R_s (principal-angle dip).
        for theta in 0..90 {
            let (rs, rp) = reflectances(theta as f64, 10.0, 30.0);
            assert!(
                rs <= 1.0 && rp <= rs + 1e-15 && rp > 0.5,
                "{theta}: {rs} {rp}"
            );
        }
    }
}
