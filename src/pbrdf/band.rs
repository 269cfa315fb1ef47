//! A material over a sensor band (docs/design.md §1.9): its pBRDF at each wavelength node of the band
//! ([`crate::optics::band_nodes`]), all sharing the slope distribution and shadowing (σ, q do not
//! depend on λ) and differing in N and ρ_d. What a renderer needs from it:
//!
//! - the reflection quadrature nodes of every model at once: the node placement depends on σ, q
//!   and the shadowing only, so it is done once and only the Fresnel factor is evaluated per
//!   wavelength ([`BandPbrdf::visit_specular_nodes`]);
//! - the band-weighted Mueller matrix Σ_m f_m F(λ_m) for the spectral shares f_m of a source
//!   ([`BandPbrdf::mueller_mixtures`]): F is linear in the Fresnel elements A, B, C, S and in ρ_d,
//!   so the geometry, density and shadowing are shared and only the Fresnel terms are mixed.

use super::hemisphere::HemisphereQuadrature;
use super::model::ScatteringGeometry;
use super::{ModelError, Pbrdf};
use crate::optics::{Direction, FresnelFractions, Mueller, SpectralMix, Stokes, WavelengthNodes};
use nalgebra::Vector3;
use std::f64::consts::FRAC_1_PI;

/// How a scene material scatters and emits over the sensor band.
#[derive(Clone, Debug)]
pub enum MaterialOptics {
    /// One pBRDF at every wavelength (a material measured at one wavelength, or inline).
    Grey(Pbrdf),
    /// A spectral material integrated over the band's wavelength nodes.
    Band(BandPbrdf),
}

impl MaterialOptics {
    /// The pBRDF whose lobe directions are importance-sampled and whose σ sizes tables and
    /// solar-disc rules: the grey model, or the band model with the largest ρ_d (so that the
    /// cosine lobe covers every wavelength's diffuse part).
    pub fn sampling_pbrdf(&self) -> &Pbrdf {
        match self {
            MaterialOptics::Grey(pbrdf) => pbrdf,
            MaterialOptics::Band(band) => &band.models[band.sampling],
        }
    }

    /// The band model, `None` for a grey one.
    pub fn band(&self) -> Option<&BandPbrdf> {
        match self {
            MaterialOptics::Grey(_) => None,
            MaterialOptics::Band(band) => Some(band),
        }
    }
}

/// The pBRDF of one material at each wavelength node of a band.
#[derive(Clone, Debug)]
pub struct BandPbrdf {
    nodes: WavelengthNodes,
    /// The model at each node, in node order.
    models: Vec<Pbrdf>,
    /// Index of the model with the largest ρ_d ([`MaterialOptics::sampling_pbrdf`]).
    sampling: usize,
}

impl BandPbrdf {
    /// `models[m]` is the material at `nodes.wavelengths_um()[m]`; they must share the slope
    /// distribution and the shadowing.
    pub fn new(nodes: WavelengthNodes, models: Vec<Pbrdf>) -> Result<BandPbrdf, ModelError> {
        let first = models.first().ok_or(ModelError::BandModels)?;
        let shared = models.iter().all(|m| {
            m.distribution() == first.distribution() && m.shadowing() == first.shadowing()
        });
        if !shared || models.len() != nodes.len() {
            return Err(ModelError::BandModels);
        }
        let sampling = (0..models.len())
            .rev()
            .max_by(|&a, &b| models[a].rho_d().total_cmp(&models[b].rho_d()))
            .unwrap_or(0);
        Ok(BandPbrdf {
            nodes,
            models,
            sampling,
        })
    }

    pub fn nodes(&self) -> &WavelengthNodes {
        &self.nodes
    }

    /// The model at each wavelength node.
    pub fn models(&self) -> &[Pbrdf] {
        &self.models
    }

    /// [`Pbrdf::visit_specular_nodes`] of every model at once: `visit(ω_i, K)` with `K[m]` the
    /// Stokes weight of node ω_i for the model at wavelength node m. The nodes are those of each
    /// model's own quadrature (they depend on σ, q and the shadowing alone).
    pub fn visit_specular_nodes(
        &self,
        scattered: &Direction,
        quadrature: &HemisphereQuadrature,
        mut visit: impl FnMut(&Vector3<f64>, &[Stokes]),
    ) {
        let permittivities: Vec<_> = self.models.iter().map(Pbrdf::permittivity).collect();
        let mut weights = vec![Stokes::zeros(); self.models.len()];
        self.models[0].visit_specular_facets(scattered, quadrature, |w_i, facet| {
            for (weight, &permittivity) in weights.iter_mut().zip(&permittivities) {
                *weight = facet.stokes(permittivity);
            }
            visit(w_i, &weights)
        });
    }

    /// Σ_m f_m F(λ_m) (sr⁻¹) from `incident` to `scattered` for each set of shares f in `mixes`
    /// (each over the wavelength nodes, e.g. the Planck fractions of a source), with the
    /// per-direction shadowing factors supplied as in [`Pbrdf::mueller_with_masking`]. The
    /// geometry, facet density and shadowing are evaluated once, the Fresnel terms once per
    /// wavelength node. Zero below the horizon.
    pub fn mueller_mixtures<const N: usize>(
        &self,
        incident: &Direction,
        scattered: &Direction,
        masking: [f64; 2],
        mixes: [SpectralMix; N],
    ) -> [Mueller; N] {
        let Some(geometry) = ScatteringGeometry::new(incident, scattered) else {
            return [Mueller::zeros(); N];
        };
        let facet = geometry.facet();
        let shape = self.models[0].facet_shape(facet, masking);
        let mut fresnel = [[0.0f64; 4]; N];
        let mut diffuse = [0.0f64; N];
        for (m, model) in self.models.iter().enumerate() {
            let (rs2, rp2, cross, inverse) =
                FresnelFractions::from_cos2(facet.cos2_beta, model.permittivity())
                    .reflectances_and_cross_unnormalized();
            let scale = shape.scale(inverse);
            let elements = [
                0.5 * (rs2 + rp2) * scale,
                0.5 * (rs2 - rp2) * scale,
                cross.re * scale,
                cross.im * scale,
            ];
            for ((sum, d), mix) in fresnel.iter_mut().zip(&mut diffuse).zip(&mixes) {
                let f = mix.weight(m);
                for (s, e) in sum.iter_mut().zip(elements) {
                    *s += f * e;
                }
                *d += f * model.rho_d();
            }
        }
        std::array::from_fn(|i| geometry.assemble_mueller(fresnel[i], diffuse[i] * FRAC_1_PI))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::{Band, RefractiveIndex};
    use crate::pbrdf::{Shadowing, SlopeDistribution};

    fn band_of(indices: &[(f64, f64, f64)]) -> BandPbrdf {
        let table: Vec<f64> = (0..indices.len())
            .map(|i| 8.0 + 6.0 * i as f64 / (indices.len() - 1) as f64)
            .collect();
        let nodes = WavelengthNodes::for_table(&Band::lwir(), &table).unwrap();
        let models = (0..nodes.len())
            .map(|m| {
                let (n, k, rho) = indices[m * indices.len() / nodes.len()];
                Pbrdf::new(
                    SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
                    Shadowing::Smith,
                    RefractiveIndex::new(n, k),
                    rho,
                )
                .unwrap()
            })
            .collect();
        BandPbrdf::new(nodes, models).unwrap()
    }

    #[test]
    fn mixtures_are_the_weighted_sums_of_the_models() {
        let band = band_of(&[(1.4, 0.1, 0.0), (2.8, 1.3, 0.05), (0.6, 0.5, 0.02)]);
        let shares = band.nodes().planck_fractions(290.0);
        let incident = Direction::from_angles(0.5, 0.3);
        let scattered = Direction::from_angles(0.9, 2.9);
        let masking = |p: &Pbrdf| {
            [
                p.masking(incident.cos_theta()),
                p.masking(scattered.cos_theta()),
            ]
        };
        let [mixed] = band.mueller_mixtures(
            &incident,
            &scattered,
            masking(&band.models()[0]),
            [SpectralMix::fixed(&shares)],
        );
        let mut direct = Mueller::zeros();
        for (model, f) in band.models().iter().zip(&shares) {
            direct += model.mueller(&incident, &scattered) * *f;
        }
        assert!((mixed - direct).abs().max() < 1e-14 * direct.abs().max());
    }

    #[test]
    fn sampling_follows_the_largest_diffuse_part_and_models_must_share_geometry() {
        let band = band_of(&[(1.4, 0.1, 0.0), (2.8, 1.3, 0.05), (0.6, 0.5, 0.02)]);
        let optics = MaterialOptics::Band(band.clone());
        assert_eq!(optics.sampling_pbrdf().rho_d(), 0.05);
        let mut models = band.models().to_vec();
        models[1] = Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.3, q: 2.5 },
            Shadowing::Smith,
            RefractiveIndex::new(1.5, 0.0),
            0.0,
        )
        .unwrap();
        assert!(BandPbrdf::new(band.nodes().clone(), models).is_err());
    }
}
