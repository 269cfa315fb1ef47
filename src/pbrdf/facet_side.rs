//! Which side of the surface's facets reflects the facet term (docs/design.md §1.10): a choice
//! of the model's terms ([`super::ModelTerms`]) and the permittivity its Fresnel coefficients
//! see.

use crate::optics::RefractiveIndex;
use num_complex::Complex64;
use serde::{Deserialize, Serialize};

/// Which side of the surface's facets reflects the facet term (docs/design.md §1.10).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FacetSide {
    /// Reflection off the outside of the surface: relative index N (docs/design.md §1.3).
    #[default]
    External,
    /// Reflection inside grains at grain/air facets: relative index 1/N, total internal
    /// reflection included (sintered PTFE, powders, pigments).
    Internal,
}

impl FacetSide {
    pub const ALL: [FacetSide; 2] = [FacetSide::External, FacetSide::Internal];

    pub fn name(&self) -> &'static str {
        match self {
            FacetSide::External => "external",
            FacetSide::Internal => "internal",
        }
    }

    /// Whether this is the default side (a material file then leaves the key out).
    pub fn is_external(&self) -> bool {
        *self == FacetSide::External
    }

    pub fn parse(text: &str) -> Option<FacetSide> {
        FacetSide::ALL.into_iter().find(|s| s.name() == text.trim())
    }

    /// The permittivity the facets' Fresnel coefficients see: N² outside; inside, the relative
    /// permittivity of air to the grain, 1/N², taken as N²/|N|⁴ = conj(1/N²). Why the
    /// conjugate: 1/N² has Im < 0 for k > 0, and under total internal reflection the principal
    /// root w = √(ε − sin²β) then jumps from +i√a (k = 0, the evanescent wave decaying into the
    /// air) to −i√a for any k > 0, flipping the sign of the retardance m23, m32; with Im ε ≥ 0
    /// the coefficients are continuous in k, |r| ≤ 1, and k = 0 is unchanged. (conj also turns
    /// the −0 imaginary part of 1/n² into +0, which keeps k = 0 itself on the physical branch.)
    pub(super) fn facet_permittivity(&self, index: RefractiveIndex) -> Complex64 {
        match self {
            FacetSide::External => index.permittivity(),
            FacetSide::Internal => index.permittivity().inv().conj(),
        }
    }
}
