use crate::text::number;
use thiserror::Error;

/// Why a pBRDF model or a request to it is refused.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ModelError {
    #[error("σ = {} is invalid: the slope parameter must be within [1e-4, 10] (smoother is a mirror, rougher a diffuser)", number(*.0))]
    Sigma(f64),
    #[error("q = {} is invalid: the Cauchy exponent must be within (1, 100] (not normalizable for q ≤ 1; beyond 100 the lobe is Gaussian: use the gaussian distribution)", number(*.0))]
    Q(f64),
    #[error("Smith shadowing with the Cauchy distribution needs q > 1.5 (got q = {}): its Λ diverges for q ≤ 3/2; use torrance-sparrow or none", number(*.0))]
    SmithNeedsQ(f64),
    #[error("n = {} is invalid: the real part of the refractive index must be within [0.01, 1000]", number(*.0))]
    RealIndex(f64),
    #[error("k = {} is invalid: the extinction coefficient must be within [0, 1000]", number(*.0))]
    ExtinctionIndex(f64),
    #[error("ρ_d = {} is invalid: the diffuse reflectance must be finite and within [0, 1]", number(*.0))]
    Diffuse(f64),
    #[error("{name} = {}° is invalid: zenith angles must be finite and within [0°, 90°)", number(*.value))]
    Zenith { name: &'static str, value: f64 },
    #[error("{name} = {}° is invalid: detector zenith angles must be finite and within (−90°, 90°) (a negative one is the other side of the normal)", number(*.value))]
    DetectorZenith { name: &'static str, value: f64 },
    #[error("{name} = {}° is invalid: azimuths must be finite", number(*.value))]
    Azimuth { name: &'static str, value: f64 },
    #[error("the directional-hemispherical reflectance at θ = {theta_deg:.2}° is {reflectance:.6} > 1: this model is not energy conserving there (no shadowing at grazing angles?); use shadowing = smith")]
    ReflectanceAboveOne { theta_deg: f64, reflectance: f64 },
    #[error("at {} µm: {source}", number(*.wavelength_um))]
    AtWavelength {
        wavelength_um: f64,
        source: Box<ModelError>,
    },
    #[error(
        "d = {}, d_c = {}: the subsurface term's D = diag(1, d, −d, −d_c) is not a physical \
         (realizable) Mueller matrix; d_c must be within [2d − 1, 1]",
        number(*.d),
        number(*.d_c)
    )]
    UnrealizableSubsurface { d: f64, d_c: f64 },
    #[error(
        "d = {}, d1 = {}: the residual polarization d + d1 cos Θ reaches |d| + |d1| > 1 at some \
         scattering angle; keep |d| + |d1| ≤ 1",
        number(*.d),
        number(*.d1)
    )]
    ResidualAboveOne { d: f64, d1: f64 },
    #[error(transparent)]
    Outside(#[from] super::OutsideDomain),
    #[error("a band material needs one model per wavelength node, all with the same slope distribution and shadowing")]
    BandModels,
}
