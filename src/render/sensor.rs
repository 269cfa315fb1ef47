//! What happens between the surface and the detector: the optional atmospheric path
//! S_sensor = τ S + L_path δ_j0 with τ and L_path of the scene's [`Atmosphere`] at the pixel's range
//! (docs/design.md §1.5, §1.12), and detector noise.
//!
//! Noise model: a polarimetric camera records the four polarizer images I(0°, 45°, 90°, 135°); each
//! gets independent Gaussian noise whose temperature equivalent is the NETD, σ_I = NETD · dI/dT =
//! ½ NETD · dL_bb/dT at the reference temperature (I = ½L for unpolarized light). The Stokes
//! images are then re-estimated from the noisy polarizer images, S0 = ½ΣI, S1 = I0 − I90,
//! S2 = I45 − I135, so their noise is correlated exactly as in a real instrument. Seeded
//! (ChaCha8, one stream per image row), so a render is reproducible whatever the thread count.

use super::film::polarizer;
use crate::scene::{Atmosphere, Sensor};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

/// Atmospheric transmission and path emission for one pixel at `range` metres: the Stokes
/// vector `s` seen through the path, and its standard error `error` scaled by τ (the path
/// itself is exact).
#[inline]
pub fn through_atmosphere(
    s: [f64; 4],
    error: [f64; 4],
    range: f64,
    atmosphere: &Atmosphere,
) -> ([f64; 4], [f64; 4]) {
    let (tau, path_radiance) = atmosphere.along(range);
    (
        [
            tau * s[0] + path_radiance,
            tau * s[1],
            tau * s[2],
            tau * s[3],
        ],
        error.map(|e| e * tau),
    )
}

/// Per-row noise generator: σ_I is the radiance noise of each polarizer image.
pub struct Noise {
    pub sigma_polarizer: f64,
    pub seed: u64,
}

impl Noise {
    /// The sensor's noise: σ_I = ½ NETD dL_bb/dT at the reference temperature.
    pub fn of_sensor(sensor: &Sensor) -> Noise {
        let sigma_polarizer = if sensor.netd_mk > 0.0 {
            0.5 * sensor.netd_mk * 1e-3 * sensor.band.radiance_derivative(sensor.netd_reference_k)
        } else {
            0.0
        };
        Noise {
            sigma_polarizer,
            seed: sensor.seed,
        }
    }

    /// Whether the sensor adds noise at all.
    pub fn is_noisy(&self) -> bool {
        self.sigma_polarizer > 0.0
    }

    /// Adds polarizer-image noise to a row of Stokes vectors and re-estimates them; the noisy
    /// polarizer images themselves (what the camera records) go into `recorded` (I0, I45, I90,
    /// I135 per pixel) when it is not empty. S3 is not measured by linear polarizers and is left
    /// as it is.
    pub fn apply_to_row(&self, row: usize, stokes: &mut [[f64; 4]], recorded: &mut [[f32; 4]]) {
        if !self.is_noisy() {
            return;
        }
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(row as u64);
        for (x, s) in stokes.iter_mut().enumerate() {
            let i = [0.0, FRAC_PI_4, FRAC_PI_2, 3.0 * FRAC_PI_4].map(|alpha| {
                polarizer(*s, alpha) + self.sigma_polarizer * standard_normal(&mut rng)
            });
            if let Some(r) = recorded.get_mut(x) {
                *r = i.map(|v| v as f32);
            }
            *s = [
                0.5 * (i[0] + i[1] + i[2] + i[3]),
                i[0] - i[2],
                i[1] - i[3],
                s[3],
            ];
        }
    }
}

/// Box–Muller transform of two uniforms in (0, 1].
fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atmosphere_blends_toward_path_radiance() {
        let band = crate::optics::Band::lwir();
        let atm = Atmosphere::extinction(1e-3, 280.0, &band);
        let (s, e) = through_atmosphere([10.0, 1.0, -1.0, 0.5], [0.1; 4], 1000.0, &atm);
        let tau = (-1.0f64).exp();
        let path = band.radiance(280.0);
        assert!((s[0] - (10.0 * tau + path * (1.0 - tau))).abs() < 1e-12);
        assert!(e.iter().all(|e| (e - 0.1 * tau).abs() < 1e-15));
        assert!((s[1] - tau).abs() < 1e-12 && (s[2] + tau).abs() < 1e-12);
        assert!((s[3] - 0.5 * tau).abs() < 1e-12);
    }

    #[test]
    fn noise_has_the_stated_spread_and_is_reproducible() {
        let noise = Noise {
            sigma_polarizer: 0.01,
            seed: 7,
        };
        let mut row = vec![[5.0, 0.2, -0.1, 0.0]; 20_000];
        let mut recorded = vec![[0.0f32; 4]; 20_000];
        noise.apply_to_row(3, &mut row, &mut recorded);
        let mut again = vec![[5.0, 0.2, -0.1, 0.0]; 20_000];
        noise.apply_to_row(3, &mut again, &mut []);
        assert_eq!(row, again);
        // The Stokes vectors are the re-estimate from the recorded polarizer images.
        for (s, i) in row.iter().zip(&recorded).take(100) {
            let i = i.map(f64::from);
            assert!((s[0] - 0.5 * (i[0] + i[1] + i[2] + i[3])).abs() < 1e-5);
            assert!((s[1] - (i[0] - i[2])).abs() < 1e-5 && (s[2] - (i[1] - i[3])).abs() < 1e-5);
        }
        // Each recorded image has its own noise: I0's spread is σ_I, not that of ½(S0 + S1).
        let mean_i0 = recorded.iter().map(|i| i[0] as f64).sum::<f64>() / 20_000.0;
        let var_i0 = recorded
            .iter()
            .map(|i| (i[0] as f64 - mean_i0).powi(2))
            .sum::<f64>()
            / 20_000.0;
        assert!(
            (var_i0.sqrt() / 0.01 - 1.0).abs() < 0.03,
            "{}",
            var_i0.sqrt()
        );
        let n = row.len() as f64;
        let mean0 = row.iter().map(|s| s[0]).sum::<f64>() / n;
        let var0 = row.iter().map(|s| (s[0] - mean0).powi(2)).sum::<f64>() / n;
        let var1 = row.iter().map(|s| (s[1] - 0.2).powi(2)).sum::<f64>() / n;
        // S0 = ½ Σ of four: σ(S0) = σ_I; S1 = I0 − I90: σ(S1) = √2 σ_I.
        assert!((mean0 - 5.0).abs() < 3e-4);
        assert!((var0.sqrt() / 0.01 - 1.0).abs() < 0.03, "{}", var0.sqrt());
        assert!((var1.sqrt() / (0.01 * 2f64.sqrt()) - 1.0).abs() < 0.03);
        let mut other = vec![[5.0, 0.2, -0.1, 0.0]; 10];
        noise.apply_to_row(4, &mut other, &mut []);
        assert_ne!(other[0], row[0]);
    }
}
