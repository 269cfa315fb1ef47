//! Detector noise of a polarimetric camera.
//!
//! Noise model: a polarimetric camera records the four polarizer images I(0°, 45°, 90°, 135°); each
//! gets independent Gaussian noise whose temperature equivalent is the NETD, σ_I = NETD · dI/dT =
//! ½ NETD · dL_bb/dT at the reference temperature (I = ½L for unpolarized light). The Stokes
//! images are then re-estimated from the noisy polarizer images, S0 = ½ΣI, S1 = I0 − I90,
//! S2 = I45 − I135, so their noise is correlated exactly as in a real instrument. Seeded
//! (ChaCha8, one stream per image row), so a render is reproducible whatever the thread count.

use crate::elementary::standard_normal;
use crate::scene::Sensor;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

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

    /// The standard normal draws of image row `row` (its own random stream, so a render is
    /// reproducible whatever the thread count): one per polarizer image (0°, 45°, 90°, 135°) of
    /// each pixel, in that order; zeros without noise.
    pub fn row_normals(&self, row: usize, width: usize) -> Vec<[f64; 4]> {
        if !self.is_noisy() {
            return vec![[0.0; 4]; width];
        }
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(row as u64);
        (0..width)
            .map(|_| [0; 4].map(|_| standard_normal(&mut rng)))
            .collect()
    }
}
