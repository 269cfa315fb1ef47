//! Hemispherical integrals of the pBRDF: the reflected Stokes vector of an unpolarized environment,
//! ∫ F_j0(ω_i→ω_r) L(ω_i) cosθ_i dΩ_i, and from it the polarized emissivity by Kirchhoff's law,
//! ε_j(ω_e) = δ_j0 − ∫ F_j0(ω_i→ω_e) cosθ_i dΩ_i (docs/design.md §1.4; Ma et al. eqs. 8–9, Resnick 1999).
//!
//! Why not a grid over ω_i: for σ = 0.02 the specular lobe is a few degrees wide and a direction grid
//! needs millions of points. Instead the specular part is integrated over facet slopes m, where the
//! lobe is the slope density itself: with ω_i the mirror of ω_r about h(m), dΩ_i = 4 cosβ dΩ_h and
//! P(θ) dΩ_h = p(m) d²m, so
//!     ∫ F_spec,j0 L cosθ_i dΩ_i = ∫ p(m) G M_j0(β) L(ω_i) cosβ / (cosθ_h cosθ_r) d²m
//! over the slopes whose mirror direction is above the horizon. In polar slope coordinates (u, Δ)
//! that region is known in closed form (see `reflected_stokes`), so the horizon cut is exact and the
//! integrand is smooth inside it. Radial panels grow geometrically from a fraction of σ (the density
//! varies on the scale σ near 0 and as a power law in the Cauchy tail), Gauss–Legendre inside each;
//! the azimuth uses the trapezoid rule over full circles and Gauss–Legendre over cut arcs.
//! Torrance–Sparrow's min() puts kinks inside the domain, so with it the error is ~1e-4 at grazing
//! angles instead of 1e-5.
//! The diffuse term (ρ_d/π) ∫ L cosθ_i dΩ_i uses a cosine-weighted (projected disk) rule.

use super::{ModelError, Pbrdf, ScatteringGeometry};
use crate::optics::frame::{double_angle, facet_axis_in_scattered_frame, Direction};
use crate::optics::{FresnelFractions, Stokes};
use gauss_quad::legendre::GaussLegendre;
use nalgebra::Vector3;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::{FRAC_1_PI, PI};

/// Node counts of the hemispherical quadrature. `default()` meets 1e-5 absolute in emissivity for
/// σ ≥ 0.02 up to 89° (shadowing none or Smith); `fine()` is for reference values. The renderer's
/// tables choose their own node counts (`render::kernel::KernelQuadrature::hemisphere`).
#[derive(Clone, Debug)]
pub struct HemisphereQuadrature {
    /// Trapezoid nodes over a full circle of facet azimuths (slopes whose mirror is never cut).
    full_circle_nodes: usize,
    /// Gauss–Legendre nodes and weights on [0, 1] for the azimuth arc of cut slopes.
    arc_rule: Vec<(f64, f64)>,
    /// Gauss–Legendre nodes and weights mapped to [0, 1].
    panel_rule: Vec<(f64, f64)>,
    /// Width of the first radial panel in units of the distribution's slope scale σ.
    first_panel: f64,
    /// Each further radial panel is this many times wider than the last.
    panel_growth: f64,
    /// Cosine-weighted rule for the diffuse term: (ω_i, weight) with Σ weight = π.
    diffuse_rule: Vec<(Vector3<f64>, f64)>,
}

impl HemisphereQuadrature {
    /// `azimuth_nodes` trapezoid nodes per full circle (half as many Gauss–Legendre nodes per cut
    /// arc), `points_per_panel` Gauss–Legendre nodes per radial panel, the first panel
    /// `first_panel` σ wide and each next `panel_growth` times wider.
    pub fn new(
        azimuth_nodes: usize,
        points_per_panel: usize,
        first_panel: f64,
        panel_growth: f64,
    ) -> HemisphereQuadrature {
        let azimuth_nodes = azimuth_nodes.max(4);
        let panel_rule = unit_interval_rule(points_per_panel.max(1));
        let diffuse_rule = cosine_hemisphere_rule(points_per_panel.max(1) * 2, azimuth_nodes);
        HemisphereQuadrature {
            full_circle_nodes: azimuth_nodes,
            arc_rule: unit_interval_rule(azimuth_nodes / 2),
            panel_rule,
            first_panel,
            panel_growth: panel_growth.max(1.1),
            diffuse_rule,
        }
    }

    pub fn fine() -> HemisphereQuadrature {
        HemisphereQuadrature::new(512, 12, 0.2, 1.5)
    }
}

impl HemisphereQuadrature {
    /// The cosine-weighted hemisphere rule (ω, w) with Σ w = π = ∫ cosθ dΩ, used for the diffuse
    /// term: (ρ_d/π) ∫ L cosθ_i dΩ_i ≈ (ρ_d/π) Σ w L(ω).
    pub fn cosine_weighted_nodes(&self) -> &[(Vector3<f64>, f64)] {
        &self.diffuse_rule
    }
}

impl Default for HemisphereQuadrature {
    fn default() -> HemisphereQuadrature {
        HemisphereQuadrature::new(48, 8, 0.5, 2.0)
    }
}

/// Gauss–Legendre nodes in sin²θ for [`Pbrdf::hemispherical_emissivity`].
const HEMISPHERICAL_EMISSIVITY_NODES: usize = 24;

fn unit_interval_rule(points: usize) -> Vec<(f64, f64)> {
    let rule = GaussLegendre::new(points.try_into().expect("points ≥ 1"));
    rule.as_node_weight_pairs()
        .iter()
        .map(|&(x, w)| (0.5 * (x + 1.0), 0.5 * w))
        .collect()
}

/// Projected-disk rule: cosθ dΩ = r dr dφ = ½ d(r²) dφ on the unit disk; Gauss–Legendre in r²,
/// trapezoid in φ. Weights sum to π = ∫ cosθ dΩ. Directions are about +z.
pub fn cosine_hemisphere_rule(radial: usize, azimuthal: usize) -> Vec<(Vector3<f64>, f64)> {
    let radial_rule = unit_interval_rule(radial);
    let dphi = 2.0 * PI / azimuthal as f64;
    let mut rule = Vec::with_capacity(radial * azimuthal);
    for &(t, wt) in &radial_rule {
        let r = t.sqrt();
        let z = (1.0 - t).sqrt();
        for j in 0..azimuthal {
            let (sin_p, cos_p) = ((j as f64 + 0.5) * dphi).sin_cos();
            rule.push((Vector3::new(r * cos_p, r * sin_p, z), 0.5 * wt * dphi));
        }
    }
    rule
}

/// Radial panel edges 0 = e0 < e1 < … = end: the first panel `first` wide, each next `growth` times
/// wider, with `split` inserted as an edge when it lies inside.
fn radial_panel_edges(first: f64, growth: f64, split: f64, end: f64) -> Vec<f64> {
    let mut edges = vec![0.0];
    let mut width = first;
    let mut next = first;
    while next < end {
        edges.push(next);
        width *= growth;
        next += width;
    }
    edges.push(end);
    if split > 0.0 && split < end && !edges.contains(&split) {
        let at = edges.partition_point(|&e| e < split);
        edges.insert(at, split);
    }
    edges
}

/// One node of the specular reflection quadrature without its Fresnel factor
/// ([`Pbrdf::visit_specular_facets`]): cos β of the facet, the node's weight times
/// G cosβ secθ_h / cosθ_r, and (cos 2η_r, sin 2η_r) of the facet frame against ω_r's.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SpecularFacet {
    pub cos_beta: f64,
    pub scale: f64,
    pub cos2: f64,
    pub sin2: f64,
}

impl SpecularFacet {
    /// The node's Stokes weight (first column of the facet Mueller matrix) for permittivity ε.
    #[inline]
    pub fn stokes(&self, permittivity: Complex64) -> Stokes {
        let (rs2, rp2, _) =
            FresnelFractions::new(self.cos_beta, permittivity).reflectances_and_cross();
        let half_diff = 0.5 * (rs2 - rp2) * self.scale;
        Stokes::new(
            0.5 * (rs2 + rp2) * self.scale,
            self.cos2 * half_diff,
            self.sin2 * half_diff,
            0.0,
        )
    }
}

impl Pbrdf {
    /// ∫ F_j0(ω_i→ω_r) L(ω_i) cosθ_i dΩ_i for an unpolarized environment radiance L given in the
    /// local frame, as a Stokes vector in the psps frame of ω_r (docs/design.md §1.5). Zero for ω_r at or
    /// below the horizon.
    pub fn reflected_stokes(
        &self,
        scattered: &Direction,
        environment: impl Fn(&Vector3<f64>) -> f64,
        quadrature: &HemisphereQuadrature,
    ) -> Stokes {
        let mut sum = Stokes::zeros();
        self.visit_reflection_nodes(scattered, quadrature, |w_i, kernel| {
            sum += kernel * environment(w_i)
        });
        sum
    }

    /// The quadrature of [`Pbrdf::reflected_stokes`] as explicit nodes: calls `visit(ω_i, K)` for
    /// each incident direction ω_i (local frame) with the Stokes weight K such that
    /// ∫ F_j0 L cosθ_i dΩ_i ≈ Σ K_j L(ω_i) for any environment L. Callers that integrate many
    /// environments against one direction (a renderer's tables) keep the nodes instead of
    /// re-evaluating the pBRDF.
    pub fn visit_reflection_nodes(
        &self,
        scattered: &Direction,
        quadrature: &HemisphereQuadrature,
        mut visit: impl FnMut(&Vector3<f64>, Stokes),
    ) {
        if scattered.cos_theta() <= 0.0 {
            return;
        }
        self.visit_specular_nodes(scattered, quadrature, &mut visit);
        if self.has_subsurface() {
            self.visit_subsurface_nodes(scattered, quadrature, self.rho_d(), &mut visit);
        } else if self.rho_d() > 0.0 {
            for (w_i, weight) in quadrature.cosine_weighted_nodes() {
                visit(
                    w_i,
                    Stokes::new(self.rho_d() * FRAC_1_PI * weight, 0.0, 0.0, 0.0),
                );
            }
        }
    }

    /// The subsurface part of [`Pbrdf::visit_reflection_nodes`] (nothing without the term), with
    /// `rho_d`/π added to each node's S0 weight. The subsurface term (docs/design.md §1.10) is
    /// smooth over ω_i like the ideal depolarizer, so it shares its cosine-weighted rule.
    pub fn visit_subsurface_nodes(
        &self,
        scattered: &Direction,
        quadrature: &HemisphereQuadrature,
        rho_d: f64,
        mut visit: impl FnMut(&Vector3<f64>, Stokes),
    ) {
        if !self.has_subsurface() || scattered.cos_theta() <= 0.0 {
            return;
        }
        let depolarized = Stokes::new(rho_d * FRAC_1_PI, 0.0, 0.0, 0.0);
        for (w_i, weight) in quadrature.cosine_weighted_nodes() {
            let incident = Direction::from_unit_vector(*w_i);
            let subsurface = ScatteringGeometry::new(&incident, scattered)
                .map_or_else(Stokes::zeros, |g| self.subsurface_first_column(&g));
            visit(w_i, (depolarized + subsurface) * *weight);
        }
    }

    /// The facet (specular) part of [`Pbrdf::visit_reflection_nodes`] alone; the diffuse part is
    /// (ρ_d/π) times [`HemisphereQuadrature::cosine_weighted_nodes`].
    pub fn visit_specular_nodes(
        &self,
        scattered: &Direction,
        quadrature: &HemisphereQuadrature,
        mut visit: impl FnMut(&Vector3<f64>, Stokes),
    ) {
        let permittivity = self.permittivity();
        self.visit_specular_facets(scattered, quadrature, |w_i, facet| {
            visit(w_i, facet.stokes(permittivity))
        });
    }

    /// The node placement of [`Pbrdf::visit_specular_nodes`] without the Fresnel factor: calls
    /// `visit(ω_i, facet)` for each node, whose weight for an index of permittivity ε is
    /// `facet.stokes(ε)`. It depends on the slope distribution and shadowing alone, so that
    /// models differing only in N (one material over wavelength, docs/design.md §1.9) share it.
    pub(crate) fn visit_specular_facets(
        &self,
        scattered: &Direction,
        quadrature: &HemisphereQuadrature,
        mut visit: impl FnMut(&Vector3<f64>, SpecularFacet),
    ) {
        let Some(frame) = MirrorFrame::new(self, scattered) else {
            return;
        };
        let distribution = self.prepared_distribution();
        let u_last = frame.u_none.min(distribution.slope_cutoff());
        let edges = radial_panel_edges(
            quadrature.first_panel * distribution.slope_scale(),
            quadrature.panel_growth,
            frame.u_full,
            u_last,
        );
        let mut add_facet = |u: f64, delta: f64, weight: f64| {
            if let Some((w_i, facet)) = frame.facet(u, delta, weight) {
                visit(&w_i, facet);
            }
        };
        for panel in edges.windows(2) {
            let (a, b) = (panel[0], panel[1]);
            // √ end points (at u_full on the left, u_none on the right) are smoothed by
            // u = a + (b − a) sin²(πv/2).
            let singular_ends = a == frame.u_full || b == frame.u_none;
            for &(v, wv) in &quadrature.panel_rule {
                let (u, du) = radial_node(a, b, v, singular_ends);
                // Polar slope measure u du dΔ times the slope density.
                let radial_weight = wv * du * u * distribution.slope_pdf(u * u);
                frame.visit_azimuths(u, radial_weight, quadrature, &mut add_facet);
            }
        }
    }

    /// Polarized emissivity (ε0, ε1, ε2, ε3) at emission zenith θ_e (radians), in the psps frame of
    /// ω_e, unclamped: ε0 < 0 where the model reflects more than it receives (see
    /// [`Pbrdf::checked_emissivity`]).
    pub fn emissivity(&self, theta_e: f64, quadrature: &HemisphereQuadrature) -> Stokes {
        let direction = Direction::from_angles(theta_e, 0.0);
        Stokes::new(1.0, 0.0, 0.0, 0.0) - self.reflected_stokes(&direction, |_| 1.0, quadrature)
    }

    /// ε_j at each of `thetas` (radians), evaluated in parallel.
    pub fn emissivity_table(
        &self,
        thetas: &[f64],
        quadrature: &HemisphereQuadrature,
    ) -> Vec<Stokes> {
        thetas
            .par_iter()
            .map(|&theta| self.emissivity(theta, quadrature))
            .collect()
    }

    /// [`Pbrdf::emissivity`], refusing angles where the directional-hemispherical reflectance
    /// 1 − ε0 exceeds 1 (beyond 1e-9 of quadrature rounding): never silently clamped.
    pub fn checked_emissivity(
        &self,
        theta_e: f64,
        quadrature: &HemisphereQuadrature,
    ) -> Result<Stokes, ModelError> {
        let e = self.emissivity(theta_e, quadrature);
        if e[0] < -1e-9 {
            return Err(ModelError::ReflectanceAboveOne {
                theta_deg: theta_e.to_degrees(),
                reflectance: 1.0 - e[0],
            });
        }
        Ok(e)
    }

    /// Hemispherical emissivity ε_h = (1/π) ∫ ε0(θ) cosθ dΩ, the flux-weighted mean of ε0 that a
    /// surface's thermal balance needs (docs/design.md §1.8 default). With t = sin²θ, cosθ dΩ = ½ dt dφ,
    /// so ε_h = ∫₀¹ ε0(arcsin √t) dt: Gauss–Legendre in t, whose nodes avoid the grazing end where
    /// ε0 varies fastest. 24 nodes and the default quadrature give ε_h to ~1e-5.
    pub fn hemispherical_emissivity(&self) -> f64 {
        let quadrature = HemisphereQuadrature::default();
        unit_interval_rule(HEMISPHERICAL_EMISSIVITY_NODES)
            .iter()
            .map(|&(t, w)| w * self.emissivity(t.sqrt().asin(), &quadrature)[0])
            .sum()
    }

    /// Directional-hemispherical reflectance ρ(θ) = ∫ F_00(ω_i→ω) cosθ_i dΩ_i = 1 − ε0(θ)
    /// (reciprocity makes incidence and emission directions interchangeable).
    pub fn directional_hemispherical_reflectance(
        &self,
        theta: f64,
        quadrature: &HemisphereQuadrature,
    ) -> f64 {
        self.reflected_stokes(&Direction::from_angles(theta, 0.0), |_| 1.0, quadrature)[0]
    }
}

/// Slope u and du/dv of node v ∈ [0, 1] of the radial panel [a, b]; with `singular_ends`, through
/// u = a + (b − a) sin²(πv/2).
fn radial_node(a: f64, b: f64, v: f64, singular_ends: bool) -> (f64, f64) {
    if singular_ends {
        let half_angle = 0.5 * PI * v;
        (
            a + (b - a) * half_angle.sin().powi(2),
            (b - a) * 0.5 * PI * (PI * v).sin(),
        )
    } else {
        (a + (b - a) * v, b - a)
    }
}

/// What every specular facet node of one scattered direction ω_r shares
/// ([`Pbrdf::visit_specular_facets`]).
struct MirrorFrame<'a> {
    pbrdf: &'a Pbrdf,
    scattered: &'a Direction,
    w_r: Vector3<f64>,
    cos_r: f64,
    sin_r: f64,
    tangential: Vector3<f64>,
    radial: Vector3<f64>,
    /// The scattered direction's shadowing factor is the same for every facet.
    masking_r: f64,
    /// Slopes up to this mirror ω_r above the horizon at every azimuth.
    u_full: f64,
    /// Slopes from this on mirror ω_r below the horizon at every azimuth.
    u_none: f64,
}

impl<'a> MirrorFrame<'a> {
    /// `None` for ω_r at or below the horizon.
    fn new(pbrdf: &'a Pbrdf, scattered: &'a Direction) -> Option<MirrorFrame<'a>> {
        let w_r = scattered.vector;
        let cos_r = w_r.z;
        if cos_r <= 0.0 {
            return None;
        }
        let sin_r = (1.0 - cos_r * cos_r).max(0.0).sqrt();
        let tangential = scattered.azimuthal_axis;
        let radial = tangential.cross(&Vector3::z());
        // The facet tilted by slope u toward azimuth Δ (from ω_r's azimuth) mirrors ω_r above the
        // horizon iff cosΔ > κ(u) = cosθ_r (u² − 1) / (2u sinθ_r). Hence every azimuth is kept for
        // u ≤ u_full = cosθ_r/(1 + sinθ_r), none for u ≥ u_none = (1 + sinθ_r)/cosθ_r, and
        // |Δ| < arccos κ(u) in between, where the azimuthal width has √ end-point behaviour.
        let u_full = cos_r / (1.0 + sin_r);
        let u_none = (1.0 + sin_r) / cos_r;
        Some(MirrorFrame {
            pbrdf,
            scattered,
            w_r,
            cos_r,
            sin_r,
            tangential,
            radial,
            masking_r: pbrdf.masking(cos_r),
            u_full,
            u_none,
        })
    }

    /// Calls `add_facet(u, Δ, weight)` for the azimuth nodes of slope `u` whose radial weight is
    /// `radial_weight`: the trapezoid rule over the full circle where no azimuth is cut,
    /// Gauss–Legendre over |Δ| < arccos κ(u) where some are.
    fn visit_azimuths(
        &self,
        u: f64,
        radial_weight: f64,
        quadrature: &HemisphereQuadrature,
        add_facet: &mut impl FnMut(f64, f64, f64),
    ) {
        if u <= self.u_full {
            let n_full = quadrature.full_circle_nodes;
            let step = 2.0 * PI / n_full as f64;
            for j in 0..n_full {
                add_facet(u, (j as f64 + 0.5) * step, radial_weight * step);
            }
        } else {
            let kappa = self.cos_r * (u * u - 1.0) / (2.0 * u * self.sin_r);
            let half_width = kappa.clamp(-1.0, 1.0).acos();
            for &(t, wt) in &quadrature.arc_rule {
                add_facet(
                    u,
                    half_width * (2.0 * t - 1.0),
                    radial_weight * wt * 2.0 * half_width,
                );
            }
        }
    }

    /// The incident direction ω_i mirrored by the facet of slope `u` toward azimuth `delta`, and
    /// its node with quadrature weight `weight`; `None` where rounding at the horizon cut puts
    /// ω_i below the horizon.
    fn facet(&self, u: f64, delta: f64, weight: f64) -> Option<(Vector3<f64>, SpecularFacet)> {
        let (sin_d, cos_d) = delta.sin_cos();
        let sec_h = (1.0 + u * u).sqrt();
        let h = ((self.radial * cos_d + self.tangential * sin_d) * u + Vector3::z()) / sec_h;
        let cos_beta = h.dot(&self.w_r);
        let w_i = h * (2.0 * cos_beta) - self.w_r;
        let cos_i = w_i.z;
        if cos_i <= 0.0 {
            return None;
        }
        let g = self.pbrdf.shadowing().factor_with_masking(
            cos_i,
            self.cos_r,
            cos_beta * cos_beta,
            [self.pbrdf.masking(cos_i), self.masking_r],
        );
        // Facet s axis against the psps frame of ω_r (η_r of docs/design.md §1.3).
        let (cos2, sin2) = double_angle(facet_axis_in_scattered_frame(&w_i, self.scattered));
        let scale = weight * g * cos_beta * sec_h / self.cos_r;
        let facet = SpecularFacet {
            cos_beta,
            scale,
            cos2,
            sin2,
        };
        Some((w_i, facet))
    }
}
