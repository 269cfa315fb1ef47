//! How well a camera's Stokes images reconstruct the noise-free truth the renderer knows
//! (docs/design.md §1.11): PSNR of S0, S1, S2 and DoLP, and the RMS error of the AoP where the
//! true DoLP exceeds [`AOP_DOLP_THRESHOLD`] (elsewhere the angle is noise).

use super::DofpImages;
use crate::render::film::dolp_aop;
use rayon::prelude::*;
use serde::Serialize;
use std::f64::consts::PI;

/// True DoLP above which the AoP error is counted.
pub const AOP_DOLP_THRESHOLD: f64 = 0.01;

/// `estimate − truth` of two AoPs (radians), wrapped into (−π/2, π/2]: the AoP is an axis.
pub fn aop_difference(estimate: f64, truth: f64) -> f64 {
    let d = (estimate - truth).rem_euclid(PI);
    if d > PI / 2.0 {
        d - PI
    } else {
        d
    }
}

/// PSNR = 10 log10(peak²/MSE) dB, peak the truth's largest magnitude; `None` when the estimate is
/// exact (MSE = 0) or the truth is all zeros.
pub fn psnr(truth: &[f64], estimate: &[f64]) -> Option<f64> {
    let peak = truth.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let squared: f64 = truth
        .iter()
        .zip(estimate)
        .map(|(t, e)| (t - e).powi(2))
        .sum();
    psnr_db(peak, squared / truth.len().max(1) as f64)
}

/// 10 log10(peak²/MSE); `None` for an exact estimate or a zero peak.
fn psnr_db(peak: f64, mse: f64) -> Option<f64> {
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
    /// Compares `estimate` (S0, S1, S2 per pixel) with `truth`, in one parallel pass.
    pub fn of(truth: &[[f64; 4]], estimate: &[[f64; 3]]) -> Reconstruction {
        // Fixed blocks summed in image order: the same sums, to the last bit, on any number of
        // threads (a work-stealing reduction would make summary.json differ between runs).
        const BLOCK: usize = 4096;
        let sums = truth
            .par_chunks(BLOCK)
            .zip(estimate.par_chunks(BLOCK))
            .map(|(t, e)| {
                t.iter()
                    .zip(e)
                    .fold(ErrorSums::default(), |sums, (t, e)| sums.add(t, e))
            })
            .collect::<Vec<_>>()
            .into_iter()
            .fold(ErrorSums::default(), ErrorSums::merge);
        let n = truth.len().max(1) as f64;
        let psnr_of = |peak: f64, squared: f64| psnr_db(peak, squared / n);
        Reconstruction {
            psnr_s0_db: psnr_of(sums.peak[0], sums.squared[0]),
            psnr_s1_db: psnr_of(sums.peak[1], sums.squared[1]),
            psnr_s2_db: psnr_of(sums.peak[2], sums.squared[2]),
            psnr_dolp_db: psnr_of(sums.peak[3], sums.squared[3]),
            aop_rmse_deg: (sums.aop_pixels > 0).then(|| {
                (sums.aop_squared / sums.aop_pixels as f64)
                    .sqrt()
                    .to_degrees()
            }),
            aop_pixels: sums.aop_pixels,
        }
    }
}

/// Running peaks and squared errors of S0, S1, S2, DoLP, and the squared AoP error where the true
/// DoLP exceeds [`AOP_DOLP_THRESHOLD`].
#[derive(Clone, Copy, Default)]
struct ErrorSums {
    peak: [f64; 4],
    squared: [f64; 4],
    aop_squared: f64,
    aop_pixels: usize,
}

impl ErrorSums {
    fn add(mut self, t: &[f64; 4], e: &[f64; 3]) -> ErrorSums {
        let (true_dolp, true_aop) = dolp_aop([t[0], t[1], t[2], 0.0]);
        let (dolp, aop) = dolp_aop([e[0], e[1], e[2], 0.0]);
        let pairs = [(t[0], e[0]), (t[1], e[1]), (t[2], e[2]), (true_dolp, dolp)];
        for (j, (truth, estimate)) in pairs.into_iter().enumerate() {
            self.peak[j] = self.peak[j].max(truth.abs());
            self.squared[j] += (truth - estimate).powi(2);
        }
        if true_dolp > AOP_DOLP_THRESHOLD {
            self.aop_squared += aop_difference(aop, true_aop).powi(2);
            self.aop_pixels += 1;
        }
        self
    }

    fn merge(a: ErrorSums, b: ErrorSums) -> ErrorSums {
        ErrorSums {
            peak: [0, 1, 2, 3].map(|j| a.peak[j].max(b.peak[j])),
            squared: [0, 1, 2, 3].map(|j| a.squared[j] + b.squared[j]),
            aop_squared: a.aop_squared + b.aop_squared,
            aop_pixels: a.aop_pixels + b.aop_pixels,
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

    /// summary.json must not change with the thread count: sweeps compare outputs by hash.
    #[test]
    fn metrics_are_bit_identical_on_any_number_of_threads() {
        let pixels = 100_003;
        let value = |i: usize, k: usize| ((i * 7919 + k * 104_729) % 10_007) as f64 * 1e-3 + 0.1;
        let truth: Vec<[f64; 4]> = (0..pixels)
            .map(|i| {
                [
                    10.0 + value(i, 0),
                    value(i, 1) - 5.0,
                    value(i, 2) - 5.0,
                    0.0,
                ]
            })
            .collect();
        let estimate: Vec<[f64; 3]> = truth
            .iter()
            .enumerate()
            .map(|(i, t)| [t[0] + value(i, 3) * 1e-3, t[1] * 0.99, t[2] + 1e-3])
            .collect();
        let on_threads = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            let r = pool.install(|| Reconstruction::of(&truth, &estimate));
            [
                r.psnr_s0_db,
                r.psnr_s1_db,
                r.psnr_s2_db,
                r.psnr_dolp_db,
                r.aop_rmse_deg,
            ]
            .map(|v| v.unwrap().to_bits())
        };
        let one = on_threads(1);
        for threads in [2, 3, 7] {
            assert_eq!(on_threads(threads), one, "{threads} threads");
        }
    }

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
