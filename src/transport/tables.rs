//! Per-material lookup tables that make per-pixel shading cheap (DESIGN §1.4–1.5):
//!
//! * emissivity ε_j(θ_r), 1-D;
//! * reflected environment R_j(tilt, θ_r, φ): the environment depends on world elevation only, so
//!   at a surface point it is fixed by the tilt of the normal from world up, and the reflection
//!   toward ω_r by θ_r and the azimuth φ of ω_r measured from the uphill direction;
//! * the diffuse term (ρ_d/π)∫L cosθ dΩ, which depends on the tilt alone.
//!
//! Both ε and R come from the same kernel ([`super::kernel`]), ε_j = δ_j0 − Σ K_j (Kirchhoff, DESIGN
//! §1.4), and are interpolated linearly on the same θ_r grid, so an isothermal enclosure gives
//! S = (L_bb(T), 0, 0) to rounding, whatever the table resolution.
//!
//! The θ_r axis is uniform in v = θ_r + (1 − cos θ_r): steps toward grazing, where Fresnel
//! reflectance and polarization change fastest, are half those at the normal (θ_r also moves the
//! mirror direction across the sky, so it cannot be coarse anywhere).

use super::kernel::{specular_kernel, KernelQuadrature, SpecularKernel};
use crate::optics::Band;
use crate::pbrdf::{ModelError, Pbrdf};
use crate::scene::environment::Environment;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::f64::consts::{FRAC_1_PI, PI};

/// Largest emission/view angle tabulated; beyond it the table is clamped (silhouette pixels).
pub const THETA_MAX: f64 = 89.0 * PI / 180.0;

/// The θ_r table coordinate v = θ + (1 − cos θ), from cos θ.
#[inline]
fn theta_coordinate(cos_theta: f64) -> f64 {
    cos_theta.clamp(-1.0, 1.0).acos() + 1.0 - cos_theta
}

/// θ with θ + (1 − cos θ) = v (Newton; v is increasing and convex enough on [0, π/2]).
fn theta_of_coordinate(v: f64) -> f64 {
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
    /// (ε0, ε1) at each θ_r node.
    emissivity: Vec<[f64; 2]>,
    /// Specular reflection (S0, S1, S2), index (tilt · n_θ + θ) · n_φ + φ.
    reflection: Vec<[f32; 3]>,
    diffuse_tilt: UniformGrid,
    diffuse: Vec<f64>,
    pub resolution: TableResolution,
}

impl MaterialTables {
    /// Builds the tables of one material in one environment. Refuses a material whose
    /// directional-hemispherical reflectance exceeds 1 at some tabulated angle (DESIGN §1.4).
    pub fn build(
        pbrdf: &Pbrdf,
        environment: &Environment,
        resolution: TableResolution,
        quadrature: &KernelQuadrature,
    ) -> Result<MaterialTables, ModelError> {
        let theta = UniformGrid::new(0.0, theta_coordinate(THETA_MAX.cos()), resolution.theta);
        let tilt = UniformGrid::new(0.0, PI, resolution.tilt);
        let phi = UniformGrid::new(0.0, PI, resolution.phi);
        let quadrature = KernelQuadrature {
            merge_cell: resolution.merge_cell_deg.to_radians(),
            ..quadrature.clone()
        };
        let kernels: Vec<SpecularKernel> = (0..theta.len())
            .into_par_iter()
            .map(|i| specular_kernel(pbrdf, theta_of_coordinate(theta.value(i)), &quadrature))
            .collect();

        let hemisphere = quadrature.hemisphere();
        let diffuse_rule = hemisphere.cosine_weighted_nodes();
        let rho_over_pi = pbrdf.rho_d() * FRAC_1_PI;
        let diffuse_albedo = rho_over_pi * diffuse_rule.iter().map(|(_, w)| w).sum::<f64>();
        let emissivity = kernels
            .iter()
            .enumerate()
            .map(|(i, kernel)| {
                let total = kernel.total();
                let e0 = 1.0 - total[0] - diffuse_albedo;
                if e0 < -1e-9 {
                    return Err(ModelError::ReflectanceAboveOne {
                        theta_deg: theta_of_coordinate(theta.value(i)).to_degrees(),
                        reflectance: 1.0 - e0,
                    });
                }
                Ok([e0, -total[1]])
            })
            .collect::<Result<Vec<_>, _>>()?;

        let (n_theta, n_phi) = (theta.len(), phi.len());
        // 1024 cells (16 KiB) stay in L1; the window sky is smooth enough for Δu = 1/512.
        let sky = environment.sine_table(1024);
        let scale = sky.cells_per_unit;
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
                for (slot, &(sin_p, cos_p)) in out.iter_mut().zip(&trig) {
                    let mut sum = [0f64; 3];
                    for ([a, b, c], weight) in projections.iter().zip(&kernel.weights) {
                        let l = sky.at_cell(a + b * cos_p + c * sin_p);
                        sum[0] += weight[0] * l;
                        sum[1] += weight[1] * l;
                        sum[2] += weight[2] * l;
                    }
                    *slot = sum.map(|v| v as f32);
                }
            });

        let diffuse_tilt = UniformGrid::new(0.0, PI, 181);
        let diffuse = (0..diffuse_tilt.len())
            .map(|t| {
                if rho_over_pi == 0.0 {
                    return 0.0;
                }
                let (sin_t, cos_t) = diffuse_tilt.value(t).sin_cos();
                let up = Vector3::new(sin_t, 0.0, cos_t);
                rho_over_pi
                    * diffuse_rule
                        .iter()
                        .map(|(w, weight)| weight * environment.radiance_at_sine(w.dot(&up)))
                        .sum::<f64>()
            })
            .collect();

        Ok(MaterialTables {
            theta,
            tilt,
            phi,
            emissivity,
            reflection,
            diffuse_tilt,
            diffuse,
            resolution,
        })
    }

    /// (ε0, ε1) at emission angle θ, given as cos θ (psps frame; ε2 = ε3 = 0 for isotropic
    /// surfaces). Angles beyond [`THETA_MAX`] read the last node.
    #[inline]
    pub fn emissivity(&self, cos_theta: f64) -> [f64; 2] {
        let (i, f) = self.theta.locate(theta_coordinate(cos_theta));
        let (a, b) = (self.emissivity[i], self.emissivity[i + 1]);
        [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])]
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

/// Brightness temperature (K) of band radiance over a radiance range, by linear interpolation
/// on 257 exact inversions (`Band::brightness_temperature` is a Newton solve per call); clamped
/// to the range. For previews and summaries, not for physics.
pub struct TemperatureLookup {
    lo: f64,
    step: f64,
    values: Vec<f64>,
}

impl TemperatureLookup {
    pub fn new(band: &Band, lo: f64, hi: f64) -> TemperatureLookup {
        TemperatureLookup::with_nodes(band, lo, hi, 257)
    }

    /// The lookup with `n` ≥ 2 exact inversions (more nodes, smaller interpolation error).
    pub fn with_nodes(band: &Band, lo: f64, hi: f64, n: usize) -> TemperatureLookup {
        let n = n.max(2);
        let step = ((hi - lo) / (n - 1) as f64).max(1e-12);
        let values = (0..n)
            .map(|i| {
                band.brightness_temperature((lo + step * i as f64).max(0.0))
                    .unwrap_or(0.0)
            })
            .collect();
        TemperatureLookup { lo, step, values }
    }

    #[inline]
    pub fn at(&self, radiance: f64) -> f64 {
        let x = ((radiance - self.lo) / self.step).clamp(0.0, (self.values.len() - 1) as f64);
        let i = (x as usize).min(self.values.len() - 2);
        let f = x - i as f64;
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
