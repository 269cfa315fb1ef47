//! The film: per-pixel Stokes vectors in the pixel frame (docs/design.md §1.6), their standard errors,
//! and the quantities derived from them (DoLP, AoP, polarizer images).

/// Pixels that see no object.
pub const BACKGROUND: u32 = u32::MAX;

/// A rendered Stokes image (pixel frame, W·m⁻²·sr⁻¹), row 0 at the top.
pub struct StokesImage {
    pub width: usize,
    pub height: usize,
    /// (S0, S1, S2, S3) per pixel.
    pub stokes: Vec<[f64; 4]>,
    /// Monte Carlo standard error of (S0, S1, S2, S3) per pixel (0 where the estimate is exact).
    pub standard_error: Vec<[f64; 4]>,
    /// Scene surface (object part, `Scene::surfaces`) seen at each pixel, or [`BACKGROUND`].
    pub surface: Vec<u32>,
    /// Ground truth of the visible point at each pixel (zeros for the background).
    pub truth: Vec<SurfaceTruth>,
    /// With detector noise or a detector pattern: the polarizer images I0, I45, I90, I135 per pixel
    /// as the camera records them (the Stokes vectors are re-estimated from them). Empty for an
    /// ideal camera, where I(α) follows from the Stokes vector exactly.
    pub recorded_polarizers: Vec<[f32; 4]>,
}

/// The visible point at a pixel, for users who train or validate algorithms.
/// Single precision: these become 32-bit float images.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceTruth {
    /// Depth along the optical axis, camera-space z (m); 0 for the background.
    pub depth_m: f32,
    /// Unit world-frame normal of the side the camera sees; 0 for the background.
    pub normal: [f32; 3],
    /// Surface temperature of the visible point (K); 0 for the background.
    pub temperature_k: f32,
}

/// DoLP = √(S1² + S2²)/S0 (0 where S0 ≤ 0) and AoP = ½ atan2(S2, S1) in (−π/2, π/2], radians
/// counter-clockwise from image right (docs/design.md §1.6).
#[inline]
pub fn dolp_aop(s: [f64; 4]) -> (f64, f64) {
    let linear = s[1].hypot(s[2]);
    let dolp = if s[0] > 0.0 { linear / s[0] } else { 0.0 };
    let mut aop = 0.5 * s[2].atan2(s[1]);
    if aop <= -std::f64::consts::FRAC_PI_2 {
        aop += std::f64::consts::PI;
    }
    (dolp, aop)
}

/// Polarizer image I(α) = ½(S0 + S1 cos2α + S2 sin2α) (docs/design.md §1.6).
#[inline]
pub fn polarizer(s: [f64; 4], alpha: f64) -> f64 {
    let (sin2, cos2) = (2.0 * alpha).sin_cos();
    0.5 * (s[0] + s[1] * cos2 + s[2] * sin2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    #[test]
    fn aop_and_polarizers_follow_the_stokes_convention() {
        // Horizontal (along image right) linear polarization.
        let (d, a) = dolp_aop([2.0, 1.0, 0.0, 0.0]);
        assert!((d - 0.5).abs() < 1e-15 && a.abs() < 1e-15);
        // Vertical: AoP = +π/2 (not −π/2).
        let (_, a) = dolp_aop([1.0, -1.0, 0.0, 0.0]);
        assert!((a - FRAC_PI_2).abs() < 1e-15);
        let (_, a) = dolp_aop([1.0, 0.0, 1.0, 0.0]);
        assert!((a - FRAC_PI_4).abs() < 1e-15);
        let s = [1.0, 0.3, -0.2, 0.1];
        assert!((polarizer(s, 0.0) + polarizer(s, FRAC_PI_2) - 1.0).abs() < 1e-15);
        assert!((polarizer(s, 0.0) - polarizer(s, FRAC_PI_2) - 0.3).abs() < 1e-15);
        assert!((polarizer(s, FRAC_PI_4) - polarizer(s, 3.0 * FRAC_PI_4) + 0.2).abs() < 1e-15);
    }
}
