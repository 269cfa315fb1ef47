//! Fresnel amplitude reflection coefficients for a complex refractive index (DESIGN §1.3).

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

/// Amplitude reflection coefficients (r_s, r_p) at local incidence angle β, given cos β and the
/// substrate permittivity ε (DESIGN §1.3):
/// r_s = (cosβ − √(ε − sin²β)) / (cosβ + √(ε − sin²β)),
/// r_p = (ε cosβ − √(ε − sin²β)) / (ε cosβ + √(ε − sin²β)).
///
/// With k ≥ 0, Im(ε − sin²β) = 2nk ≥ 0, so the principal square root has Re ≥ 0 and Im ≥ 0: the
/// transmitted wave decays into the substrate, which is the physical branch for metals too.
#[inline]
pub fn fresnel_amplitudes(cos_beta: f64, permittivity: Complex64) -> (Complex64, Complex64) {
    let sin2 = 1.0 - cos_beta * cos_beta;
    let root = (permittivity - sin2).sqrt();
    let r_s = (cos_beta - root) / (cos_beta + root);
    let eps_cos = permittivity * cos_beta;
    let r_p = (eps_cos - root) / (eps_cos + root);
    (r_s, r_p)
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
