//! Importance sampling of incident directions for the renderer's Monte Carlo transport
//! (docs/design.md §1.2, §1.7): a facet normal h drawn from the facets that ω_r sees (the distribution of
//! visible normals, [`super::visible_slopes`]), the incident direction its mirror,
//! ω_i = 2(ω_r·h)h − ω_r. With h distributed by D_r(h) = G1(ω_r) (ω_r·h) D(h)/cosθ_r and
//! dΩ_i = 4 cosβ dΩ_h (cos β = ω_r·h), the density of ω_i is G1(ω_r) D(h)/(4 cosθ_r). Where no
//! visible-normal density exists (Cauchy q ≤ 3/2) h comes from the facet density itself, by its
//! closed-form inverse CDF, and ω_i has the density P(θ_h)/(4 cos β). A cosine-weighted lobe
//! (pdf cosθ_i/π) covers the diffuse term; the two are mixed with a fixed weight, so the mixture
//! pdf is exact everywhere.

use super::visible_slopes::VisibleView;
use super::Pbrdf;
use nalgebra::Vector3;
use std::f64::consts::{FRAC_1_PI, PI};

impl Pbrdf {
    /// The probability of sampling the specular lobe rather than the cosine lobe. Visible
    /// normals cover the whole lobe with the bounded weight F G1(ω_i), so without a diffuse term
    /// every sample goes to the lobe; otherwise the lobe gets most samples and the cosine lobe
    /// enough to cover the diffuse term (and, with facet-density sampling, the lobe's far tail).
    pub fn specular_sampling_weight(&self) -> f64 {
        let diffuse = self.body_albedo().clamp(0.0, 1.0);
        if diffuse == 0.0 && self.visible_slopes().is_some() {
            return 1.0;
        }
        (0.9 - 0.8 * diffuse).clamp(0.1, 0.9)
    }

    /// `scattered` (local, unit, above the surface) prepared for [`Pbrdf::sample_incident`]: what
    /// every sample drawn for it shares, computed once (a pixel's paths all share their first
    /// vertex's).
    pub fn scattered_view(&self, scattered: &Vector3<f64>) -> ScatteredView {
        let sin_theta = scattered.x.hypot(scattered.y);
        let azimuth = if sin_theta > 0.0 {
            [scattered.x / sin_theta, scattered.y / sin_theta]
        } else {
            [1.0, 0.0]
        };
        ScatteredView {
            direction: *scattered,
            masking: self.masking(scattered.z),
            azimuth,
            visible: (self.visible_slopes()).map(|v| v.view(scattered.z / sin_theta)),
        }
    }

    /// Draws ω_i (local frame, macro normal ẑ) for light scattered along `view`'s direction from
    /// the mixture of the facet-lobe and cosine densities, with uniforms `u` ∈ [0, 1)². `u[0]` both
    /// chooses the lobe (below the lobe's weight w) and, rescaled to [0, 1), gives the first
    /// coordinate within it (the visible slope along ω_r's azimuth, or the radius); `u[1]` gives
    /// the second (the slope across it, or the azimuth). Stratifying `u[0]` over a pixel's samples
    /// therefore allocates the two lobes in proportion (Veach's multi-sample estimator with the
    /// balance heuristic is then exactly f/pdf_mixture per sample) and stratifies each lobe.
    /// Returns ω_i and its mixture pdf (sr⁻¹), or `None` for a direction below the
    /// horizon (such samples carry zero BRDF; they count as drawn).
    pub fn sample_incident(
        &self,
        view: &ScatteredView,
        u: [f64; 2],
    ) -> Option<(Vector3<f64>, f64)> {
        let weight = self.specular_sampling_weight();
        let scattered = &view.direction;
        let phi = 2.0 * PI * u[1];
        if u[0] >= weight {
            // Malley: a uniform point on the disc lifted to the hemisphere.
            let r2 = ((u[0] - weight) / (1.0 - weight)).clamp(0.0, 1.0);
            let r = r2.sqrt();
            let incident = Vector3::new(r * phi.cos(), r * phi.sin(), (1.0 - r2).sqrt());
            let pdf = self.mixture_pdf(view, &incident);
            return (pdf > 0.0 && pdf.is_finite()).then_some((incident, pdf));
        }
        let lobe_point = [u[0] / weight, u[1]];
        let (h, tan2) = match (self.visible_slopes(), &view.visible) {
            (Some(sampler), Some(visible)) => {
                // The slope drawn at azimuth 0, rotated back by ω_r's azimuth φ.
                let [x, y] = sampler.sample(visible, lobe_point);
                let [cos_phi, sin_phi] = view.azimuth;
                let (mx, my) = (cos_phi * x - sin_phi * y, sin_phi * x + cos_phi * y);
                (Vector3::new(-mx, -my, 1.0).normalize(), x * x + y * y)
            }
            _ => {
                let tan2 = self.distribution().slope_quantile(lobe_point[0]).powi(2);
                let cos_h = 1.0 / (1.0 + tan2).sqrt();
                let sin_h = tan2.sqrt() * cos_h;
                let h = Vector3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
                (h, tan2)
            }
        };
        let cos_beta = scattered.dot(&h);
        if cos_beta <= 0.0 {
            return None;
        }
        let incident = h * (2.0 * cos_beta) - scattered;
        if incident.z <= 0.0 {
            return None;
        }
        // The facet just drawn gives the lobe's density without re-deriving it from ω_i + ω_r.
        let pdf = mixture(weight, self.lobe_pdf(view, tan2, h.z, cos_beta), &incident);
        (pdf > 0.0 && pdf.is_finite()).then_some((incident, pdf))
    }

    /// The mixture density (sr⁻¹) with which [`Pbrdf::sample_incident`] draws unit `incident`
    /// for unit `scattered`.
    pub fn incident_pdf(&self, scattered: &Vector3<f64>, incident: &Vector3<f64>) -> f64 {
        self.mixture_pdf(&self.scattered_view(scattered), incident)
    }

    /// [`Pbrdf::incident_pdf`] for a prepared view.
    fn mixture_pdf(&self, view: &ScatteredView, incident: &Vector3<f64>) -> f64 {
        if incident.z <= 0.0 {
            return 0.0;
        }
        let weight = self.specular_sampling_weight();
        let half = incident + view.direction;
        let lobe = if half.z > 0.0 {
            let h = half.normalize();
            let tan2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
            self.lobe_pdf(view, tan2, h.z, incident.dot(&h))
        } else {
            0.0
        };
        mixture(weight, lobe, incident)
    }

    /// The facet lobe's density (sr⁻¹) of the ω_i mirrored by the facet h with tan²θ_h = `tan2`,
    /// cosθ_h = `cos_h` and ω_i·h = `cos_beta`. Facet density P(θ_h) = p(tanθ_h)/cos³θ_h and
    /// D = P/cosθ_h; with visible normals G1(ω_r) D/(4 cosθ_r) = G1 p (1 + tan²θ_h)²/(4 cosθ_r),
    /// without them P/(4 cos β).
    fn lobe_pdf(&self, view: &ScatteredView, tan2: f64, cos_h: f64, cos_beta: f64) -> f64 {
        let slope_density = self.prepared_distribution().slope_pdf(tan2);
        match &view.visible {
            Some(visible) => {
                let secant2 = 1.0 + tan2;
                visible.masking() * slope_density * secant2 * secant2 / (4.0 * view.direction.z)
            }
            None => slope_density / (cos_h * cos_h * cos_h * 4.0 * cos_beta),
        }
    }
}

/// The mixture density of the facet lobe (density `lobe`, chosen with probability `weight`) and
/// the cosine lobe cosθ_i/π at unit `incident`.
fn mixture(weight: f64, lobe: f64, incident: &Vector3<f64>) -> f64 {
    weight * lobe + (1.0 - weight) * incident.z * FRAC_1_PI
}

/// A scattered direction prepared for sampling ([`Pbrdf::scattered_view`]).
#[derive(Clone, Copy, Debug)]
pub struct ScatteredView {
    /// ω_r, local and unit.
    pub direction: Vector3<f64>,
    /// The model's G1(ω_r) ([`Pbrdf::masking`]), which shading needs with every sample.
    pub masking: f64,
    /// (cos φ_r, sin φ_r): the visible slopes are drawn at azimuth 0 and turned by it.
    azimuth: [f64; 2],
    /// The visible-normal sampler's view of ω_r; `None` where there is no such sampler.
    visible: Option<VisibleView>,
}

#[cfg(test)]
mod tests {
    use crate::optics::RefractiveIndex;
    use crate::pbrdf::{Pbrdf, Shadowing, SlopeDistribution};
    use nalgebra::Vector3;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// E[f/pdf] over the samples equals ∫ f dΩ for the mixture pdf: with f = the pdf itself on a
    /// test cap the estimator must give the cap's probability, and the pdf integrates to one.
    #[test]
    fn sampled_directions_follow_their_pdf() {
        // Visible normals with and without the cosine lobe, at a moderate and a grazing view;
        // facet-density sampling where no visible-normal density exists (q ≤ 3/2).
        for (distribution, shadowing, rho_d, theta_r) in [
            (
                SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
                Shadowing::Smith,
                0.2,
                0.5f64,
            ),
            (
                SlopeDistribution::Gaussian { sigma: 0.1 },
                Shadowing::Smith,
                0.2,
                0.5,
            ),
            (
                SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
                Shadowing::Smith,
                0.0,
                1.4,
            ),
            (
                SlopeDistribution::Gaussian { sigma: 0.15 },
                Shadowing::None,
                0.0,
                1.3,
            ),
            (
                SlopeDistribution::Cauchy { sigma: 0.2, q: 1.3 },
                Shadowing::None,
                0.0,
                0.5,
            ),
        ] {
            let pbrdf = Pbrdf::new(
                distribution,
                shadowing,
                RefractiveIndex::new(1.5, 0.1),
                rho_d,
            )
            .unwrap();
            let w_r = Vector3::new(theta_r.sin(), 0.0, theta_r.cos());
            let view = pbrdf.scattered_view(&w_r);
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            // Fraction of samples inside a cap around the specular direction, against the
            // integral of the pdf over the cap by a fine quadrature.
            let axis = Vector3::new(-w_r.x, 0.0, w_r.z).normalize();
            let cap = 0.3f64.cos();
            let n = 400_000;
            let mut inside = 0usize;
            for _ in 0..n {
                let u = [rng.random(), rng.random()];
                if let Some((w, _)) = pbrdf.sample_incident(&view, u) {
                    inside += (w.dot(&axis) > cap) as usize;
                }
            }
            let (mut total, mut in_cap) = (0.0, 0.0);
            let (nt, np) = (800, 800);
            for i in 0..nt {
                let theta = (i as f64 + 0.5) / nt as f64 * std::f64::consts::FRAC_PI_2;
                for j in 0..np {
                    let phi = (j as f64 + 0.5) / np as f64 * 2.0 * std::f64::consts::PI;
                    let w = Vector3::new(
                        theta.sin() * phi.cos(),
                        theta.sin() * phi.sin(),
                        theta.cos(),
                    );
                    let d = pbrdf.incident_pdf(&w_r, &w)
                        * theta.sin()
                        * (std::f64::consts::FRAC_PI_2 / nt as f64)
                        * (2.0 * std::f64::consts::PI / np as f64);
                    total += d;
                    if w.dot(&axis) > cap {
                        in_cap += d;
                    }
                }
            }
            // Samples below the horizon are lost, so the pdf integrates to ≤ 1 (to ~0.6 for the
            // heavy q = 1.3 tail sampled by facet density).
            assert!(
                total <= 1.0 + 1e-3 && total > 0.5,
                "{distribution:?}: {total}"
            );
            let observed = inside as f64 / n as f64;
            let sigma = (in_cap * (1.0 - in_cap) / n as f64).sqrt();
            assert!(
                (observed - in_cap).abs() < 4.0 * sigma + 1e-4,
                "{distribution:?}: {observed} vs {in_cap}"
            );
        }
    }

    /// With visible normals and no diffuse term, a sample's weight f cosθ_i/pdf is the facet's
    /// Fresnel reflectance times Smith's G1(ω_i): bounded by 1, and large only where the pBRDF is.
    #[test]
    fn visible_normal_weight_is_fresnel_times_masking() {
        use crate::optics::{Direction, FresnelFractions};
        let index = RefractiveIndex::new(3.0, 20.0);
        for distribution in [
            SlopeDistribution::Gaussian { sigma: 0.15 },
            SlopeDistribution::Cauchy { sigma: 0.2, q: 2.2 },
        ] {
            let pbrdf = Pbrdf::new(distribution, Shadowing::Smith, index, 0.0).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(5);
            for theta_r in [0.1f64, 0.9, 1.45] {
                let w_r = Vector3::new(theta_r.sin() * 0.6, theta_r.sin() * 0.8, theta_r.cos());
                let view = pbrdf.scattered_view(&w_r);
                for _ in 0..200 {
                    let u = [rng.random(), rng.random()];
                    let Some((w_i, pdf)) = pbrdf.sample_incident(&view, u) else {
                        continue;
                    };
                    let m00 = pbrdf.mueller(
                        &Direction::from_unit_vector(w_i),
                        &Direction::from_unit_vector(w_r),
                    )[(0, 0)];
                    let cos_beta = (w_i + w_r).normalize().dot(&w_r);
                    let (rs2, rp2, _) = FresnelFractions::new(cos_beta, index.permittivity())
                        .reflectances_and_cross();
                    let expected = 0.5 * (rs2 + rp2) * pbrdf.masking(w_i.z);
                    let weight = m00 * w_i.z / pdf;
                    assert!(
                        (weight - expected).abs() < 1e-9 * expected && weight <= 1.0,
                        "{distribution:?} θ_r = {theta_r}: {weight} vs {expected}"
                    );
                }
            }
        }
    }

    /// The estimator Σ f cosθ_i/pdf over a stratified grid of uniforms integrates the pBRDF's
    /// directional albedo to what the hemispherical quadrature gives (1 − ε by Kirchhoff), for
    /// a glossy metal and dielectric from normal to grazing views: no bias from the
    /// visible-normal sampler, its normalization or the dropped cosine lobe.
    #[test]
    fn visible_normal_samples_integrate_the_albedo() {
        use crate::optics::Direction;
        use crate::pbrdf::HemisphereQuadrature;
        for (distribution, n, k) in [
            (SlopeDistribution::Gaussian { sigma: 0.15 }, 3.0, 20.0),
            (SlopeDistribution::Gaussian { sigma: 0.2 }, 1.5, 0.1),
            (SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 }, 1.5, 0.1),
        ] {
            let index = RefractiveIndex::new(n, k);
            let pbrdf = Pbrdf::new(distribution, Shadowing::Smith, index, 0.0).unwrap();
            for theta in [0.3f64, 1.0, 1.3, 1.5] {
                let w_r = Vector3::new(theta.sin(), 0.0, theta.cos());
                let view = pbrdf.scattered_view(&w_r);
                let m = 1000;
                let mut sum = 0.0;
                for i in 0..m {
                    for j in 0..m {
                        let u = [(i as f64 + 0.5) / m as f64, (j as f64 + 0.5) / m as f64];
                        if let Some((w_i, pdf)) = pbrdf.sample_incident(&view, u) {
                            let m00 = pbrdf.mueller(
                                &Direction::from_unit_vector(w_i),
                                &Direction::from_unit_vector(w_r),
                            )[(0, 0)];
                            sum += m00 * w_i.z / pdf;
                        }
                    }
                }
                let sampled = sum / (m * m) as f64;
                let albedo = 1.0 - pbrdf.emissivity(theta, &HemisphereQuadrature::fine())[0];
                assert!(
                    (sampled / albedo - 1.0).abs() < 3e-4,
                    "{distribution:?} θ = {theta}: {sampled} vs {albedo}"
                );
            }
        }
    }
}
