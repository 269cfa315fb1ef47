//! The detector after non-uniformity correction (docs/design.md §1.11): each pixel of each
//! polarizer image keeps a residual gain g = 1 + σ_g·N and offset o = σ_o·N (fixed-pattern noise,
//! the same for every frame of a seed), then the signal is quantized to N bits over the radiances
//! of `range_k`. Offsets are temperature-like: σ_o = ½ · offset · dL_bb/dT at the NETD reference,
//! the NETD's own conversion (a polarizer image carries half the radiance).

use crate::scene::{Detector, Sensor};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::elementary::standard_normal;

/// Salt that keeps the fixed pattern's random streams apart from the temporal noise's.
const PATTERN_SALT: u64 = 0x6669_7865_6470_6174;

/// The detector's fixed pattern and quantizer.
pub struct DetectorModel {
    gain_sigma: f64,
    offset_sigma: f64,
    seed: u64,
    /// (lowest radiance, step, levels − 1) of the quantizer; `None` = no quantization.
    quantizer: Option<(f64, f64, f64)>,
}

/// One pixel's residual gain and offset for each of the four polarizer images (0°, 45°, 90°, 135°).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelPattern {
    pub gain: [f64; 4],
    pub offset: [f64; 4],
}

impl DetectorModel {
    pub fn new(sensor: &Sensor, detector: Detector) -> DetectorModel {
        let band = &sensor.band;
        let quantizer = (detector.bits > 0).then(|| {
            let (lo, hi) = detector.range_k;
            let (low, high) = (0.5 * band.radiance(lo), 0.5 * band.radiance(hi));
            let levels = (2f64).powi(detector.bits as i32) - 1.0;
            (low, (high - low) / levels, levels)
        });
        DetectorModel {
            gain_sigma: detector.fpn_gain_sigma,
            offset_sigma: 0.5
                * detector.fpn_offset_mk
                * 1e-3
                * band.radiance_derivative(sensor.netd_reference_k),
            seed: sensor.seed ^ PATTERN_SALT,
            quantizer,
        }
    }

    /// Every pixel's pattern in image row `row` (its own random stream: any thread count gives the
    /// same pattern).
    pub fn pattern_row(&self, row: usize, width: usize) -> Vec<PixelPattern> {
        let mut rng = ChaCha8Rng::seed_from_u64(self.seed);
        rng.set_stream(row as u64);
        (0..width)
            .map(|_| PixelPattern {
                gain: [0; 4].map(|_| 1.0 + self.gain_sigma * standard_normal(&mut rng)),
                offset: [0; 4].map(|_| self.offset_sigma * standard_normal(&mut rng)),
            })
            .collect()
    }

    /// What polarizer image `k` of a pixel with `pattern` reads for the radiance `signal`.
    #[inline]
    pub fn read(&self, signal: f64, pattern: &PixelPattern, k: usize) -> f64 {
        let value = pattern.gain[k] * signal + pattern.offset[k];
        match self.quantizer {
            None => value,
            Some((low, step, levels)) => {
                low + ((value - low) / step).round().clamp(0.0, levels) * step
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::instrument::ideal_sensor as sensor;

    #[test]
    fn the_pattern_has_its_stated_spread_and_is_fixed_per_seed() {
        let detector = Detector {
            fpn_gain_sigma: 0.02,
            fpn_offset_mk: 40.0,
            bits: 0,
            range_k: (250.0, 350.0),
        };
        let s = sensor();
        let model = DetectorModel::new(&s, detector);
        let row = model.pattern_row(3, 20_000);
        assert_eq!(row, model.pattern_row(3, 20_000));
        assert_ne!(row[0], model.pattern_row(4, 1)[0]);
        let gains: Vec<f64> = row.iter().map(|p| p.gain[1]).collect();
        let offsets: Vec<f64> = row.iter().map(|p| p.offset[2]).collect();
        let spread = |v: &[f64]| {
            let mean = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        assert!((spread(&gains) / 0.02 - 1.0).abs() < 0.03);
        // 40 mK of offset reads as a 40 mK step of an unpolarized scene's polarizer image.
        let sigma_o = 0.5 * 0.040 * s.band.radiance_derivative(300.0);
        assert!((spread(&offsets) / sigma_o - 1.0).abs() < 0.03);
    }

    #[test]
    fn quantization_rounds_to_the_nearest_level_and_clips_to_the_range() {
        let detector = Detector {
            fpn_gain_sigma: 0.0,
            fpn_offset_mk: 0.0,
            bits: 4,
            range_k: (250.0, 350.0),
        };
        let s = sensor();
        let model = DetectorModel::new(&s, detector);
        let flat = PixelPattern {
            gain: [1.0; 4],
            offset: [0.0; 4],
        };
        let (low, high) = (0.5 * s.band.radiance(250.0), 0.5 * s.band.radiance(350.0));
        let step = (high - low) / 15.0;
        assert_eq!(model.read(low - 1.0, &flat, 0), low);
        assert!((model.read(high + 1.0, &flat, 0) - high).abs() < 1e-12);
        let near_third = low + 3.4 * step;
        assert!((model.read(near_third, &flat, 0) - (low + 3.0 * step)).abs() < 1e-12);
    }
}
