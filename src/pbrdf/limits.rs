//! The parameter ranges a pBRDF model accepts ([`super::Pbrdf::new`], and so every material file,
//! command-line model and fit). Beyond them the model is not physically meaningful or its
//! numerics break down, so a value outside is refused with a message that names the range rather
//! than producing NaN, an endless quadrature or an allocation of the whole address space.

/// Smallest slope parameter σ: smoother surfaces are mirrors for any LWIR purpose, and the
/// hemispherical quadratures lay out panels in units of σ (σ = 1e-300 asked for 2 GB of them).
pub const MIN_SIGMA: f64 = 1e-4;
/// Largest σ: a mean slope of 10 (facets within 6° of vertical) is a diffuser already.
pub const MAX_SIGMA: f64 = 10.0;
/// Largest Cauchy exponent q: the lobe is practically Gaussian long before (q → ∞ is the
/// Gaussian limit), and the Smith Λ table of larger q underflows to NaN.
pub const MAX_Q: f64 = 100.0;
/// Smallest real refractive index n (metals in the visible reach ~0.05; the LWIR is far above).
pub const MIN_N: f64 = 0.01;
/// Largest n and extinction coefficient k (LWIR metals reach n, k ≈ 100).
pub const MAX_N: f64 = 1000.0;
pub const MAX_K: f64 = 1000.0;

/// Whether `value` is finite and within [low, high].
pub(crate) fn within(value: f64, low: f64, high: f64) -> bool {
    value.is_finite() && (low..=high).contains(&value)
}
