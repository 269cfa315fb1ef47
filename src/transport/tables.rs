//! Per-material lookup tables that make per-pixel shading cheap (docs/design.md §1.4–1.5):
//!
//! * emissivity ε_j(θ_r), 1-D;
//! * reflected environment R_j(tilt, θ_r, φ): the environment depends on world elevation only, so
//!   at a surface point it is fixed by the tilt of the normal from world up, and the reflection
//!   toward ω_r by θ_r and the azimuth φ of ω_r measured from the uphill direction;
//! * the diffuse term (ρ_d/π)∫L cosθ dΩ, which depends on the tilt alone.
//!
//! Both ε and R come from the same kernel ([`super::kernel`]), ε_j = δ_j0 − Σ K_j (Kirchhoff, docs/design.md
//! §1.4), and are interpolated linearly on the same θ_r grid, so an isothermal enclosure gives
//! S = (L_bb(T), 0, 0) to rounding, whatever the table resolution.
//!
//! The θ_r axis is uniform in v = θ_r + (1 − cos θ_r): steps toward grazing, where Fresnel
//! reflectance and polarization change fastest, are half those at the normal (θ_r also moves the
//! mirror direction across the sky, so it cannot be coarse anywhere).

use super::band_environment::BandEnvironment;
use super::kernel::{band_specular_kernel, specular_kernel, KernelQuadrature, SpecularKernel};
use crate::optics::Band;
use crate::pbrdf::{BandPbrdf, ModelError, Pbrdf};
use crate::scene::environment::{Environment, SineTable};
use nalgebra::Vector3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_1_PI, PI};

/// Largest emission/view angle tabulated; beyond it the table is clamped (silhouette pixels).
pub const THETA_MAX: f64 = 89.0 * PI / 180.0;

/// The θ_r table coordinate v = θ + (1 − cos θ), from cos θ.
#[inline]
pub fn theta_coordinate(cos_theta: f64) -> f64 {
    cos_theta.clamp(-1.0, 1.0).acos() + 1.0 - cos_theta
}

/// θ with θ + (1 − cos θ) = v (Newton; v is increasing and convex enough on [0, π/2]).
pub fn theta_of_coordinate(v: f64) -> f64 {
    let mut theta = v / 1.5;
    for _ in 0..30 {
        let step = (theta + 1.0 - theta.cos() - v) / (1.0 + theta.sin());
        theta -= step;
        if step.abs() < 1e-15 {
            break;
        }
    }
    theta
}

/// n equally spaced points from `start` to `end`.
#[derive(Clone, Copy, Debug)]
pub struct UniformGrid {
    start: f64,
    step: f64,
    n: usize,
}

impl UniformGrid {
    pub fn new(start: f64, end: f64, n: usize) -> UniformGrid {
        let n = n.max(2);
        UniformGrid {
            start,
            step: (end - start) / (n - 1) as f64,
            n,
        }
    }

    pub fn len(&self) -> usize {
        self.n
    }

    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    pub fn value(&self, i: usize) -> f64 {
        self.start + self.step * i as f64
    }

    /// Cell index i ∈ [0, n − 2] and fraction f ∈ [0, 1] of x, clamped to the grid.
    #[inline]
    pub fn locate(&self, x: f64) -> (usize, f64) {
        let t = ((x - self.start) / self.step).clamp(0.0, (self.n - 1) as f64);
        let i = (t as usize).min(self.n - 2);
        (i, t - i as f64)
    }
}

/// Grid sizes of the reflection table.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct TableResolution {
    pub tilt: usize,
    pub theta: usize,
    pub phi: usize,
    /// Kernel nodes closer than this (degrees) are merged; half the tilt/azimuth step, so that
    /// merging blurs less than the table interpolation does.
    pub merge_cell_deg: f64,
}

impl TableResolution {
    /// Finer grids for narrower lobes: the reflected environment changes over an angle ~ the
    /// lobe width, a few σ radians. Steps of 3° (σ ≤ 0.06) to 8° (σ ≥ 0.16) in tilt and azimuth;
    /// in θ_r 61 nodes (2.4° at the normal, 1.2° at grazing) for narrow lobes, 46 otherwise.
    pub fn for_material(pbrdf: &Pbrdf) -> TableResolution {
        let step_deg = (pbrdf.distribution().sigma() * 50.0).clamp(3.0, 8.0);
        TableResolution {
            tilt: (180.0 / step_deg).ceil() as usize + 1,
            theta: if step_deg < 4.0 { 61 } else { 46 },
            phi: (180.0 / step_deg).ceil() as usize + 1,
            merge_cell_deg: 0.5 * step_deg,
        }
    }

    pub fn entries(&self) -> usize {
        self.tilt * self.theta * self.phi
    }
}

#[derive(Clone, Debug)]
pub struct MaterialTables {
    /// Over v = θ_r + (1 − cos θ_r).
    theta: UniformGrid,
    tilt: UniformGrid,
    phi: UniformGrid,
    emission: Emission,
    /// Specular reflection (S0, S1, S2), index (tilt · n_θ + θ) · n_φ + φ.
    reflection: Vec<[f32; 3]>,
    diffuse_tilt: UniformGrid,
    diffuse: Vec<f64>,
    pub resolution: TableResolution,
}

/// (ε0, ε1) over the θ_r grid: one row for a grey material; for a band material the band
/// emissivity ε_band(θ, T) = Σ_m f_m(T) ε(λ_m, θ) (docs/design.md §1.9, f the Planck fractions, so that
/// ε_band L_bb(T) = Σ w_m ε(λ_m, θ) B_λm(T) to the band's own quadrature), one row per node of a
/// temperature grid over the scene's temperatures.
#[derive(Clone, Debug)]
enum Emission {
    Grey(Vec<[f64; 2]>),
    Band {
        temperature: UniformGrid,
        /// Index temperature · n_θ + θ.
        values: Vec<[f64; 2]>,
        /// ε(λ_m, θ_i) itself, index θ · nodes + m (what the path integrator needs to give
        /// light emitted here its spectrum, docs/design.md §1.9).
        per_node: Vec<[f64; 2]>,
    },
}

/// Temperature step (K) of a band material's emissivity table. ε_band(T) is slow (silicate glass:
/// d²ε0/dT² ≈ 1e-6 K⁻² at 250–350 K), so linear interpolation on 0.5 K errs by ~3e-8.
const EMISSION_TEMPERATURE_STEP_K: f64 = 0.5;
/// Largest number of temperature rows (a scene spanning 0–10 000 K gets 5 K steps).
const EMISSION_TEMPERATURE_ROWS: usize = 2001;

/// The grid of the emissivity and reflection tables over [`theta_coordinate`] v, from 0 to
/// [`THETA_MAX`]: emissivities are linear in v between its nodes.
pub fn theta_grid(resolution: &TableResolution) -> UniformGrid {
    UniformGrid::new(0.0, theta_coordinate(THETA_MAX.cos()), resolution.theta)
}

/// The θ_r, tilt and azimuth grids of a resolution.
fn table_grids(resolution: &TableResolution) -> (UniformGrid, UniformGrid, UniformGrid) {
    (
        theta_grid(resolution),
        UniformGrid::new(0.0, PI, resolution.tilt),
        UniformGrid::new(0.0, PI, resolution.phi),
    )
}

/// The kernel quadrature with the resolution's merge cell.
fn merged_quadrature(
    resolution: &TableResolution,
    quadrature: &KernelQuadrature,
) -> KernelQuadrature {
    KernelQuadrature {
        merge_cell: resolution.merge_cell_deg.to_radians(),
        ..quadrature.clone()
    }
}

/// The reflection kernel of one θ_r against each environment component: shared directions, one
/// weight per direction and component (`weights[k · components + c]`; one component for a grey
/// material).
struct ComponentKernel {
    directions: Vec<Vector3<f64>>,
    weights: Vec<[f64; 3]>,
}

impl ComponentKernel {
    /// The kernel of `directions` with `per_component[c][k]` the weight of direction k against
    /// component c.
    fn interleaved(directions: &[Vector3<f64>], per_component: &[Vec<[f64; 3]>]) -> Self {
        let weights = (0..directions.len())
            .flat_map(|k| per_component.iter().map(move |w| w[k]))
            .collect();
        ComponentKernel {
            directions: directions.to_vec(),
            weights,
        }
    }
}

/// Environment components c = 0… as functions of u = sin(elevation) on the same cells, each
/// cell's pieces side by side (`cells[i · components + c]`, as in [`SineTable::cells`]) so that a
/// lookup locates the cell once for all of them.
struct ComponentSkies {
    cells_per_unit: f64,
    components: usize,
    cells: Vec<[f64; 2]>,
}

impl ComponentSkies {
    /// `skies` must share their cells (one [`Environment::sine_table`] size).
    fn new(skies: &[&SineTable]) -> ComponentSkies {
        let count = skies[0].cells().len();
        ComponentSkies {
            cells_per_unit: skies[0].cells_per_unit,
            components: skies.len(),
            cells: (0..count)
                .flat_map(|i| skies.iter().map(move |sky| sky.cells()[i]))
                .collect(),
        }
    }

    /// Σ_c weights\[c\] · L_c(x) at cell coordinate x (clamped to the table), as
    /// [`SineTable::at_cell`] computes each L_c.
    #[inline]
    fn weighted_at_cell(&self, x: f64, weights: &[[f64; 3]], sum: &mut [f64; 3]) {
        let cells = self.cells.len() / self.components;
        let i = (x.max(0.0) as usize).min(cells - 1);
        let offset = x - i as f64;
        let pieces = &self.cells[i * self.components..(i + 1) * self.components];
        for ([a, rise], weight) in pieces.iter().zip(weights) {
            let l = a + rise * offset;
            sum[0] += weight[0] * l;
            sum[1] += weight[1] * l;
            sum[2] += weight[2] * l;
        }
    }
}

/// (ε0, ε1) = (1 − Σ K0 − diffuse albedo, −Σ K1) from a kernel's totals (Kirchhoff, docs/design.md §1.4),
/// refusing a reflectance above 1 at grid node `theta_index`.
fn kirchhoff_emissivity(
    total: [f64; 3],
    diffuse_albedo: f64,
    theta: &UniformGrid,
    theta_index: usize,
) -> Result<[f64; 2], ModelError> {
    let e0 = 1.0 - total[0] - diffuse_albedo;
    if e0 < -1e-9 {
        return Err(ModelError::ReflectanceAboveOne {
            theta_deg: theta_of_coordinate(theta.value(theta_index)).to_degrees(),
            reflectance: 1.0 - e0,
        });
    }
    Ok([e0, -total[1]])
}

impl MaterialTables {
    /// Builds the tables of one grey material in one environment. Refuses a material whose
    /// directional-hemispherical reflectance exceeds 1 at some tabulated angle (docs/design.md §1.4).
    pub fn build(
        pbrdf: &Pbrdf,
        environment: &Environment,
        resolution: TableResolution,
        quadrature: &KernelQuadrature,
    ) -> Result<MaterialTables, ModelError> {
        let (theta, tilt, phi) = table_grids(&resolution);
        let quadrature = merged_quadrature(&resolution, quadrature);
        let kernels: Vec<SpecularKernel> = (0..theta.len())
            .into_par_iter()
            .map(|i| specular_kernel(pbrdf, theta_of_coordinate(theta.value(i)), &quadrature))
            .collect();
        let diffuse_rule = quadrature.hemisphere();
        let diffuse_rule = diffuse_rule.cosine_weighted_nodes();
        let rho_over_pi = pbrdf.rho_d() * FRAC_1_PI;
        let diffuse_albedo = rho_over_pi * diffuse_rule.iter().map(|(_, w)| w).sum::<f64>();
        let emissivity = kernels
            .iter()
            .enumerate()
            .map(|(i, kernel)| kirchhoff_emissivity(kernel.total(), diffuse_albedo, &theta, i))
            .collect::<Result<Vec<_>, _>>()?;
        // 1024 cells (16 KiB) stay in L1; the window sky is smooth enough for Δu = 1/512.
        let sky = environment.sine_table(1024);
        let kernels: Vec<ComponentKernel> = kernels
            .into_iter()
            .map(|k| ComponentKernel {
                directions: k.directions,
                weights: k.weights,
            })
            .collect();
        let reflection =
            fill_reflection(&tilt, &theta, &phi, &kernels, &ComponentSkies::new(&[&sky]));
        let diffuse = diffuse_table(
            diffuse_rule,
            &[(rho_over_pi, &|u| environment.radiance_at_sine(u))],
        );
        Ok(MaterialTables {
            theta,
            tilt,
            phi,
            emission: Emission::Grey(emissivity),
            reflection,
            diffuse_tilt: UniformGrid::new(0.0, PI, DIFFUSE_TILTS),
            diffuse,
            resolution,
        })
    }

    /// Builds the tables of a band material (docs/design.md §1.9) for scene temperatures within
    /// `temperatures_k` (min, max): the band emissivity over θ_r and temperature, and the
    /// reflection of the environment split over the wavelength nodes ([`BandEnvironment`]).
    /// Refuses a model whose reflectance exceeds 1 at some angle and wavelength node.
    pub fn build_band(
        material: &BandPbrdf,
        environment: &Environment,
        band: &Band,
        temperatures_k: (f64, f64),
        resolution: TableResolution,
        quadrature: &KernelQuadrature,
    ) -> Result<MaterialTables, ModelError> {
        let (theta, tilt, phi) = table_grids(&resolution);
        let quadrature = merged_quadrature(&resolution, quadrature);
        let sky = environment.sine_table(1024);
        let split = BandEnvironment::new(&sky, band, material.nodes());
        let merge_node = split.brightest_node();
        let kernels: Vec<(ComponentKernel, Vec<[f64; 3]>)> = (0..theta.len())
            .into_par_iter()
            .map(|i| {
                let theta_r = theta_of_coordinate(theta.value(i));
                let kernel = band_specular_kernel(material, theta_r, &quadrature, merge_node);
                let per_component: Vec<Vec<[f64; 3]>> = std::iter::once(&split.mean_shares)
                    .chain(split.components.iter().map(|c| &c.shares))
                    .map(|shares| kernel.combined(shares))
                    .collect();
                (
                    ComponentKernel::interleaved(kernel.directions(), &per_component),
                    kernel.totals(),
                )
            })
            .collect();
        let diffuse_rule = quadrature.hemisphere();
        let diffuse_rule = diffuse_rule.cosine_weighted_nodes();
        let emission = band_emission(material, &kernels, diffuse_rule, &theta, temperatures_k)?;
        let kernels: Vec<ComponentKernel> = kernels.into_iter().map(|(k, _)| k).collect();
        let skies: Vec<&SineTable> = std::iter::once(&sky)
            .chain(split.components.iter().map(|c| &c.sky))
            .collect();
        let reflection =
            fill_reflection(&tilt, &theta, &phi, &kernels, &ComponentSkies::new(&skies));
        let rho = split.project(|m| material.models()[m].rho_d());
        let grey_environment = |u: f64| environment.radiance_at_sine(u);
        let mut lookups: Vec<(f64, &dyn Fn(f64) -> f64)> =
            vec![(rho[0] * FRAC_1_PI, &grey_environment)];
        let component_lookups: Vec<_> = split
            .components
            .iter()
            .map(|c| move |u: f64| c.sky.radiance(u))
            .collect();
        for (r, lookup) in rho[1..].iter().zip(&component_lookups) {
            lookups.push((r * FRAC_1_PI, lookup));
        }
        let diffuse = diffuse_table(diffuse_rule, &lookups);
        Ok(MaterialTables {
            theta,
            tilt,
            phi,
            emission,
            reflection,
            diffuse_tilt: UniformGrid::new(0.0, PI, DIFFUSE_TILTS),
            diffuse,
            resolution,
        })
    }

    /// (ε0, ε1) at emission angle θ, given as cos θ (psps frame; ε2 = ε3 = 0 for isotropic
    /// surfaces). Angles beyond [`THETA_MAX`] read the last node. A band material's emissivity
    /// depends on the temperature too ([`MaterialTables::emissivity_at`]): this is its value at
    /// the coldest tabulated temperature.
    #[inline]
    pub fn emissivity(&self, cos_theta: f64) -> [f64; 2] {
        let coldest = match &self.emission {
            Emission::Grey(_) => 0.0,
            Emission::Band { temperature, .. } => temperature.value(0),
        };
        self.emissivity_at(cos_theta, coldest)
    }

    /// (ε0, ε1) at emission angle θ (given as cos θ) of a surface at `temperature`: a grey
    /// material's does not depend on it, a band material's is its band emissivity (docs/design.md §1.9).
    #[inline]
    pub fn emissivity_at(&self, cos_theta: f64, temperature: f64) -> [f64; 2] {
        let (i, f) = self.theta.locate(theta_coordinate(cos_theta));
        match &self.emission {
            Emission::Grey(values) => {
                let (a, b) = (values[i], values[i + 1]);
                [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
            }
            Emission::Band {
                temperature: grid,
                values,
                ..
            } => {
                let (g, h) = grid.locate(temperature);
                let n = self.theta.len();
                let mut out = [0.0; 2];
                for (row, w) in [(g, 1.0 - h), (g + 1, h)] {
                    let (a, b) = (values[row * n + i], values[row * n + i + 1]);
                    for j in 0..2 {
                        out[j] += w * (a[j] + f * (b[j] - a[j]));
                    }
                }
                out
            }
        }
    }

    /// A band material's (ε0, ε1) at each of its wavelength nodes at emission angle θ (given as
    /// cos θ, linear in the table coordinate as [`MaterialTables::emissivity`]); `None` for a grey
    /// material.
    pub fn node_emissivities(&self, cos_theta: f64) -> Option<Vec<[f64; 2]>> {
        let Emission::Band { per_node, .. } = &self.emission else {
            return None;
        };
        let (i, f) = self.theta.locate(theta_coordinate(cos_theta));
        let nodes = per_node.len() / self.theta.len();
        let (a, b) = (
            &per_node[i * nodes..(i + 1) * nodes],
            &per_node[(i + 1) * nodes..(i + 2) * nodes],
        );
        Some(
            a.iter()
                .zip(b)
                .map(|(a, b)| [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])])
                .collect(),
        )
    }

    /// Reflected environment (S0, S1, S2) toward ω_r in its psps frame, for a normal tilted by
    /// `tilt` from world up and ω_r at zenith θ (given as cos θ) and azimuth `phi` ∈ [−π, π] from
    /// uphill. Mirror symmetry about the plane of the normal and world up: R2(−φ) = −R2(φ).
    #[inline]
    pub fn reflected(&self, tilt: f64, cos_theta: f64, phi: f64) -> [f64; 3] {
        let sign = if phi < 0.0 { -1.0 } else { 1.0 };
        let (ti, tf) = self.tilt.locate(tilt);
        let (ki, kf) = self.theta.locate(theta_coordinate(cos_theta));
        let (pi, pf) = self.phi.locate(phi.abs());
        let (n_theta, n_phi) = (self.theta.len(), self.phi.len());
        let mut out = [0.0f64; 3];
        for (dt, wt) in [(0, 1.0 - tf), (1, tf)] {
            for (dk, wk) in [(0, 1.0 - kf), (1, kf)] {
                let row = ((ti + dt) * n_theta + ki + dk) * n_phi + pi;
                let (a, b) = (&self.reflection[row], &self.reflection[row + 1]);
                let w = wt * wk;
                for j in 0..3 {
                    out[j] += w * ((1.0 - pf) * a[j] as f64 + pf * b[j] as f64);
                }
            }
        }
        let (di, df) = self.diffuse_tilt.locate(tilt);
        out[0] += self.diffuse[di] + df * (self.diffuse[di + 1] - self.diffuse[di]);
        out[2] *= sign;
        out
    }
}

/// Tilts of the diffuse table over [0, π].
const DIFFUSE_TILTS: usize = 181;

/// The band emissivity rows of a band material (see [`Emission`]): ε(λ_m, θ_i) from each
/// wavelength node's kernel totals and diffuse albedo, weighted by the Planck fractions at every
/// node of a temperature grid over `temperatures_k`.
fn band_emission(
    material: &BandPbrdf,
    kernels: &[(ComponentKernel, Vec<[f64; 3]>)],
    diffuse_rule: &[(Vector3<f64>, f64)],
    theta: &UniformGrid,
    temperatures_k: (f64, f64),
) -> Result<Emission, ModelError> {
    let rule_weight: f64 = diffuse_rule.iter().map(|(_, w)| w).sum();
    let wavelengths = material.nodes().wavelengths_um();
    // per_node[m][i] = (ε0, ε1) of wavelength node m at θ node i.
    let per_node = material
        .models()
        .iter()
        .enumerate()
        .map(|(m, model)| {
            let albedo = model.rho_d() * FRAC_1_PI * rule_weight;
            kernels
                .iter()
                .enumerate()
                .map(|(i, (_, totals))| kirchhoff_emissivity(totals[m], albedo, theta, i))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|source| ModelError::AtWavelength {
                    wavelength_um: wavelengths[m],
                    source: Box::new(source),
                })
        })
        .collect::<Result<Vec<_>, _>>()?;
    let (lo, hi) = (
        temperatures_k.0.min(temperatures_k.1),
        temperatures_k.0.max(temperatures_k.1),
    );
    let hi = hi + 1e-6;
    let rows = (((hi - lo) / EMISSION_TEMPERATURE_STEP_K).ceil() as usize + 1)
        .clamp(2, EMISSION_TEMPERATURE_ROWS);
    let temperature = UniformGrid::new(lo, hi, rows);
    let values = (0..rows)
        .flat_map(|g| {
            let shares = material.nodes().planck_fractions(temperature.value(g));
            let per_node = &per_node;
            (0..theta.len()).map(move |i| {
                let mut sum = [0.0; 2];
                for (f, e) in shares.iter().zip(per_node) {
                    sum[0] += f * e[i][0];
                    sum[1] += f * e[i][1];
                }
                sum
            })
        })
        .collect();
    let per_node = (0..theta.len())
        .flat_map(|i| per_node.iter().map(move |e| e[i]))
        .collect();
    Ok(Emission::Band {
        temperature,
        values,
        per_node,
    })
}

/// The specular reflection table: for every (tilt, θ_r, φ) entry, Σ_k Σ_c K^c_k L_c(u_k) over
/// the kernel's directions k and the environment components c, summed in f64 and stored as f32.
fn fill_reflection(
    tilt: &UniformGrid,
    theta: &UniformGrid,
    phi: &UniformGrid,
    kernels: &[ComponentKernel],
    skies: &ComponentSkies,
) -> Vec<[f32; 3]> {
    let (n_theta, n_phi) = (theta.len(), phi.len());
    let scale = skies.cells_per_unit;
    let trig: Vec<(f64, f64)> = (0..n_phi).map(|p| phi.value(p).sin_cos()).collect();
    let mut reflection = vec![[0f32; 3]; tilt.len() * n_theta * n_phi];
    reflection
        .par_chunks_mut(n_phi)
        .enumerate()
        .for_each(|(row, out)| {
            let (t, k) = (row / n_theta, row % n_theta);
            let (sin_t, cos_t) = tilt.value(t).sin_cos();
            let kernel = &kernels[k];
            // ω_r sits at azimuth 0 in the kernel frame and at φ from uphill, so uphill is
            // at azimuth −φ: up = (sin t cos φ, −sin t sin φ, cos t), and for each node
            // u = ω·up = z cos t + x sin t cos φ − y sin t sin φ, here in table cells.
            let projections: Vec<[f64; 3]> = kernel
                .directions
                .iter()
                .map(|w| {
                    [
                        (w.z * cos_t + 1.0) * scale,
                        w.x * sin_t * scale,
                        -w.y * sin_t * scale,
                    ]
                })
                .collect();
            let weights = kernel.weights.chunks(skies.components);
            for (slot, &(sin_p, cos_p)) in out.iter_mut().zip(&trig) {
                let mut sum = [0f64; 3];
                for ([a, b, c], weight) in projections.iter().zip(weights.clone()) {
                    skies.weighted_at_cell(a + b * cos_p + c * sin_p, weight, &mut sum);
                }
                *slot = sum.map(|v| v as f32);
            }
        });
    reflection
}

/// The diffuse term (ρ_d/π) ∫ L cosθ dΩ over [`DIFFUSE_TILTS`] tilts of the normal from world
/// up, as Σ_c (ρ_c/π) Σ_n w_n L_c(ω_n·up) over environment components c given as
/// (ρ_c/π, L_c(u)); components with ρ_c = 0 are skipped.
fn diffuse_table(
    rule: &[(Vector3<f64>, f64)],
    components: &[(f64, &dyn Fn(f64) -> f64)],
) -> Vec<f64> {
    let tilts = UniformGrid::new(0.0, PI, DIFFUSE_TILTS);
    (0..tilts.len())
        .map(|t| {
            let (sin_t, cos_t) = tilts.value(t).sin_cos();
            let up = Vector3::new(sin_t, 0.0, cos_t);
            let mut total = None;
            for &(rho_over_pi, radiance) in components {
                if rho_over_pi == 0.0 {
                    continue;
                }
                let term = rho_over_pi
                    * rule
                        .iter()
                        .map(|(w, weight)| weight * radiance(w.dot(&up)))
                        .sum::<f64>();
                total = Some(total.map_or(term, |sum: f64| sum + term));
            }
            total.unwrap_or(0.0)
        })
        .collect()
}

/// Band radiance L_bb(T) tabulated on a fine temperature grid (`Band::radiance` is a 96-point
/// spectral quadrature, ~µs; per pixel it would dominate). Linear interpolation on 0.05 K steps
/// is within ~1e-7 relative around 300 K.
#[derive(Clone, Debug)]
pub struct RadianceTable {
    grid: UniformGrid,
    values: Vec<f64>,
}

impl RadianceTable {
    pub fn new(band: &Band, t_min: f64, t_max: f64) -> RadianceTable {
        let (lo, hi) = (t_min.min(t_max), t_max.max(t_min) + 1e-6);
        let n = (((hi - lo) / 0.05).ceil() as usize + 1).clamp(2, 20_001);
        let grid = UniformGrid::new(lo, hi, n);
        let values = (0..n).map(|i| band.radiance(grid.value(i))).collect();
        RadianceTable { grid, values }
    }

    #[inline]
    pub fn radiance(&self, temperature: f64) -> f64 {
        let (i, f) = self.grid.locate(temperature);
        self.values[i] + f * (self.values[i + 1] - self.values[i])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::optics::RefractiveIndex;
    use crate::pbrdf::{Shadowing, SlopeDistribution};

    #[test]
    fn grid_locates_and_clamps() {
        let g = UniformGrid::new(0.0, 1.0, 11);
        let (i, f) = g.locate(0.25);
        assert_eq!(i, 2);
        assert!((f - 0.5).abs() < 1e-12);
        assert_eq!(g.locate(-1.0), (0, 0.0));
        let (i, f) = g.locate(2.0);
        assert_eq!((i, f), (9, 1.0));
    }

    #[test]
    fn theta_coordinate_inverts() {
        for theta in [0.0f64, 0.1, 0.7, 1.2, THETA_MAX] {
            let back = theta_of_coordinate(theta_coordinate(theta.cos()));
            assert!((back - theta).abs() < 1e-12, "{theta}");
        }
    }

    #[test]
    fn radiance_table_matches_the_band() {
        let band = Band::lwir();
        let table = RadianceTable::new(&band, 250.0, 330.0);
        for t in [250.0, 271.234, 300.01, 329.99] {
            let exact = band.radiance(t);
            assert!((table.radiance(t) - exact).abs() < 1e-6 * exact, "{t}");
        }
    }

    #[test]
    fn isothermal_environment_cancels_emission_at_any_orientation() {
        let band = Band::lwir();
        let l = band.radiance(300.0);
        let env = Environment::uniform(l);
        let pbrdf = Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.3, q: 2.5 },
            Shadowing::Smith,
            RefractiveIndex::new(1.5, 0.2),
            0.1,
        )
        .unwrap();
        let resolution = TableResolution {
            tilt: 7,
            theta: 12,
            phi: 5,
            merge_cell_deg: 1.0,
        };
        let tables =
            MaterialTables::build(&pbrdf, &env, resolution, &KernelQuadrature::default()).unwrap();
        for (tilt, theta, phi) in [(0.3, 0.2f64, 1.0), (2.0, 1.3, -2.5), (1.1, 1.5, 0.0)] {
            let e = tables.emissivity(theta.cos());
            let r = tables.reflected(tilt, theta.cos(), phi);
            assert!((e[0] * l + r[0] - l).abs() < 1e-6 * l);
            assert!((e[1] * l + r[1]).abs() < 1e-6 * l);
            assert!(r[2].abs() < 1e-6 * l);
        }
    }

    /// The shipped silicate glass (nine nodes across its reststrahlen band) over 8–14 µm.
    fn silicate(band: &Band) -> BandPbrdf {
        let model = crate::material::SpectralModel {
            distribution: SlopeDistribution::Cauchy {
                sigma: 0.06,
                q: 2.8,
            },
            shadowing: Shadowing::Smith,
            wavelength_um: vec![8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0],
            n: vec![
                0.517774, 0.588464, 1.36346, 2.87319, 2.62133, 2.30722, 2.08423, 1.96574, 1.87624,
            ],
            k: vec![
                0.543731, 1.2793, 2.12223, 1.38554, 0.477271, 0.210027, 0.100204, 0.0596999,
                0.0359674,
            ],
            rho_d: vec![0.0; 9],
            volume: Default::default(),
            dispersion: None,
        };
        model.band_pbrdf(band).unwrap()
    }

    fn window_sky(band: &Band) -> Environment {
        let config: crate::scene::config::EnvironmentConfig = toml::from_str(
            "air_temperature_k = 283.15\nsky = { model = \"window\", zenith_emissivity = 0.75 }\n\
             ground = { temperature_k = 288.0, emissivity = 0.95 }\n",
        )
        .unwrap();
        Environment::new(&config, band).unwrap()
    }

    /// The reflection table as docs/design.md §1.9 writes it: one fill per wavelength node m with the
    /// environment L(u) f_m(T_b(u)), summed (the split of `BandEnvironment` is checked against it).
    fn reflection_node_by_node(
        material: &BandPbrdf,
        environment: &Environment,
        band: &Band,
        resolution: TableResolution,
    ) -> Vec<[f32; 3]> {
        let (theta, tilt, phi) = table_grids(&resolution);
        let quadrature = merged_quadrature(&resolution, &KernelQuadrature::default());
        let sky = environment.sine_table(1024);
        let merge_node = BandEnvironment::new(&sky, band, material.nodes()).brightest_node();
        let nodes = material.nodes().len();
        let split = |l: f64| {
            let f = material
                .nodes()
                .planck_fractions(band.brightness_temperature(l).unwrap());
            f.iter().map(|f| l * f).collect::<Vec<_>>()
        };
        let ends: Vec<(Vec<f64>, Vec<f64>)> = sky
            .cells()
            .iter()
            .map(|&[a, rise]| (split(a), split(a + rise)))
            .collect();
        let at_node = |m: usize| {
            let cells = ends.iter().map(|(a, b)| [a[m], b[m] - a[m]]).collect();
            SineTable::from_cells(cells)
        };
        let skies: Vec<SineTable> = (0..nodes).map(at_node).collect();
        let kernels: Vec<ComponentKernel> = (0..theta.len())
            .map(|i| {
                let kernel = band_specular_kernel(
                    material,
                    theta_of_coordinate(theta.value(i)),
                    &quadrature,
                    merge_node,
                );
                let unit = |m: usize| {
                    (0..nodes)
                        .map(|j| if j == m { 1.0 } else { 0.0 })
                        .collect::<Vec<_>>()
                };
                let per_node: Vec<_> = (0..nodes).map(|m| kernel.combined(&unit(m))).collect();
                ComponentKernel::interleaved(kernel.directions(), &per_node)
            })
            .collect();
        let skies: Vec<&SineTable> = skies.iter().collect();
        fill_reflection(&tilt, &theta, &phi, &kernels, &ComponentSkies::new(&skies))
    }

    #[test]
    fn band_reflection_matches_one_fill_per_wavelength_node() {
        let band = Band::lwir();
        let material = silicate(&band);
        let environment = window_sky(&band);
        let resolution = TableResolution {
            tilt: 13,
            theta: 16,
            phi: 13,
            merge_cell_deg: 1.5,
        };
        let tables = MaterialTables::build_band(
            &material,
            &environment,
            &band,
            (290.0, 290.0),
            resolution,
            &KernelQuadrature::default(),
        )
        .unwrap();
        let exact = reflection_node_by_node(&material, &environment, &band, resolution);
        let largest = exact.iter().map(|e| e[0]).fold(0.0f32, f32::max) as f64;
        let worst = tables
            .reflection
            .iter()
            .zip(&exact)
            .flat_map(|(a, b)| (0..3).map(move |j| (a[j] as f64 - b[j] as f64).abs()))
            .fold(0.0, f64::max);
        eprintln!(
            "band reflection vs node by node: {:.2e} of the largest entry",
            worst / largest
        );
        assert!(worst < 1e-5 * largest, "{worst} vs {largest}");
    }

    #[test]
    fn a_band_material_that_does_not_change_with_wavelength_has_its_grey_tables() {
        let band = Band::lwir();
        let grey = Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.1, q: 2.5 },
            Shadowing::Smith,
            RefractiveIndex::new(1.6, 0.4),
            0.05,
        )
        .unwrap();
        let nodes =
            crate::optics::WavelengthNodes::for_table(&band, &[7.0, 9.0, 12.0, 15.0]).unwrap();
        let flat = BandPbrdf::new(nodes.clone(), vec![grey.clone(); nodes.len()]).unwrap();
        let environment = window_sky(&band);
        let resolution = TableResolution {
            tilt: 9,
            theta: 16,
            phi: 9,
            merge_cell_deg: 2.0,
        };
        let quadrature = KernelQuadrature::default();
        let a = MaterialTables::build(&grey, &environment, resolution, &quadrature).unwrap();
        let b = MaterialTables::build_band(
            &flat,
            &environment,
            &band,
            (280.0, 300.0),
            resolution,
            &quadrature,
        )
        .unwrap();
        for cos_theta in [1.0, 0.7, 0.2, 0.01] {
            let (e_grey, e_band) = (a.emissivity(cos_theta), b.emissivity_at(cos_theta, 291.3));
            for j in 0..2 {
                assert!((e_grey[j] - e_band[j]).abs() < 1e-15, "{cos_theta} ε{j}");
            }
        }
        for (x, y) in a.diffuse.iter().zip(&b.diffuse) {
            assert!((x - y).abs() <= 1e-14 * x.abs(), "{x} vs {y}");
        }
        // The f32 entries agree but where the f64 sums, equal to ~1e-16, round differently.
        for (x, y) in a.reflection.iter().zip(&b.reflection) {
            for j in 0..3 {
                assert!(
                    (x[j] - y[j]).abs() <= f32::EPSILON * x[0].abs(),
                    "{x:?} vs {y:?}"
                );
            }
        }
    }

    #[test]
    fn band_emissivity_interpolates_in_temperature_to_1e_7() {
        let band = Band::lwir();
        let material = silicate(&band);
        let resolution = TableResolution {
            tilt: 3,
            theta: 16,
            phi: 3,
            merge_cell_deg: 1.5,
        };
        let tables = MaterialTables::build_band(
            &material,
            &window_sky(&band),
            &band,
            (250.0, 350.0),
            resolution,
            &KernelQuadrature::default(),
        )
        .unwrap();
        for t in [250.0, 250.26, 287.3, 349.9] {
            let shares = material.nodes().planck_fractions(t);
            for cos_theta in [1.0, 0.5, 0.1] {
                let per_node = tables.node_emissivities(cos_theta).unwrap();
                let exact = per_node
                    .iter()
                    .zip(&shares)
                    .fold([0.0; 2], |s, (e, f)| [s[0] + f * e[0], s[1] + f * e[1]]);
                let table = tables.emissivity_at(cos_theta, t);
                for j in 0..2 {
                    assert!((table[j] - exact[j]).abs() < 1e-7, "{t} K {cos_theta}: {j}");
                }
            }
        }
    }

    #[test]
    fn energy_non_conserving_materials_are_refused() {
        let env = Environment::uniform(1.0);
        let pbrdf = Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.8, q: 1.6 },
            Shadowing::None,
            RefractiveIndex::new(1.5, 0.0),
            0.0,
        )
        .unwrap();
        let resolution = TableResolution {
            tilt: 3,
            theta: 46,
            phi: 3,
            merge_cell_deg: 1.0,
        };
        let err = MaterialTables::build(&pbrdf, &env, resolution, &KernelQuadrature::default())
            .unwrap_err();
        assert!(
            matches!(err, ModelError::ReflectanceAboveOne { .. }),
            "{err}"
        );
    }
}
