//! The `[model]` of a material file: grey (one wavelength, as fitted from one measurement) or
//! spectral (docs/design.md §1.9, §2.6): n, k and ρ_d as tables over ascending wavelengths, σ, q and the
//! shadowing shared (the surface's geometry does not depend on λ). Between table nodes n, k and ρ_d
//! are linear in λ; outside the table the model is not defined and [`MaterialModel::at`] refuses.
//! A grey model is the same at every wavelength.

use super::ModelSpec;
use crate::optics::{Band, LorentzDispersion, TableMissesBand, WavelengthNodes};
use crate::pbrdf::{BandPbrdf, FacetSide, LobeKeys, ModelError, Shadowing, SlopeDistribution};
use crate::text::number;
use serde::{Deserialize, Serialize};

/// A material's model over wavelength.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged, try_from = "super::raw::RawModel<PerWavelength>")]
pub enum MaterialModel {
    /// One N = n + ik and ρ_d, used at every wavelength (`wavelength_um` is where it was measured).
    Grey(ModelSpec),
    Spectral(SpectralModel),
}

/// n, k and ρ_d tabulated over wavelength with shared σ, q and shadowing.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SpectralModel {
    #[serde(flatten)]
    pub distribution: SlopeDistribution,
    pub shadowing: Shadowing,
    /// Table wavelengths, µm, strictly ascending (at least two).
    pub wavelength_um: Vec<f64>,
    pub n: Vec<f64>,
    pub k: Vec<f64>,
    /// One per wavelength.
    pub rho_d: Vec<f64>,
    /// The facet side and the subsurface term (docs/design.md §1.10), as a grey model has them.
    #[serde(flatten)]
    pub volume: SpectralVolume,
    /// The dispersion law n, k were fitted with, when a law was (`fit --dispersion lorentz:N`);
    /// `n`, `k` hold it evaluated at the table wavelengths, so readers need not know the law.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dispersion: Option<LorentzDispersion>,
}

/// The volume terms of a spectral model (docs/design.md §1.10): which side of the facets reflects,
/// and the subsurface term's parameters, each shared by every wavelength (one number: the fit
/// shared it) or one per table wavelength. Absent keys mean what they mean in a grey model: no
/// subsurface term without ρ_s, d = 0, n_sub = n, d_c = d, d1 = 0.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct SpectralVolume {
    #[serde(default, skip_serializing_if = "FacetSide::is_external")]
    pub facet: FacetSide,
    #[serde(flatten)]
    pub lobe_keys: LobeKeys<PerWavelength>,
}

/// A model parameter over a spectral table: one number for every wavelength, or one per
/// wavelength (linear in λ between nodes, as n and k).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PerWavelength {
    Shared(f64),
    Each(Vec<f64>),
}

impl PerWavelength {
    /// The value at a wavelength, `interpolate` taking a table to its value there.
    fn at(&self, interpolate: &impl Fn(&[f64]) -> f64) -> f64 {
        match self {
            PerWavelength::Shared(value) => *value,
            PerWavelength::Each(values) => interpolate(values),
        }
    }

    /// One number when every wavelength has the same value, else the table.
    pub fn from_values(values: Vec<f64>) -> PerWavelength {
        match values.first() {
            Some(&first) if values.iter().all(|&v| v == first) => PerWavelength::Shared(first),
            _ => PerWavelength::Each(values),
        }
    }

    /// The number of values a table holds (`None` for a shared number).
    pub fn table_len(&self) -> Option<usize> {
        match self {
            PerWavelength::Shared(_) => None,
            PerWavelength::Each(values) => Some(values.len()),
        }
    }
}

/// A wavelength outside a spectral material's table.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{} µm is outside its table, {}–{} µm", number(*.wavelength_um), number(*.first_um), number(*.last_um))]
pub struct OutsideTable {
    pub wavelength_um: f64,
    pub first_um: f64,
    pub last_um: f64,
}

/// Why a spectral model cannot be integrated over a band.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BandModelError {
    #[error(transparent)]
    Table(#[from] TableMissesBand),
    #[error(transparent)]
    Outside(#[from] OutsideTable),
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// The temperature (K) at which a spectral material's thermal emissivity is Planck-weighted
/// ([`SpectralModel::thermal_emissivity`]).
pub const THERMAL_EMISSIVITY_REFERENCE_K: f64 = 300.0;

impl SpectralModel {
    /// The model at each wavelength node of `band` (docs/design.md §1.9, [`crate::optics::band_nodes`]),
    /// refused when the table does not span the band.
    pub fn band_pbrdf(&self, band: &Band) -> Result<BandPbrdf, BandModelError> {
        self.band_pbrdf_on(WavelengthNodes::for_table(band, &self.wavelength_um)?)
    }

    /// The model at each of `nodes` (which must lie inside the table: nodes of a band it spans,
    /// e.g. shared with other materials, [`WavelengthNodes::for_tables`]).
    pub fn band_pbrdf_on(&self, nodes: WavelengthNodes) -> Result<BandPbrdf, BandModelError> {
        let models = nodes
            .wavelengths_um()
            .iter()
            .map(|&lambda| Ok(self.at(lambda)?.pbrdf()?))
            .collect::<Result<Vec<_>, BandModelError>>()?;
        Ok(BandPbrdf::new(nodes, models)?)
    }

    /// The thermal hemispherical emissivity of docs/design.md §1.8 for a spectral material: the
    /// hemispherical ε_h(λ) of each model, Planck-weighted at
    /// [`THERMAL_EMISSIVITY_REFERENCE_K`] over the table's own range (flat response), the
    /// wavelengths the material is known at: Σ_m f_m ε_h(λ_m). A heat balance is broadband and
    /// the table is not, so this takes the table's Planck-weighted mean to hold outside it.
    pub fn thermal_emissivity(&self) -> Result<f64, BandModelError> {
        let (first, last) = self.range_um();
        let table = Band::new(first, last, None).map_err(|_| TableMissesBand {
            table_um: (first, last),
            band_um: (first, last),
        })?;
        let band = self.band_pbrdf(&table)?;
        let shares = band
            .nodes()
            .planck_fractions(THERMAL_EMISSIVITY_REFERENCE_K);
        Ok(band
            .models()
            .iter()
            .zip(&shares)
            .map(|(model, f)| f * model.hemispherical_emissivity())
            .sum())
    }

    /// The model at `wavelength_um`: n, k, ρ_d interpolated linearly between the two nearest
    /// table nodes (exactly the node's values at a node).
    pub fn at(&self, wavelength_um: f64) -> Result<ModelSpec, OutsideTable> {
        let (first, last) = self.range_um();
        if !(wavelength_um >= first && wavelength_um <= last) {
            return Err(OutsideTable {
                wavelength_um,
                first_um: first,
                last_um: last,
            });
        }
        let upper = self
            .wavelength_um
            .partition_point(|&w| w < wavelength_um)
            .clamp(1, self.wavelength_um.len() - 1);
        let (a, b) = (upper - 1, upper);
        let (wa, wb) = (self.wavelength_um[a], self.wavelength_um[b]);
        let interpolate = |values: &[f64]| {
            if wavelength_um == wa {
                values[a]
            } else if wavelength_um == wb {
                values[b]
            } else {
                let f = (wavelength_um - wa) / (wb - wa);
                values[a] + f * (values[b] - values[a])
            }
        };
        // As a grey file reads (material::raw): each lobe's d is written, 0 where absent.
        let lobe_keys = self.volume.lobe_keys.map(|_, v| v.at(&interpolate));
        let lobe_keys = lobe_keys.clone().with_residuals().unwrap_or(lobe_keys);
        Ok(ModelSpec {
            distribution: self.distribution,
            shadowing: self.shadowing,
            n: interpolate(&self.n),
            k: interpolate(&self.k),
            rho_d: interpolate(&self.rho_d),
            facet: self.volume.facet,
            lobe_keys,
            wavelength_um,
        })
    }

    /// The spectral model whose nodes are `nodes`, grey models at ascending wavelengths with one
    /// slope distribution, shadowing and facet side (a spectral fit's wavelengths): the inverse of
    /// [`SpectralModel::nodes`]. A subsurface parameter equal at every node is written once.
    pub fn from_nodes(nodes: &[ModelSpec], dispersion: Option<LorentzDispersion>) -> SpectralModel {
        let column = |value: fn(&ModelSpec) -> f64| nodes.iter().map(value).collect::<Vec<_>>();
        // A lobe key written at every node, as one number or a table.
        let mut lobe_keys = LobeKeys::default();
        for (parameter, _) in nodes[0].lobe_keys.iter() {
            let values: Option<Vec<f64>> = nodes
                .iter()
                .map(|m| m.lobe_keys.get(parameter).copied())
                .collect();
            lobe_keys.set(parameter, values.map(PerWavelength::from_values));
        }
        SpectralModel {
            distribution: nodes[0].distribution,
            shadowing: nodes[0].shadowing,
            wavelength_um: column(|m| m.wavelength_um),
            n: column(|m| m.n),
            k: column(|m| m.k),
            rho_d: column(|m| m.rho_d),
            volume: SpectralVolume {
                facet: nodes[0].facet,
                lobe_keys,
            },
            dispersion,
        }
    }

    /// The model's terms (docs/design.md §1.10), as [`ModelSpec::terms`] says them.
    pub fn terms(&self) -> crate::pbrdf::ModelTerms {
        crate::pbrdf::ModelTerms::new(self.volume.facet, self.volume.lobe_keys.body())
    }

    /// The first and last table wavelengths, µm.
    pub fn range_um(&self) -> (f64, f64) {
        (
            self.wavelength_um[0],
            self.wavelength_um[self.wavelength_um.len() - 1],
        )
    }

    /// The model at each table node, in wavelength order.
    pub fn nodes(&self) -> impl Iterator<Item = ModelSpec> + '_ {
        self.wavelength_um
            .iter()
            .map(|&w| self.at(w).expect("a node is inside its own table"))
    }
}

impl MaterialModel {
    pub fn distribution(&self) -> SlopeDistribution {
        match self {
            MaterialModel::Grey(m) => m.distribution,
            MaterialModel::Spectral(m) => m.distribution,
        }
    }

    pub fn shadowing(&self) -> Shadowing {
        match self {
            MaterialModel::Grey(m) => m.shadowing,
            MaterialModel::Spectral(m) => m.shadowing,
        }
    }

    pub fn set_shadowing(&mut self, shadowing: Shadowing) {
        match self {
            MaterialModel::Grey(m) => m.shadowing = shadowing,
            MaterialModel::Spectral(m) => m.shadowing = shadowing,
        }
    }

    /// The grey model, or `None` for a spectral one.
    pub fn grey(&self) -> Option<&ModelSpec> {
        match self {
            MaterialModel::Grey(m) => Some(m),
            MaterialModel::Spectral(_) => None,
        }
    }

    pub fn spectral(&self) -> Option<&SpectralModel> {
        match self {
            MaterialModel::Grey(_) => None,
            MaterialModel::Spectral(m) => Some(m),
        }
    }

    /// The model at `wavelength_um`: a grey model's own at any wavelength, a spectral one's
    /// interpolated in its table ([`SpectralModel::at`]).
    pub fn at(&self, wavelength_um: f64) -> Result<ModelSpec, OutsideTable> {
        match self {
            MaterialModel::Grey(m) => Ok(m.clone()),
            MaterialModel::Spectral(m) => m.at(wavelength_um),
        }
    }

    /// The wavelengths the model was measured at: one for a grey model, the table's for a
    /// spectral one.
    pub fn wavelengths_um(&self) -> Vec<f64> {
        match self {
            MaterialModel::Grey(m) => vec![m.wavelength_um],
            MaterialModel::Spectral(m) => m.wavelength_um.clone(),
        }
    }

    /// Checks that the model is valid at every table node (a grey model at its wavelength).
    pub fn validate(&self) -> Result<(), ModelError> {
        match self {
            MaterialModel::Grey(m) => m.pbrdf().map(drop),
            MaterialModel::Spectral(m) => m.nodes().try_for_each(|node| node.pbrdf().map(drop)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn glass() -> SpectralModel {
        SpectralModel {
            distribution: SlopeDistribution::Cauchy {
                sigma: 0.06,
                q: 2.8,
            },
            shadowing: Shadowing::Smith,
            wavelength_um: vec![8.0, 9.0, 11.5],
            n: vec![0.5, 1.4, 2.1],
            k: vec![0.5, 2.1, 0.1],
            rho_d: vec![0.0, 0.01, 0.02],
            volume: SpectralVolume::default(),
            dispersion: None,
        }
    }

    #[test]
    fn between_nodes_the_table_is_linear_and_at_nodes_exact() {
        let model = glass();
        let at = model.at(8.5).unwrap();
        assert!((at.n - 0.95).abs() < 1e-15 && (at.k - 1.3).abs() < 1e-15);
        assert!((at.rho_d - 0.005).abs() < 1e-15 && at.wavelength_um == 8.5);
        let node = model.at(11.5).unwrap();
        assert_eq!((node.n, node.k, node.rho_d), (2.1, 0.1, 0.02));
        let first = model.at(8.0).unwrap();
        assert_eq!((first.n, first.k), (0.5, 0.5));
        let outside = model.at(7.9).unwrap_err().to_string();
        assert_eq!(outside, "7.9 µm is outside its table, 8–11.5 µm");
        assert!(model.at(f64::NAN).is_err());
    }

    #[test]
    fn a_flat_table_has_its_grey_thermal_emissivity() {
        let flat = SpectralModel {
            n: vec![1.4; 3],
            k: vec![0.3; 3],
            rho_d: vec![0.02; 3],
            ..glass()
        };
        let grey = flat.at(9.0).unwrap().pbrdf().unwrap();
        let thermal = flat.thermal_emissivity().unwrap();
        assert!((thermal - grey.hemispherical_emissivity()).abs() < 1e-12);
        // A table that does not change with λ integrates over any band to its grey self.
        let band = flat
            .band_pbrdf(&Band::new(8.5, 11.0, None).unwrap())
            .unwrap();
        assert!(band.models().iter().all(|m| m.index() == grey.index()));
        let err = flat.band_pbrdf(&Band::lwir()).unwrap_err().to_string();
        assert!(
            err.contains("8–11.5 µm") && err.contains("8–14 µm"),
            "{err}"
        );
    }

    #[test]
    fn a_grey_model_is_the_same_everywhere() {
        let grey = MaterialModel::Grey(glass().at(9.0).unwrap());
        assert_eq!(grey.at(13.0).unwrap(), grey.at(8.0).unwrap());
        assert_eq!(grey.wavelengths_um(), vec![9.0]);
    }

    mod grey_twins {
        use super::super::super::{Material, ModelSpec};
        use super::*;
        use crate::pbrdf::{Body, FacetSide, LobeKeys, ModelTerms, Parameter};
        use std::path::Path;

        /// The lobe keys `values` where `present`, else none.
        fn lobe_keys(present: bool, values: [(Parameter, f64); 5]) -> LobeKeys<f64> {
            let mut keys = LobeKeys::default();
            for (parameter, value) in values {
                keys.set(parameter, present.then_some(value));
            }
            keys
        }

        /// A grey model of each term set at `wavelength_um`, with per-wavelength n, k and
        /// reflectances and the subsurface's d, n_sub, d_c shared (`per_wavelength_d` makes d
        /// differ).
        fn node(terms: ModelTerms, wavelength_um: f64, per_wavelength_d: bool) -> ModelSpec {
            let j = if wavelength_um < 1.0 { 0.0 } else { 1.0 };
            let subsurface = terms.body == Body::Subsurface;
            ModelSpec {
                distribution: SlopeDistribution::Cauchy {
                    sigma: 0.62,
                    q: 2.1,
                },
                shadowing: Shadowing::Smith,
                n: 1.38 - 0.03 * j,
                k: 0.04 + 0.01 * j,
                rho_d: if subsurface { 0.0 } else { 0.7 + 0.05 * j },
                facet: terms.facet_side,
                lobe_keys: lobe_keys(
                    subsurface,
                    [
                        (Parameter::RhoS, 0.96 - 0.01 * j),
                        (
                            Parameter::D,
                            0.02 + if per_wavelength_d { 0.01 * j } else { 0.0 },
                        ),
                        (Parameter::NSub, 1.05),
                        (Parameter::DC, -0.015),
                        (Parameter::D1, 0.004),
                    ],
                ),
                wavelength_um,
            }
        }

        /// docs/design.md §1.10 "spectral materials carry every term": a spectral material written
        /// and read back is, at each of its wavelengths, the grey material of that wavelength —
        /// facet side and every subsurface parameter included, whether shared or per wavelength.
        #[test]
        fn a_spectral_material_is_its_grey_twin_at_each_wavelength_for_every_term_set() {
            let terms = ModelTerms::ALL
                .into_iter()
                .chain([ModelTerms::new(FacetSide::Internal, Body::Depolarizer)]);
            for (terms, per_wavelength_d) in terms.flat_map(|t| [(t, false), (t, true)]) {
                let nodes = [
                    node(terms, 0.351, per_wavelength_d),
                    node(terms, 1.064, per_wavelength_d),
                ];
                let material = Material {
                    name: "twin".into(),
                    tool_version: "irpol test".into(),
                    model: MaterialModel::Spectral(SpectralModel::from_nodes(&nodes, None)),
                    fit: None,
                };
                let path = Path::new("twin.toml");
                let text = material.to_toml(path).unwrap();
                let read = Material::from_toml(&text, path).unwrap();
                for grey in &nodes {
                    let spectral = read.at(grey.wavelength_um).unwrap();
                    assert_eq!(&spectral, grey, "{terms} {text}");
                    let (a, b) = (spectral.pbrdf().unwrap(), grey.pbrdf().unwrap());
                    assert_eq!(a.facet_side(), terms.facet_side);
                    for (ti, tr, phi) in [(0.0, 30.0, 180.0), (45.0, 60.0, 90.0), (75.0, 10.0, 0.0)]
                    {
                        let (wi, wr) = (
                            crate::optics::Direction::from_degrees(ti, 0.0),
                            crate::optics::Direction::from_degrees(tr, phi),
                        );
                        let (ma, mb) = (a.mueller(&wi, &wr), b.mueller(&wi, &wr));
                        assert!((ma - mb).abs().max() <= 1e-12 * mb[(0, 0)], "{terms}");
                    }
                }
            }
        }

        /// A subsurface key with a table of the wrong length is refused naming the key and the
        /// wavelength that has no value.
        #[test]
        fn a_spectral_term_key_missing_a_wavelength_is_refused_by_name() {
            let terms = ModelTerms::new(FacetSide::Internal, Body::Subsurface);
            let nodes = [node(terms, 0.351, true), node(terms, 1.064, true)];
            let material = Material {
                name: "short".into(),
                tool_version: "irpol test".into(),
                model: MaterialModel::Spectral(SpectralModel::from_nodes(&nodes, None)),
                fit: None,
            };
            let path = Path::new("short.toml");
            let text = material.to_toml(path).unwrap();
            let start = text.find("\nd = [").expect("d is a table");
            let end = start + text[start..].find(']').unwrap();
            let short = format!("{}\nd = [0.02{}", &text[..start], &text[end..]);
            let error = Material::from_toml(&short, path).unwrap_err().to_string();
            assert!(
                error.contains("d has 1 values for 2 wavelengths")
                    && error.contains("1.064 µm has none"),
                "{error}"
            );
        }
    }
}
