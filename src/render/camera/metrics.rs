//! How well a camera's Stokes images reconstruct the noise-free truth the renderer knows
//! (docs/design.md §1.11): PSNR of S0, S1, S2 and DoLP, and the RMS error of the AoP where the
//! true DoLP exceeds [`AOP_DOLP_THRESHOLD`] (elsewhere the angle is noise).

use super::DofpImages;
use crate::render::film::dolp_aop;
use serde::Serialize;
use std::f64::consts::PI;

/// True DoLP above which the AoP error is counted.
pub const AOP_DOLP_THRESHOLD: f64 = 0.01;

/// PSNR = 10 log10(peak²/MSE) dB, peak the truth's largest magnitude; `None` when the estimate is
/// exact (MSE = 0) or the truth is all zeros.
pub fn psnr(truth: &[f64], estimate: &[f64]) -> Option<f64> {
    let peak = truth.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let mse = truth
        .iter()
        .zip(estimate)
        .map(|(t, e)| (t - e).powi(2))
        .sum::<f64>()
        / truth.len().max(1) as f64;
    (mse > 0.0 && peak > 0.0).then(|| 10.0 * (peak * peak / mse).log10())
}

/// One camera's reconstruction quality.
#[derive(Clone, Debug, Serialize)]
pub struct Reconstruction {
    pub psnr_s0_db: Option<f64>,
    pub psnr_s1_db: Option<f64>,
    pub psnr_s2_db: Option<f64>,
    pub psnr_dolp_db: Option<f64>,
    /// RMS of the AoP error (degrees, wrapped to ±90°) where the true DoLP > 1 %.
    pub aop_rmse_deg: Option<f64>,
    /// How many pixels the AoP error is taken over.
    pub aop_pixels: usize,
}

impl Reconstruction {
    /// Compares `estimate` (S0, S1, S2 per pixel) with `truth`.
    pub fn of(truth: &[[f64; 4]], estimate: &[[f64; 3]]) -> Reconstruction {
        let channel = |c: usize| {
            let t: Vec<f64> = truth.iter().map(|s| s[c]).collect();
            let e: Vec<f64> = estimate.iter().map(|s| s[c]).collect();
            psnr(&t, &e)
        };
        let polarization = |s: [f64; 3]| dolp_aop([s[0], s[1], s[2], 0.0]);
        // (DoLP, AoP) of the truth and of the estimate at each pixel.
        type Polarization = Vec<(f64, f64)>;
        let (true_pol, est_pol): (Polarization, Polarization) = truth
            .iter()
            .zip(estimate)
            .map(|(t, e)| (polarization([t[0], t[1], t[2]]), polarization(*e)))
            .unzip();
        let dolp = |v: &[(f64, f64)]| v.iter().map(|p| p.0).collect::<Vec<f64>>();
        let aop_errors: Vec<f64> = true_pol
            .iter()
            .zip(&est_pol)
            .filter(|(t, _)| t.0 > AOP_DOLP_THRESHOLD)
            .map(|(t, e)| {
                // The AoP is an axis: wrap the difference into (−π/2, π/2].
                let d = (e.1 - t.1).rem_euclid(PI);
                if d > PI / 2.0 {
                    d - PI
                } else {
                    d
                }
            })
            .collect();
        let aop_rmse_deg = (!aop_errors.is_empty()).then(|| {
            (aop_errors.iter().map(|d| d * d).sum::<f64>() / aop_errors.len() as f64)
                .sqrt()
                .to_degrees()
        });
        Reconstruction {
            psnr_s0_db: channel(0),
            psnr_s1_db: channel(1),
            psnr_s2_db: channel(2),
            psnr_dolp_db: psnr(&dolp(&true_pol), &dolp(&est_pol)),
            aop_rmse_deg,
            aop_pixels: aop_errors.len(),
        }
    }
}

/// Both cameras' quality: the four-image camera (the render's S0–S3) and, with `[sensor.dofp]`,
/// the DoFP camera.
#[derive(Clone, Debug, Serialize)]
pub struct CameraMetrics {
    pub stokes: Reconstruction,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub dofp: Option<Reconstruction>,
}

impl CameraMetrics {
    pub fn of(truth: &[[f64; 4]], stokes: &[[f64; 4]], dofp: Option<&DofpImages>) -> CameraMetrics {
        let four: Vec<[f64; 3]> = stokes.iter().map(|s| [s[0], s[1], s[2]]).collect();
        CameraMetrics {
            stokes: Reconstruction::of(truth, &four),
            dofp: dofp.map(|d| Reconstruction::of(truth, &d.stokes)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_follows_its_definition() {
        // Peak 2 (the largest |value|, here negative), MSE = (0.1² + 0.2²) / 2 = 0.025.
        let p = psnr(&[1.0, -2.0], &[1.1, -1.8]).unwrap();
        assert!((p - 10.0 * (4.0f64 / 0.025).log10()).abs() < 1e-12, "{p}");
        assert_eq!(psnr(&[1.0, 2.0], &[1.0, 2.0]), None);
        assert_eq!(psnr(&[0.0, 0.0], &[0.1, 0.0]), None);
    }

    #[test]
    fn aop_error_wraps_at_the_axis() {
        // AoP 89° against −89°: 2° apart, not 178°; DoLP 0.5 % pixels are not counted.
        let at = |deg: f64, dolp: f64| {
            let a = 2.0 * deg.to_radians();
            [1.0, dolp * a.cos(), dolp * a.sin(), 0.0]
        };
        let truth = [at(89.0, 0.5), at(10.0, 0.005)];
        let estimate = [at(-89.0, 0.5), at(50.0, 0.005)].map(|s| [s[0], s[1], s[2]]);
        let r = Reconstruction::of(&truth, &estimate);
        assert_eq!(r.aop_pixels, 1);
        assert!((r.aop_rmse_deg.unwrap() - 2.0).abs() < 1e-9);
    }
}
