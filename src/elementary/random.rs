//! Gaussian deviates from a seeded ChaCha8 stream, shared by the detector noise and the procedural
//! terrain. `rand_distr` would add a crate for one function; Box–Muller is exact.

use rand::Rng;
use rand_chacha::ChaCha8Rng;
use std::f64::consts::PI;

/// Box–Muller transform of two uniforms in (0, 1].
pub(crate) fn standard_normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random::<f64>();
    (-2.0 * u1.ln()).sqrt() * (2.0 * PI * u2).cos()
}
