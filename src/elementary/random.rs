//! Gaussian deviates from a seeded ChaCha8 stream, shared by the detector noise, the polarizer
//! array's orientation errors and the procedural terrain. `rand_distr`'s ziggurat (Marsaglia and
//! Tsang) is exact like Box–Muller and avoids its logarithm and cosine per deviate: those were
//! 13 % of a noisy 1080p open-world render of the car (four deviates per pixel).

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// A standard normal deviate drawn from `rng`.
pub(crate) fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    rng.sample(StandardNormal)
}
