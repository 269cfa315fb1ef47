//! A division-of-focal-plane polarizer array that is not perfect (docs/design.md §1.11): each pixel's
//! wire grid has a diattenuation D = (ER − 1)/(ER + 1) and its own orientation error, and a
//! fraction c of every pixel's signal is recorded by each of its four neighbours (optical and
//! electrical crosstalk). Pixel p of nominal orientation α_k records
//! I_p = (1 − n_p c) a_p·S_p + c Σ_q a_q·S_q,  a = ½(1, D cos2α, D sin2α),
//! the sum over its n_p neighbours inside the image (so a uniform unpolarized scene stays
//! uniform), then noise and the detector's pattern. The nominal pattern is `render::dofp`'s.
//!
//! **Calibrated reconstruction.** The effective analyzer of each pixel, A_p = (1 − n_p c) a_p +
//! c Σ a_q, is known from calibration. Its three components are demosaicked like the intensities
//! (bilinearly: a linear method maps a uniform scene's samples and its analyzers alike), and each
//! pixel's Stokes vector is the least-squares solution of the four interpolated I_k = A_k·S. For a
//! uniform scene this is exact; uncalibrated, S0 = ½ΣI, S1 = I0 − I90, S2 = I45 − I135 reads a
//! fully polarized field's DoLP as D.

use crate::render::dofp::{demosaic, orientation};
use crate::scene::{Demosaic, Dofp, Sensor};
use nalgebra::{Matrix3, Vector3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

use crate::elementary::standard_normal;

/// Nominal polarizer orientations α_k (0°, 45°, 90°, 135°).
pub const ORIENTATIONS: [f64; 4] = [0.0, FRAC_PI_4, FRAC_PI_2, 3.0 * FRAC_PI_4];

/// Salt that keeps the orientation errors' random streams apart from the noise's.
const ORIENTATION_SALT: u64 = 0x6f72_6965_6e74_6174;

/// Each pixel's analyzer a_p = ½(1, D cos2α_p, D sin2α_p) as the array was made.
pub struct PolarizerArray {
    pub dofp: Dofp,
    width: usize,
    height: usize,
    analyzers: Vec<[f64; 3]>,
}

impl PolarizerArray {
    pub fn new(sensor: &Sensor, dofp: Dofp, width: usize, height: usize) -> PolarizerArray {
        let sigma = dofp.orientation_sigma_deg.to_radians();
        let d = dofp.diattenuation;
        let analyzers = (0..height)
            .into_par_iter()
            .flat_map_iter(|y| {
                let mut rng = ChaCha8Rng::seed_from_u64(sensor.seed ^ ORIENTATION_SALT);
                rng.set_stream(y as u64);
                (0..width)
                    .map(|x| {
                        let error = if sigma > 0.0 {
                            sigma * standard_normal(&mut rng)
                        } else {
                            0.0
                        };
                        let alpha = ORIENTATIONS[orientation(x, y)] + error;
                        let (sin2, cos2) = (2.0 * alpha).sin_cos();
                        [0.5, 0.5 * d * cos2, 0.5 * d * sin2]
                    })
                    .collect::<Vec<_>>()
            })
            .collect();
        PolarizerArray {
            dofp,
            width,
            height,
            analyzers,
        }
    }

    /// The array's (width, height) in pixels.
    pub fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// Whether every pixel is a perfect polarizer at its nominal angle, without crosstalk: then
    /// the recorded value is exactly the ideal polarizer image (`film::polarizer`).
    pub fn is_ideal(&self) -> bool {
        self.dofp.diattenuation == 1.0
            && self.dofp.orientation_sigma_deg == 0.0
            && self.dofp.crosstalk == 0.0
    }

    /// a_p·S: the signal pixel `p`'s own polarizer passes. With D = 1 and no error this is
    /// ½(S0 + S1 cos2α + S2 sin2α) evaluated as `film::polarizer` does, bit for bit.
    #[inline]
    fn passed(&self, p: usize, s: &[f64; 4]) -> f64 {
        if self.is_ideal() {
            let alpha = ORIENTATIONS[orientation(p % self.width, p / self.width)];
            return crate::render::film::polarizer(*s, alpha);
        }
        let a = self.analyzers[p];
        a[0] * s[0] + a[1] * s[1] + a[2] * s[2]
    }

    /// The 4-neighbours of pixel `p` inside the image.
    fn neighbours(&self, p: usize) -> impl Iterator<Item = usize> + '_ {
        let (x, y) = (p % self.width, p / self.width);
        let (w, h) = (self.width, self.height);
        [
            (x > 0).then(|| p - 1),
            (x + 1 < w).then(|| p + 1),
            (y > 0).then(|| p - w),
            (y + 1 < h).then(|| p + w),
        ]
        .into_iter()
        .flatten()
    }

    /// The noise-free signal every pixel records from the (blurred) Stokes image, crosstalk
    /// included.
    pub fn signals(&self, stokes: &[[f64; 4]]) -> Vec<f64> {
        let c = self.dofp.crosstalk;
        (0..stokes.len())
            .into_par_iter()
            .map(|p| {
                let own = self.passed(p, &stokes[p]);
                if c == 0.0 {
                    return own;
                }
                let (count, leaked) = self.neighbours(p).fold((0.0, 0.0), |(n, sum), q| {
                    (n + 1.0, sum + self.passed(q, &stokes[q]))
                });
                (1.0 - count * c) * own + c * leaked
            })
            .collect()
    }

    /// The effective analyzer A_p of every pixel (crosstalk included), one mosaic per component.
    fn effective_analyzers(&self) -> [Vec<f64>; 3] {
        let c = self.dofp.crosstalk;
        let rows: Vec<[f64; 3]> = (0..self.analyzers.len())
            .map(|p| {
                let own = self.analyzers[p];
                let (count, leaked) = self.neighbours(p).fold((0.0, [0.0; 3]), |(n, sum), q| {
                    let a = self.analyzers[q];
                    (n + 1.0, [sum[0] + a[0], sum[1] + a[1], sum[2] + a[2]])
                });
                [0, 1, 2].map(|j| (1.0 - count * c) * own[j] + c * leaked[j])
            })
            .collect();
        [0, 1, 2].map(|j| rows.iter().map(|a| a[j]).collect())
    }

    /// Stokes (S0, S1, S2) per pixel from the demosaicked polarizer images `polarizers`.
    pub fn reconstruct(&self, polarizers: &[[f64; 4]]) -> Vec<[f64; 3]> {
        if !self.dofp.calibrated || self.is_ideal() {
            // Uncalibrated, or a perfect array, where the least-squares solution is this one.
            return polarizers
                .iter()
                .map(|&i| crate::render::dofp::stokes_from_polarizers(i))
                .collect();
        }
        let components = self.effective_analyzers();
        let interpolated: Vec<Vec<[f64; 4]>> = components
            .iter()
            .map(|mosaic| demosaic(self.width, self.height, mosaic, Demosaic::Bilinear))
            .collect();
        polarizers
            .par_iter()
            .enumerate()
            .map(|(p, i)| {
                let rows = [0, 1, 2, 3].map(|k| {
                    Vector3::new(
                        interpolated[0][p][k],
                        interpolated[1][p][k],
                        interpolated[2][p][k],
                    )
                });
                least_squares_stokes(&rows, i)
            })
            .collect()
    }
}

/// The S minimizing Σ_k (A_k·S − I_k)², by the normal equations (3 × 3, well conditioned for any
/// array that polarizes: the four orientations span the linear Stokes space).
fn least_squares_stokes(rows: &[Vector3<f64>; 4], i: &[f64; 4]) -> [f64; 3] {
    let mut normal = Matrix3::zeros();
    let mut right = Vector3::zeros();
    for (a, &value) in rows.iter().zip(i) {
        normal += a * a.transpose();
        right += a * value;
    }
    match normal.try_inverse() {
        Some(inverse) => {
            let s = inverse * right;
            [s[0], s[1], s[2]]
        }
        None => crate::render::dofp::stokes_from_polarizers(*i),
    }
}
