use thiserror::Error;

/// Why a pBRDF model or a request to it is refused.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ModelError {
    #[error("σ = {0} is invalid: the slope parameter must be finite and > 0")]
    Sigma(f64),
    #[error("q = {0} is invalid: the Cauchy exponent must be finite and > 1 (the distribution is not normalizable for q ≤ 1)")]
    Q(f64),
    #[error("Smith shadowing with the Cauchy distribution needs q > 1.5 (got q = {0}): its Λ diverges for q ≤ 3/2; use torrance-sparrow or none")]
    SmithNeedsQ(f64),
    #[error("n = {0} is invalid: the real part of the refractive index must be finite and > 0")]
    RealIndex(f64),
    #[error("k = {0} is invalid: the extinction coefficient must be finite and ≥ 0")]
    ExtinctionIndex(f64),
    #[error("ρ_d = {0} is invalid: the diffuse reflectance must be finite and within [0, 1]")]
    Diffuse(f64),
    #[error("{name} = {value}° is invalid: zenith angles must be finite and within [0°, 90°)")]
    Zenith { name: &'static str, value: f64 },
    #[error("{name} = {value}° is invalid: azimuths must be finite")]
    Azimuth { name: &'static str, value: f64 },
    #[error("the directional-hemispherical reflectance at θ = {theta_deg:.2}° is {reflectance:.6} > 1: this model is not energy conserving there (no shadowing at grazing angles?); use shadowing = smith")]
    ReflectanceAboveOne { theta_deg: f64, reflectance: f64 },
}
