//! The polarized microfacet BRDF (docs/design.md §1.3; Ma et al. eqs. 4–7, Priest & Germer 2000):
//! F(ω_i→ω_r) = P(θ) G M(β, η_i, η_r) / (4 cosθ cosθ_i cosθ_r) + (ρ_d/π) diag(1,0,0,0),
//! M = L(−η_r) F_fres(β) L(η_i).

use super::distribution::{CauchySmithTable, PreparedDistribution};
use super::facet_side::FacetSide;
use super::limits::{within, MAX_K, MAX_N, MIN_N};
use super::subsurface::{PreparedSubsurface, Subsurface};
use super::visible_slopes::VisibleSlopes;
use super::{ModelError, Shadowing, SlopeDistribution};
use crate::elementary::{exp_within_range, inline_exp};
use crate::optics::frame::{
    double_angle, facet_axis_in_incident_frame, facet_axis_in_scattered_frame, Direction,
};
use crate::optics::{FresnelFractions, Mueller, RefractiveIndex, Stokes};
use num_complex::Complex64;
use std::f64::consts::FRAC_1_PI;
use std::sync::OnceLock;

/// A validated pBRDF model. Construct with [`Pbrdf::new`]; the parameters are read-only so that
/// the constants derived from them stay consistent.
#[derive(Clone, Debug)]
pub struct Pbrdf {
    distribution: SlopeDistribution,
    shadowing: Shadowing,
    index: RefractiveIndex,
    rho_d: f64,
    facet_side: FacetSide,
    /// The polarized subsurface lobes (docs/design.md §1.10), each adding its Mueller matrix.
    subsurface_lobes: Vec<PreparedSubsurface>,
    prepared: PreparedDistribution,
    /// The permittivity the facets see: N², or 1/N² for internal facets.
    permittivity: Complex64,
    /// Smith–Cauchy Λ, built on the first [`Pbrdf::masking`]; `None` inside for the other
    /// distributions.
    /// (Boxed: with its per-interval polynomials it is large, and most models have none.)
    lambda_table: OnceLock<Option<Box<CauchySmithTable>>>,
    /// The importance sampler of visible slopes, built on the first sampled direction; `None`
    /// inside where no visible-normal density exists (Cauchy q ≤ 3/2).
    /// (Boxed: it is large, and most models are never sampled.)
    visible_slopes: OnceLock<Option<Box<VisibleSlopes>>>,
}

/// What one facet reflection contributes: P G/(4 cosθ cosθ_i cosθ_r) (|r_s|², |r_p|², r_s* r_p)
/// = `scale` (`rs2`, `rp2`, `cross`). The Fresnel terms are kept unnormalized (see
/// [`FresnelFractions::reflectances_and_cross_unnormalized`]) and their common denominator is
/// folded into `scale`.
struct FacetReflection {
    scale: f64,
    rs2: f64,
    rp2: f64,
    cross: Complex64,
}

impl FacetReflection {
    /// The elements A = (|r_s|² + |r_p|²)/2 and B = (|r_s|² − |r_p|²)/2 of F_fres (docs/design.md §1.3),
    /// times the facet scale: all that the first column needs.
    #[inline(always)]
    fn scaled_a_and_b(&self) -> (f64, f64) {
        (
            0.5 * (self.rs2 + self.rp2) * self.scale,
            0.5 * (self.rs2 - self.rp2) * self.scale,
        )
    }
}

/// The N-independent factors of a facet reflection: e^E of the facet density D = c e^E and
/// c G/(4 cosθ_i cosθ_r), so that [`FacetReflection::scale`] = e^E (that × the Fresnel terms'
/// common inverse denominator).
#[derive(Clone, Copy, Debug)]
pub(super) struct FacetShape {
    density: f64,
    factor: f64,
}

impl FacetShape {
    /// The facet scale for the Fresnel terms' inverse denominator `fresnel_inverse`.
    #[inline(always)]
    pub(super) fn scale(&self, fresnel_inverse: f64) -> f64 {
        // Two long chains, the density's log and exp and the Fresnel square roots and division,
        // meet in the last multiplications; every other factor is ready before them.
        self.density * (self.factor * fresnel_inverse)
    }
}

/// A direction pair and its facet as the model needs them: cos θ_i, cos θ_r, tan²θ of the facet
/// tilt and cos²β of the local incidence — squares, so that none costs a square root.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct FacetGeometry {
    pub(super) cos_i: f64,
    pub(super) cos_r: f64,
    pub(super) tan2_theta: f64,
    pub(super) cos2_beta: f64,
}

impl FacetGeometry {
    /// `None` when either direction is at or below the horizon.
    #[inline]
    pub(super) fn new(incident: &Direction, scattered: &Direction) -> Option<FacetGeometry> {
        let (w_i, w_r) = (&incident.vector, &scattered.vector);
        let (cos_i, cos_r) = (w_i.z, w_r.z);
        if cos_i <= 0.0 || cos_r <= 0.0 {
            return None;
        }
        // Half vector h = (ω_i + ω_r)/|ω_i + ω_r|; cos β = h·ω_i = |ω_i + ω_r|/2 (paper eqs. 1–2 in
        // vector form, regular at θ = 0 and β = 0). tan²θ comes straight from the components of
        // ω_i + ω_r: the facet density then waits for one division, not a square root and two.
        let sum = w_i + w_r;
        Some(FacetGeometry {
            cos_i,
            cos_r,
            tan2_theta: (sum.x * sum.x + sum.y * sum.y) / (sum.z * sum.z),
            cos2_beta: 0.25 * sum.norm_squared(),
        })
    }
}

/// The model-independent part of one (ω_i, ω_r) pair (docs/design.md §1.1, §1.3): the facet geometry
/// (cos θ_i, cos θ_r, tan²θ, cos²β), and the rotations (cos 2η, sin 2η) of the
/// facet s/p frame against the psps frames of the incident and the scattered light. A caller
/// that evaluates many models on the same directions (a fit) builds it once per pair and calls
/// [`Pbrdf::mueller_for_geometry`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScatteringGeometry {
    facet: FacetGeometry,
    incident_rotation: (f64, f64),
    scattered_rotation: (f64, f64),
}

impl ScatteringGeometry {
    /// `None` when either direction is at or below the horizon, where the BRDF is zero.
    #[inline]
    pub fn new(incident: &Direction, scattered: &Direction) -> Option<ScatteringGeometry> {
        Some(ScatteringGeometry {
            facet: FacetGeometry::new(incident, scattered)?,
            incident_rotation: double_angle(facet_axis_in_incident_frame(
                incident,
                &scattered.vector,
            )),
            scattered_rotation: double_angle(facet_axis_in_scattered_frame(
                &incident.vector,
                scattered,
            )),
        })
    }

    /// The facet geometry (cos θ_i, cos θ_r, tan²θ, cos²β).
    pub(super) fn facet(&self) -> &FacetGeometry {
        &self.facet
    }

    /// L(−η_r) F_fres L(η_i) + `diffuse` in m00 (docs/design.md §1.3) from F_fres's elements
    /// [A, B, C, S] with the facet scale folded in.
    #[inline(always)]
    pub(super) fn assemble_mueller(&self, fresnel: [f64; 4], diffuse: f64) -> Mueller {
        let [a, b, c, s] = fresnel;
        let (ci, si) = self.incident_rotation;
        let (cr, sr) = self.scattered_rotation;
        // L(−η_r) F_fres L(η_i) multiplied out.
        Mueller::new(
            a + diffuse,
            b * ci,
            b * si,
            0.0,
            cr * b,
            cr * a * ci + sr * c * si,
            cr * a * si - sr * c * ci,
            sr * s,
            sr * b,
            sr * a * ci - cr * c * si,
            sr * a * si + cr * c * ci,
            -cr * s,
            0.0,
            -s * si,
            s * ci,
            c,
        )
    }

    /// (cos, sin) of 2η_i + 2η_r: how far the scattering plane's frames turn from the psps
    /// frames, as the subsurface term needs them (docs/design.md §1.10).
    #[inline]
    pub(super) fn scattering_plane_turn(&self) -> (f64, f64) {
        let (ci, si) = self.incident_rotation;
        let (cr, sr) = self.scattered_rotation;
        (cr * ci - sr * si, sr * ci + cr * si)
    }

    /// cos θ_i, the argument of the incident direction's [`Pbrdf::masking`].
    pub fn cos_incident(&self) -> f64 {
        self.facet.cos_i
    }

    /// cos θ_r, the argument of the scattered direction's [`Pbrdf::masking`].
    pub fn cos_scattered(&self) -> f64 {
        self.facet.cos_r
    }
}

impl Pbrdf {
    pub fn new(
        distribution: SlopeDistribution,
        shadowing: Shadowing,
        index: RefractiveIndex,
        rho_d: f64,
    ) -> Result<Pbrdf, ModelError> {
        distribution.validate()?;
        if let (SlopeDistribution::Cauchy { q, .. }, Shadowing::Smith) = (distribution, shadowing) {
            if q <= 1.5 {
                return Err(ModelError::SmithNeedsQ(q));
            }
        }
        if !within(index.n, MIN_N, MAX_N) {
            return Err(ModelError::RealIndex(index.n));
        }
        if !within(index.k, 0.0, MAX_K) {
            return Err(ModelError::ExtinctionIndex(index.k));
        }
        if !(rho_d.is_finite() && (0.0..=1.0).contains(&rho_d)) {
            return Err(ModelError::Diffuse(rho_d));
        }
        Ok(Pbrdf {
            distribution,
            shadowing,
            index,
            rho_d,
            facet_side: FacetSide::External,
            subsurface_lobes: Vec::new(),
            prepared: distribution.prepare(),
            permittivity: index.permittivity(),
            lambda_table: OnceLock::new(),
            visible_slopes: OnceLock::new(),
        })
    }

    pub fn distribution(&self) -> SlopeDistribution {
        self.distribution
    }
    pub fn shadowing(&self) -> Shadowing {
        self.shadowing
    }
    pub fn index(&self) -> RefractiveIndex {
        self.index
    }
    pub fn rho_d(&self) -> f64 {
        self.rho_d
    }
    pub fn facet_side(&self) -> FacetSide {
        self.facet_side
    }
    /// The parameters of each subsurface lobe (none for a model without the term).
    pub fn subsurface_lobes(&self) -> impl Iterator<Item = Subsurface> + '_ {
        self.subsurface_lobes.iter().map(|s| s.terms)
    }

    /// The model with the volume-scattering terms of docs/design.md §1.10: the facets reflecting
    /// from `facet_side`, and polarized subsurface lobes (an `Option` gives none or one). Each
    /// lobe's ρ_s, d, … are checked against their domains ([`super::Parameter::check`]).
    pub fn with_volume(
        mut self,
        facet_side: FacetSide,
        subsurface: impl IntoIterator<Item = Subsurface>,
    ) -> Result<Pbrdf, ModelError> {
        let lobes: Vec<Subsurface> = subsurface.into_iter().collect();
        for &terms in &lobes {
            for (parameter, value) in terms.keys() {
                parameter.check(value)?;
            }
            if terms.largest_residual() > 1.0 {
                return Err(ModelError::ResidualAboveOne {
                    d: terms.d,
                    d1: terms.d1.unwrap_or(0.0),
                });
            }
            if !terms.is_realizable() {
                return Err(ModelError::UnrealizableSubsurface {
                    d: terms.largest_residual(),
                    d_c: terms.circular(),
                });
            }
        }
        self.facet_side = facet_side;
        self.permittivity = facet_side.facet_permittivity(self.index);
        self.subsurface_lobes = lobes
            .into_iter()
            .map(|terms| PreparedSubsurface::new(terms, self.index))
            .collect();
        Ok(self)
    }

    /// The reflectance of the terms without a facet lobe, ρ_d + Σ ρ_s: what the renderer's
    /// cosine lobe samples.
    pub fn body_albedo(&self) -> f64 {
        self.subsurface_lobes
            .iter()
            .fold(self.rho_d, |albedo, s| albedo + s.terms.rho_s)
    }

    /// The subsurface lobes' summed Mueller matrix, `None` without one (not added to zeros).
    #[inline]
    fn subsurface_mueller(&self, geometry: &ScatteringGeometry) -> Option<Mueller> {
        let (facet, turn) = (&geometry.facet, geometry.scattering_plane_turn());
        let cos_scattering = 1.0 - 2.0 * facet.cos2_beta; // cos Θ = −ω_i·ω_r (design.md §1.1)
        let lobe = |s: &PreparedSubsurface| {
            let (t_i, t_r) = (s.transmission(facet.cos_i), s.transmission(facet.cos_r));
            s.mueller(t_i, t_r, turn, cos_scattering)
        };
        self.subsurface_lobes
            .iter()
            .map(lobe)
            .reduce(|sum, m| sum + m)
    }

    /// (m00, m10, m20) of the subsurface term from ω_i onto ω_r, zero without one: its Stokes
    /// BRDF for unpolarized light, and its weight in a hemispherical integral over ω_i.
    #[inline]
    pub(super) fn subsurface_first_column(&self, geometry: &ScatteringGeometry) -> Stokes {
        self.subsurface_mueller(geometry)
            .map_or_else(Stokes::zeros, |m| m.column(0).into_owned())
    }
    pub(crate) fn prepared_distribution(&self) -> &PreparedDistribution {
        &self.prepared
    }
    pub(super) fn visible_slopes(&self) -> Option<&VisibleSlopes> {
        self.visible_slopes
            .get_or_init(|| VisibleSlopes::new(&self.prepared).map(Box::new))
            .as_deref()
    }

    /// The factor of the shadowing G that depends on one direction only, for a direction with
    /// cos θ = `cos_theta`: Smith's G1(θ) = 1/(1+Λ(θ)); 1 for `none` and `torrance-sparrow`
    /// (docs/design.md §1.3). The Cauchy Λ comes from a table built on the model's first call (~0.1 ms,
    /// then ~10 ns per direction, a few in a block's vectorized loop; within 1e-14 of the
    /// incomplete-beta form for q ≤ 4, 2e-13 up to q = 100, see `CauchySmithTable`), so every evaluation of one model — `irpol eval`, renders,
    /// quadratures, the Python `mueller` — uses the same numbers.
    pub fn masking(&self, cos_theta: f64) -> f64 {
        if self.shadowing != Shadowing::Smith {
            return 1.0;
        }
        match self.cauchy_smith_table() {
            Some(table) => table.masking(cos_theta),
            None => self.masking_without_table(cos_theta),
        }
    }

    /// The table behind [`Pbrdf::masking`] of a Cauchy model (built on the first call), `None`
    /// for the Gaussian.
    pub(super) fn cauchy_smith_table(&self) -> Option<&CauchySmithTable> {
        self.lambda_table
            .get_or_init(|| self.prepared.smith_lambda_table().map(Box::new))
            .as_deref()
    }

    /// The [`Pbrdf::masking`] factors of ω_i and ω_r.
    #[inline]
    fn masking_of(&self, geometry: &FacetGeometry) -> [f64; 2] {
        [self.masking(geometry.cos_i), self.masking(geometry.cos_r)]
    }

    /// [`Pbrdf::masking`] from the incomplete beta function itself (~0.2 µs per call), for a
    /// caller that evaluates each new model at a few dozen angles only (a fit's objective, where
    /// building the table would cost more than it saves) and passes the factors to
    /// [`Pbrdf::mueller_with_masking`].
    pub fn masking_without_table(&self, cos_theta: f64) -> f64 {
        self.shadowing.masking(&self.prepared, cos_theta)
    }

    /// Distribution, shadowing and Fresnel part shared by the full and fast paths. `masking`
    /// holds the [`Pbrdf::masking`] factors of ω_i and ω_r.
    #[inline(always)]
    fn facet_reflection(&self, geometry: &FacetGeometry, masking: [f64; 2]) -> FacetReflection {
        self.facet_reflection_with_shape(geometry, self.facet_shape(geometry, masking))
    }

    /// [`Pbrdf::facet_reflection`] for the facet shape of `geometry`.
    #[inline(always)]
    fn facet_reflection_with_shape(
        &self,
        geometry: &FacetGeometry,
        shape: FacetShape,
    ) -> FacetReflection {
        let (rs2, rp2, cross, fresnel_inverse) =
            FresnelFractions::from_cos2(geometry.cos2_beta, self.permittivity)
                .reflectances_and_cross_unnormalized();
        FacetReflection {
            scale: shape.scale(fresnel_inverse),
            rs2,
            rp2,
            cross,
        }
    }

    /// The part of [`Pbrdf::facet_reflection`] that does not depend on N: the facet density and
    /// the shadowing (shared by a material's models over wavelength, docs/design.md §1.9).
    #[inline(always)]
    pub(super) fn facet_shape(&self, geometry: &FacetGeometry, masking: [f64; 2]) -> FacetShape {
        let (exponent, factor) =
            self.facet_shape_exponent::<false>(geometry, masking, self.shadowing);
        FacetShape {
            density: inline_exp(exponent),
            factor,
        }
    }

    /// [`Pbrdf::facet_shape`] as (E, factor) with density e^E, before the exponential, for the
    /// model's `shadowing` (a parameter so that a vectorized loop can take it as a constant:
    /// LLVM does not vectorize a loop around the match on it). `INLINE_LN`: the density's
    /// logarithm for a vectorized loop (see `PreparedDistribution::slope_pdf_exponent_and_factor`).
    #[inline(always)]
    fn facet_shape_exponent<const INLINE_LN: bool>(
        &self,
        geometry: &FacetGeometry,
        masking: [f64; 2],
        shadowing: Shadowing,
    ) -> (f64, f64) {
        let FacetGeometry {
            cos_i,
            cos_r,
            tan2_theta,
            cos2_beta,
        } = *geometry;
        let g = shadowing.factor_with_masking(cos_i, cos_r, cos2_beta, masking);
        // P(θ)/(4 cosθ cosθ_i cosθ_r) = D(θ)/(4 cosθ_i cosθ_r) with D = P/cosθ = c e^E.
        let (density_exponent, density_factor) = self
            .prepared
            .normal_distribution_exponent_and_factor::<INLINE_LN>(tan2_theta);
        (density_exponent, density_factor * g / (4.0 * cos_i * cos_r))
    }

    /// ε = N², the Fresnel coefficients' parameter.
    pub(super) fn permittivity(&self) -> Complex64 {
        self.permittivity
    }

    /// The full 4×4 Mueller BRDF (sr⁻¹) from `incident` (ω_i, toward the source) to `scattered`
    /// (ω_r, toward the viewer), in the psps frames of both (docs/design.md §1.3). Zero below the horizon.
    #[inline]
    pub fn mueller(&self, incident: &Direction, scattered: &Direction) -> Mueller {
        match ScatteringGeometry::new(incident, scattered) {
            Some(geometry) => {
                let masking = self.masking_of(&geometry.facet);
                self.mueller_at(&geometry, masking)
            }
            None => Mueller::zeros(),
        }
    }

    /// [`Pbrdf::mueller`] with the per-direction shadowing factors supplied by the caller:
    /// `masking_i` = `self.masking(cos θ_i)`, `masking_r` = `self.masking(cos θ_r)`.
    pub fn mueller_with_masking(
        &self,
        incident: &Direction,
        scattered: &Direction,
        masking_i: f64,
        masking_r: f64,
    ) -> Mueller {
        match ScatteringGeometry::new(incident, scattered) {
            Some(geometry) => self.mueller_at(&geometry, [masking_i, masking_r]),
            None => Mueller::zeros(),
        }
    }

    /// [`Pbrdf::mueller_with_masking`] on a precomputed [`ScatteringGeometry`].
    #[inline]
    pub fn mueller_for_geometry(
        &self,
        geometry: &ScatteringGeometry,
        masking_i: f64,
        masking_r: f64,
    ) -> Mueller {
        self.mueller_at(geometry, [masking_i, masking_r])
    }

    #[inline]
    fn mueller_at(&self, geometry: &ScatteringGeometry, masking: [f64; 2]) -> Mueller {
        let facets_and_depolarizer =
            self.facets_and_depolarizer(geometry, self.facet_shape(&geometry.facet, masking));
        match self.subsurface_mueller(geometry) {
            Some(subsurface) => facets_and_depolarizer + subsurface,
            None => facets_and_depolarizer,
        }
    }

    /// [`Pbrdf::mueller_for_geometry`] of a model without a subsurface term and with shadowing
    /// `shadowing` (its own), without calls or branches that a vectorized loop could not take
    /// (the block evaluation, src/pbrdf/batch.rs):
    /// the density's exponential without its range check. The flag says whether the matrix is
    /// the exact one, i.e. whether the exponent was in the exponential's fast range; where not (a
    /// density below e^−708), the caller recomputes that geometry one at a time.
    #[inline(always)]
    pub(super) fn facets_and_depolarizer_in_range(
        &self,
        geometry: &ScatteringGeometry,
        masking: [f64; 2],
        shadowing: Shadowing,
    ) -> (Mueller, bool) {
        debug_assert_eq!(shadowing, self.shadowing);
        let (exponent, factor) =
            self.facet_shape_exponent::<true>(&geometry.facet, masking, shadowing);
        let shape = FacetShape {
            density: exp_within_range(exponent),
            factor,
        };
        let in_range = exponent > -708.0 && exponent < 709.0;
        (self.facets_and_depolarizer(geometry, shape), in_range)
    }

    /// The facet and depolarizer terms of [`Pbrdf::mueller_at`] for a facet shape.
    #[inline(always)]
    fn facets_and_depolarizer(&self, geometry: &ScatteringGeometry, shape: FacetShape) -> Mueller {
        let facet = self.facet_reflection_with_shape(&geometry.facet, shape);
        // F_fres = [[A, B, 0, 0], [B, A, 0, 0], [0, 0, C, S], [0, 0, −S, C]] with the facet scale
        // folded in: A, B = (|r_s|² ± |r_p|²)/2, C + iS = r_s* r_p.
        let (a, b) = facet.scaled_a_and_b();
        let c = facet.cross.re * facet.scale;
        let s = facet.cross.im * facet.scale;
        geometry.assemble_mueller([a, b, c, s], self.rho_d * FRAC_1_PI)
    }

    /// Whether the model has the subsurface term of docs/design.md §1.10.
    pub(super) fn has_subsurface(&self) -> bool {
        !self.subsurface_lobes.is_empty()
    }

    /// First column F_j0 (sr⁻¹): the Stokes BRDF for unpolarized illumination, the only part that
    /// thermal scenes need. Skips the incident-frame rotation: (A, cos2η_r B, sin2η_r B, 0).
    #[inline]
    pub fn first_column(&self, incident: &Direction, scattered: &Direction) -> Stokes {
        let Some(geometry) = FacetGeometry::new(incident, scattered) else {
            return Stokes::zeros();
        };
        let facet = self.facet_reflection(&geometry, self.masking_of(&geometry));
        let (cr, sr) = double_angle(facet_axis_in_scattered_frame(&incident.vector, scattered));
        let (a, b) = facet.scaled_a_and_b();
        let facets_and_depolarizer = Stokes::new(a + self.rho_d * FRAC_1_PI, cr * b, sr * b, 0.0);
        if self.subsurface_lobes.is_empty() {
            return facets_and_depolarizer;
        }
        // The subsurface term turns with the scattering plane: it needs the incident rotation too.
        ScatteringGeometry::new(incident, scattered).map_or(facets_and_depolarizer, |g| {
            facets_and_depolarizer + self.subsurface_first_column(&g)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cached paths (precomputed geometry, caller-supplied masking) give the same matrix as
    /// the direct one, for every shadowing and at the pole and retroreflection special cases.
    #[test]
    fn precomputed_geometry_and_masking_reproduce_mueller() {
        for shadowing in [
            Shadowing::None,
            Shadowing::TorranceSparrow,
            Shadowing::Smith,
        ] {
            let model = Pbrdf::new(
                SlopeDistribution::Cauchy { sigma: 0.2, q: 2.3 },
                shadowing,
                RefractiveIndex::new(1.5, 0.3),
                0.02,
            )
            .unwrap();
            for (i, r) in [
                ((0.5, 0.0), (0.9, 2.5)),
                ((0.0, 0.3), (0.7, 3.0)),
                ((0.6, 1.0), (0.6, 1.0)),
            ] {
                let incident = Direction::from_angles(i.0, i.1);
                let scattered = Direction::from_angles(r.0, r.1);
                let direct = model.mueller(&incident, &scattered);
                let geometry = ScatteringGeometry::new(&incident, &scattered).unwrap();
                let cached = model.mueller_for_geometry(
                    &geometry,
                    model.masking(geometry.cos_incident()),
                    model.masking(geometry.cos_scattered()),
                );
                assert!(
                    (direct - cached).abs().max() <= 1e-15 * direct.abs().max(),
                    "{shadowing:?} {i:?} {r:?}"
                );
                let first = model.first_column(&incident, &scattered);
                assert!((direct.column(0) - first).abs().max() <= 1e-15 * direct.abs().max());
            }
        }
        let below = Direction::from_angles(1.7, 0.0);
        assert!(ScatteringGeometry::new(&below, &Direction::from_angles(0.3, 0.0)).is_none());
    }
}
