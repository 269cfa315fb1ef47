//! Shadowing/masking functions G (the paper's g(k_np); docs/design.md §1.3).

use super::distribution::PreparedDistribution;
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum Shadowing {
    /// G = 1 (the paper's model; not energy conserving at grazing angles).
    #[default]
    None,
    /// V-groove: G = min(1, 2cosθ cosθ_i/cosβ, 2cosθ cosθ_r/cosβ).
    TorranceSparrow,
    /// Uncorrelated Smith: G = G1(θ_i) G1(θ_r), G1 = 1/(1+Λ) with the distribution's own Λ.
    Smith,
}

impl Shadowing {
    pub fn name(&self) -> &'static str {
        match self {
            Shadowing::None => "none",
            Shadowing::TorranceSparrow => "torrance-sparrow",
            Shadowing::Smith => "smith",
        }
    }

    pub fn parse(text: &str) -> Option<Shadowing> {
        match text {
            "none" => Some(Shadowing::None),
            "torrance-sparrow" => Some(Shadowing::TorranceSparrow),
            "smith" => Some(Shadowing::Smith),
            _ => None,
        }
    }

    /// The part of G that depends on one direction only: Smith's G1(θ) = 1/(1+Λ(θ)); 1 for the
    /// other kinds, whose G couples both directions through the facet.
    #[inline]
    pub(crate) fn masking(&self, distribution: &PreparedDistribution, cos_theta: f64) -> f64 {
        match self {
            Shadowing::Smith => 1.0 / (1.0 + distribution.smith_lambda(cos_theta)),
            Shadowing::None | Shadowing::TorranceSparrow => 1.0,
        }
    }

    /// G for incidence θ_i and reflection θ_r (as cosines) off the facet that mirrors one into the
    /// other, at local incidence β, given the per-direction factors [`Shadowing::masking`] of ω_i
    /// and ω_r. The facet enters only through cos²β: V-grooves need 2cosθ/cosβ =
    /// (cosθ_i + cosθ_r)/cos²β, as ω_i + ω_r = 2cosβ h.
    #[inline]
    pub(crate) fn factor_with_masking(
        &self,
        cos_i: f64,
        cos_r: f64,
        cos2_beta: f64,
        [masking_i, masking_r]: [f64; 2],
    ) -> f64 {
        match self {
            Shadowing::None => 1.0,
            Shadowing::TorranceSparrow => {
                let scale = (cos_i + cos_r) / cos2_beta;
                1.0f64.min(scale * cos_i).min(scale * cos_r)
            }
            Shadowing::Smith => masking_i * masking_r,
        }
    }
}
