//! The polarimetric microfacet BRDF of docs/design.md §1.3 (Priest–Germer with the Wellems/Cauchy slope
//! distribution, as in Ma et al. 2009 eqs. 1–7), its polarized emissivity by Kirchhoff's law
//! (eqs. 8–9) and the hemispherical reflection integrals that both the emissivity and the scene
//! renderer use.

mod band;
mod batch;
mod distribution;
mod error;
mod facet_side;
mod geometry;
mod hemisphere;
pub mod limits;
mod lobe_keys;
mod model;
mod sample;
mod search_rules;
mod shadowing;
mod subsurface;
pub mod terms;
mod visible_slopes;

pub use crate::optics::Direction;
pub use band::{BandPbrdf, MaterialOptics};
pub use batch::GeometryColumns;
pub use distribution::{
    parse_distribution, slope_distribution, DistributionError, DistributionKind, SlopeDistribution,
};
pub use error::ModelError;
pub use facet_side::FacetSide;
pub use geometry::{fold_signed_zenith, signed_zenith_note};
pub use hemisphere::{cosine_hemisphere_rule, HemisphereQuadrature};
pub use lobe_keys::{lobe_parameters, LobeKeys};
pub(crate) use lobe_keys::{read_table, table_fields};
pub use model::{Pbrdf, ScatteringGeometry};
pub use sample::ScatteredView;
pub use shadowing::Shadowing;
pub use subsurface::{LobeKeysWithoutReflectance, Subsurface, Transmission};
pub use terms::{
    Body, LobeParameters, ModelTerms, OutsideDomain, Parameter, ParameterInfo, SpectralRole, Term,
};
