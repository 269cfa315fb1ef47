//! Brightness (apparent) temperature of band radiance, tabulated: the inverse of
//! [`Band::radiance`] for previews and summaries of rendered images.

use super::Band;
use rayon::prelude::*;

/// Brightness temperature (K) of band radiance over a radiance range, by linear interpolation
/// on 257 exact inversions (`Band::brightness_temperature` is a Newton solve per call); clamped
/// to the range. For previews and summaries, not for physics.
pub struct TemperatureLookup {
    lo: f64,
    step: f64,
    values: Vec<f64>,
}

impl TemperatureLookup {
    pub fn new(band: &Band, lo: f64, hi: f64) -> TemperatureLookup {
        TemperatureLookup::with_nodes(band, lo, hi, 257)
    }

    /// The lookup with `n` ≥ 2 exact inversions (more nodes, smaller interpolation error).
    pub fn with_nodes(band: &Band, lo: f64, hi: f64, n: usize) -> TemperatureLookup {
        let n = n.max(2);
        let step = ((hi - lo) / (n - 1) as f64).max(1e-12);
        // Each inversion is a Newton solve on band integrals (~10 µs): in parallel.
        let values = (0..n)
            .into_par_iter()
            .map(|i| {
                band.brightness_temperature((lo + step * i as f64).max(0.0))
                    .unwrap_or(0.0)
            })
            .collect();
        TemperatureLookup { lo, step, values }
    }

    #[inline]
    pub fn at(&self, radiance: f64) -> f64 {
        let x = ((radiance - self.lo) / self.step).clamp(0.0, (self.values.len() - 1) as f64);
        let i = (x as usize).min(self.values.len() - 2);
        let f = x - i as f64;
        self.values[i] + f * (self.values[i + 1] - self.values[i])
    }
}
