//! The reflection integral of docs/design.md §1.5 as an explicit weighted sum, for the renderer's tables:
//!
//!   ∫ F_j0(ω_i→ω_r) L(ω_i) cosθ_i dΩ_i  ≈  Σ_k K_jk L(ω_k)   (specular part, j = 0, 1, 2)
//!   (ρ_d/π) ∫ L(ω_i) cosθ_i dΩ_i        ≈  Σ_m D_m L(ω_m)    (diffuse part)
//!
//! in the local frame (normal ẑ) with ω_r = (sinθ_r, 0, cosθ_r) and the Stokes vector in the psps
//! frame of ω_r. `Pbrdf::reflected_stokes` returns the sum for one environment; a table over
//! thousands of surface orientations needs the nodes and weights themselves, so that the pBRDF is
//! evaluated once per node instead of once per node and table entry (a Smith–Cauchy material costs
//! ~2 µs per evaluation and ~1000 nodes: 2 ms per entry, minutes per table).
//!
//! The nodes follow the same slope-space construction as `pbrdf::hemisphere` (the lobe is the
//! slope density; the horizon cut is exact in polar slope coordinates): ω_k is the mirror of ω_r
//! about the facet normal of slope (u, Δ), and with dΩ_i = 4 cosβ dΩ_h, dΩ_h = cos³θ_h d²m,
//!   K_jk = F_spec,j0(ω_k→ω_r) cosθ_k · 4 cosβ cos³θ_h · u du dΔ.
//! The physics (F_j0) comes from `Pbrdf::first_column`; only the node placement lives here.
//! Nodes closer than a fraction of a degree are then merged (weights summed at the weighted mean
//! direction), which is exact for an environment constant over the merged cell and shrinks a
//! narrow specular lobe from ~1000 nodes to a few dozen.

use crate::optics::Stokes;
use crate::pbrdf::{BandPbrdf, Direction, HemisphereQuadrature, Pbrdf};
use nalgebra::Vector3;
use std::collections::HashMap;

/// Node counts of the kernel quadrature (see [`KernelQuadrature::default`]).
#[derive(Clone, Debug)]
pub struct KernelQuadrature {
    /// Trapezoid nodes over a full circle of facet azimuths (half as many per cut arc).
    pub full_circle: usize,
    /// Gauss–Legendre nodes per radial slope panel.
    pub per_panel: usize,
    /// First radial panel width in units of the distribution's slope scale; later panels grow.
    pub first_panel: f64,
    pub growth: f64,
    /// Nodes whose directions fall in the same cube cell of this size (radians) are merged; the
    /// cells grow fourfold with every doubling of the angle from the specular direction beyond
    /// a few lobe widths, where the kernel is small and smooth.
    pub merge_cell: f64,
    /// The finely merged core around the specular direction holds the facets up to this
    /// quantile of the slope distribution (its mirror angle, at least 4 cells).
    pub merge_core: f64,
}

impl KernelQuadrature {
    /// The pBRDF hemisphere quadrature with these node counts.
    pub fn hemisphere(&self) -> HemisphereQuadrature {
        HemisphereQuadrature::new(
            self.full_circle,
            self.per_panel,
            self.first_panel,
            self.growth,
        )
    }
}

impl Default for KernelQuadrature {
    /// Within ~1e-4 of `reflected_stokes` with the default hemisphere quadrature for σ 0.03–0.5
    /// (tests/it/render_tables.rs); merging at 0.5° changes a smooth sky by < 1e-5.
    fn default() -> Self {
        KernelQuadrature {
            full_circle: 32,
            per_panel: 6,
            first_panel: 0.5,
            growth: 2.0,
            merge_cell: 0.5f64.to_radians(),
            merge_core: 0.9,
        }
    }
}

/// Specular nodes for one θ_r: directions ω_k (local frame, ω_r at azimuth 0) and Stokes weights.
#[derive(Clone, Debug, Default)]
pub struct SpecularKernel {
    pub directions: Vec<Vector3<f64>>,
    pub weights: Vec<[f64; 3]>,
}

impl SpecularKernel {
    /// Σ_k K_k L(ω_k) for an environment given in the local frame.
    pub fn apply(&self, environment: impl Fn(&Vector3<f64>) -> f64) -> Stokes {
        let mut sum = [0.0; 3];
        for (w, k) in self.directions.iter().zip(&self.weights) {
            let l = environment(w);
            sum[0] += k[0] * l;
            sum[1] += k[1] * l;
            sum[2] += k[2] * l;
        }
        Stokes::new(sum[0], sum[1], sum[2], 0.0)
    }

    /// Σ_k K_k: the specular directional-hemispherical reflectance (Stokes) of ω_r.
    pub fn total(&self) -> [f64; 3] {
        self.weights
            .iter()
            .fold([0.0; 3], |a, k| [a[0] + k[0], a[1] + k[1], a[2] + k[2]])
    }
}

/// The specular kernel of `pbrdf` for ω_r = (sinθ_r, 0, cosθ_r), 0 ≤ θ_r < π/2: the pBRDF's own
/// reflection quadrature nodes ([`Pbrdf::visit_specular_nodes`]) and, for a material with the
/// subsurface term, that term's nodes ([`Pbrdf::visit_subsurface_nodes`]: its reflection depends
/// on ω_i and turns with the scattering plane, so it is tabulated like the facet term, not like
/// the constant ρ_d/π of the diffuse table), merged by direction.
pub fn specular_kernel(
    pbrdf: &Pbrdf,
    theta_r: f64,
    quadrature: &KernelQuadrature,
) -> SpecularKernel {
    let scattered = Direction::from_angles(theta_r, 0.0);
    if scattered.cos_theta() <= 0.0 {
        return SpecularKernel::default();
    }
    let mut nodes = NodeMerger::new(pbrdf, theta_r, quadrature, 1);
    let hemisphere = quadrature.hemisphere();
    pbrdf.visit_specular_nodes(&scattered, &hemisphere, |w_i, k| {
        nodes.add(*w_i, k[0].abs(), &[[k[0], k[1], k[2]]])
    });
    let (mut directions, mut weights) = nodes.finish();
    pbrdf.visit_subsurface_nodes(&scattered, &hemisphere, 0.0, |w_i, k| {
        directions.push(*w_i);
        weights.push([k[0], k[1], k[2]]);
    });
    SpecularKernel {
        directions,
        weights,
    }
}

/// The specular kernels of every wavelength node of a band material at once (docs/design.md §1.9): the
/// nodes of each model's quadrature are the same directions ([`BandPbrdf::visit_specular_nodes`]),
/// merged once, each cell at its mean direction weighted by |K0| of the wavelength node
/// `merge_node` (the one carrying most of the environment's light). A material that does not
/// change with λ then merges exactly as its grey kernel (the same directions to the bit: a node
/// on the horizon must not change sides).
pub fn band_specular_kernel(
    band: &BandPbrdf,
    theta_r: f64,
    quadrature: &KernelQuadrature,
    merge_node: usize,
) -> BandKernel {
    let models = band.models().len();
    let scattered = Direction::from_angles(theta_r, 0.0);
    if scattered.cos_theta() <= 0.0 {
        return BandKernel {
            kernel: SpecularKernel::default(),
            models,
        };
    }
    let mut nodes = NodeMerger::new(&band.models()[0], theta_r, quadrature, models);
    let mut weights = vec![[0.0; 3]; models];
    band.visit_specular_nodes(&scattered, &quadrature.hemisphere(), |w_i, k| {
        for (slot, stokes) in weights.iter_mut().zip(k) {
            *slot = [stokes[0], stokes[1], stokes[2]];
        }
        nodes.add(*w_i, k[merge_node][0].abs(), &weights)
    });
    let (directions, weights) = nodes.finish();
    BandKernel {
        kernel: SpecularKernel {
            directions,
            weights,
        },
        models,
    }
}

/// The merged specular nodes of a band material at one θ_r: shared directions, a Stokes weight
/// per direction and wavelength node (`kernel.weights[k · models + m]`).
#[derive(Clone, Debug)]
pub struct BandKernel {
    kernel: SpecularKernel,
    models: usize,
}

impl BandKernel {
    pub fn directions(&self) -> &[Vector3<f64>] {
        &self.kernel.directions
    }

    /// Σ_k K_mk for each wavelength node m: the specular directional-hemispherical reflectance.
    pub fn totals(&self) -> Vec<[f64; 3]> {
        let mut totals = vec![[0.0; 3]; self.models];
        for node in self.kernel.weights.chunks(self.models) {
            for (total, k) in totals.iter_mut().zip(node) {
                for j in 0..3 {
                    total[j] += k[j];
                }
            }
        }
        totals
    }

    /// The weights Σ_m c_m K_mk of each direction for coefficients `c` over the wavelength nodes.
    pub fn combined(&self, coefficients: &[f64]) -> Vec<[f64; 3]> {
        self.kernel
            .weights
            .chunks(self.models)
            .map(|node| {
                let mut sum = [0.0; 3];
                for (k, c) in node.iter().zip(coefficients) {
                    for j in 0..3 {
                        sum[j] += c * k[j];
                    }
                }
                sum
            })
            .collect()
    }
}

/// Sums nodes falling in the same cube cell of the unit sphere. Within `core` radians of the
/// specular direction the cells are `cell` wide; beyond, level ℓ = ⌈log₂(α/core)⌉ cells are
/// 4^ℓ times wider: each doubling of the distance holds a few cells, whose weights fall off
/// with the slope density's tail. Each node carries `channels` Stokes weights (one per
/// wavelength node of a band material) and a mass that weights its direction.
struct NodeMerger {
    cell: f64,
    specular: Vector3<f64>,
    core: f64,
    channels: usize,
    index_of: HashMap<[i32; 4], usize>,
    /// Σ mass-weighted direction and Σ mass per merged node.
    sums: Vec<(Vector3<f64>, f64)>,
    /// Σ K per merged node and channel (`[node · channels + channel]`).
    weights: Vec<[f64; 3]>,
}

impl NodeMerger {
    /// The merger for ω_r at `theta_r` of a model with `pbrdf`'s slope distribution.
    fn new(
        pbrdf: &Pbrdf,
        theta_r: f64,
        quadrature: &KernelQuadrature,
        channels: usize,
    ) -> NodeMerger {
        let (sin_r, cos_r) = theta_r.sin_cos();
        let core_slope = pbrdf.distribution().slope_quantile(quadrature.merge_core);
        NodeMerger {
            cell: quadrature.merge_cell,
            specular: Vector3::new(-sin_r, 0.0, cos_r),
            core: (2.0 * core_slope.atan()).max(4.0 * quadrature.merge_cell),
            channels,
            index_of: HashMap::new(),
            sums: Vec::new(),
            weights: Vec::new(),
        }
    }

    fn add(&mut self, direction: Vector3<f64>, mass: f64, weights: &[[f64; 3]]) {
        let angle = direction.dot(&self.specular).clamp(-1.0, 1.0).acos();
        let level = if angle <= self.core {
            0
        } else {
            (angle / self.core).log2().ceil() as i32
        };
        let cell = self.cell * f64::powi(4.0, level);
        let key = direction.map(|c| (c / cell).floor() as i32);
        let key = [level, key.x, key.y, key.z];
        let channels = self.channels;
        let i = *self.index_of.entry(key).or_insert_with(|| {
            self.sums.push((Vector3::zeros(), 0.0));
            self.weights.extend(std::iter::repeat_n([0.0; 3], channels));
            self.sums.len() - 1
        });
        let entry = &mut self.sums[i];
        // mass + tiny keeps zero-weight nodes (fully shadowed) from producing a 0/0 direction.
        let mass = mass + 1e-300;
        entry.0 += direction * mass;
        entry.1 += mass;
        for (sum, w) in self.weights[i * channels..(i + 1) * channels]
            .iter_mut()
            .zip(weights)
        {
            for (s, v) in sum.iter_mut().zip(w) {
                *s += v;
            }
        }
    }

    /// The merged directions (mass-weighted means) and weights.
    fn finish(self) -> (Vec<Vector3<f64>>, Vec<[f64; 3]>) {
        let directions = self
            .sums
            .into_iter()
            .map(|(direction, mass)| (direction / mass).normalize())
            .collect();
        (directions, self.weights)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::RefractiveIndex;
    use crate::pbrdf::{Shadowing, SlopeDistribution};

    fn material(distribution: SlopeDistribution, shadowing: Shadowing, rho_d: f64) -> Pbrdf {
        Pbrdf::new(
            distribution,
            shadowing,
            RefractiveIndex::new(1.6, 0.1),
            rho_d,
        )
        .unwrap()
    }

    #[test]
    fn kernel_matches_the_pbrdf_reflection_integral() {
        // A smooth but anisotropic sky: brighter toward +x and the horizon.
        let env = |w: &Vector3<f64>| 10.0 + 3.0 * w.x + 5.0 * (1.0 - w.z).powi(2);
        let quadrature = KernelQuadrature::default();
        let reference = HemisphereQuadrature::fine();
        for (distribution, shadowing) in [
            (
                SlopeDistribution::Cauchy { sigma: 0.5, q: 2.0 },
                Shadowing::Smith,
            ),
            (
                SlopeDistribution::Cauchy {
                    sigma: 0.03,
                    q: 3.0,
                },
                Shadowing::Smith,
            ),
            (SlopeDistribution::Gaussian { sigma: 0.15 }, Shadowing::None),
            (
                SlopeDistribution::Gaussian { sigma: 0.1 },
                Shadowing::TorranceSparrow,
            ),
        ] {
            let pbrdf = material(distribution, shadowing, 0.0);
            for theta_deg in [0.0f64, 25.0, 60.0, 80.0] {
                let theta = theta_deg.to_radians();
                let ours = specular_kernel(&pbrdf, theta, &quadrature).apply(env);
                let exact =
                    pbrdf.reflected_stokes(&Direction::from_angles(theta, 0.0), env, &reference);
                // Torrance–Sparrow's min() kinks limit both quadratures to ~1e-4 at grazing.
                let relative = if shadowing == Shadowing::TorranceSparrow {
                    1e-3
                } else {
                    2e-4
                };
                let tolerance = relative * exact[0];
                for j in 0..3 {
                    assert!(
                        (ours[j] - exact[j]).abs() < tolerance,
                        "{distribution:?} {shadowing:?} θ={theta_deg}: S{j} {} vs {}",
                        ours[j],
                        exact[j]
                    );
                }
            }
        }
    }

    #[test]
    fn merging_shrinks_narrow_lobes_without_changing_the_result() {
        let smooth = material(
            SlopeDistribution::Gaussian { sigma: 0.03 },
            Shadowing::Smith,
            0.0,
        );
        let merged = KernelQuadrature {
            merge_cell: 1f64.to_radians(),
            ..KernelQuadrature::default()
        };
        let unmerged = KernelQuadrature {
            merge_cell: 1e-9,
            ..KernelQuadrature::default()
        };
        let a = specular_kernel(&smooth, 0.5, &merged);
        let b = specular_kernel(&smooth, 0.5, &unmerged);
        assert!(
            a.directions.len() * 3 < b.directions.len(),
            "{} vs {}",
            a.directions.len(),
            b.directions.len()
        );
        let env = |w: &Vector3<f64>| 10.0 + 3.0 * w.x + 5.0 * (1.0 - w.z).powi(2);
        let (sa, sb) = (a.apply(env), b.apply(env));
        assert!((sa - sb).norm() < 1e-4 * sb[0], "{sa:?} vs {sb:?}");
    }
}
