//! Importance sampling of incident directions for the renderer's Monte Carlo transport
//! (DESIGN §1.2, §1.7): a facet slope m drawn from the slope density by its closed-form inverse
//! CDF, the incident direction its mirror, ω_i = 2(ω_r·h)h − ω_r. With h distributed by the
//! normalized facet density P(θ_h) (∫ P dΩ_h = 1, DESIGN §1.2) and dΩ_i = 4 cosβ dΩ_h, the density
//! of ω_i is P(θ_h)/(4 cos β), cos β = ω_i·h. A cosine-weighted lobe (pdf cosθ_i/π) covers the
//! diffuse term; the two are mixed with a fixed weight, so the mixture pdf is exact everywhere.

use super::Pbrdf;
use nalgebra::Vector3;
use std::f64::consts::{FRAC_1_PI, PI};

impl Pbrdf {
    /// The probability of sampling the specular lobe rather than the cosine lobe: the lobe gets
    /// most samples, the cosine lobe enough to cover the diffuse term and the lobe's far tail.
    pub fn specular_sampling_weight(&self) -> f64 {
        let diffuse = self.rho_d().clamp(0.0, 1.0);
        (0.9 - 0.8 * diffuse).clamp(0.1, 0.9)
    }

    /// Draws ω_i (local frame, macro normal ẑ) for light scattered along unit `scattered` from
    /// the mixture of the facet-lobe and cosine densities, with uniforms `u` ∈ [0, 1)². `u[0]` both
    /// chooses the lobe (below the lobe's weight w) and, rescaled to [0, 1), gives the radial
    /// coordinate within it; `u[1]` gives the azimuth. Stratifying `u[0]` over a pixel's samples
    /// therefore allocates the two lobes in proportion (Veach's multi-sample estimator with the
    /// balance heuristic is then exactly f/pdf_mixture per sample) and stratifies each lobe
    /// radially. Returns ω_i and its mixture pdf (sr⁻¹), or `None` for a direction below the
    /// horizon (such samples carry zero BRDF; they count as drawn).
    pub fn sample_incident(
        &self,
        scattered: &Vector3<f64>,
        u: [f64; 2],
    ) -> Option<(Vector3<f64>, f64)> {
        let weight = self.specular_sampling_weight();
        let phi = 2.0 * PI * u[1];
        let incident = if u[0] < weight {
            let tan2 = self.distribution().slope_quantile(u[0] / weight).powi(2);
            let cos_h = 1.0 / (1.0 + tan2).sqrt();
            let sin_h = tan2.sqrt() * cos_h;
            let h = Vector3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
            let cos_beta = scattered.dot(&h);
            if cos_beta <= 0.0 {
                return None;
            }
            h * (2.0 * cos_beta) - scattered
        } else {
            // Malley: a uniform point on the disc lifted to the hemisphere.
            let r2 = ((u[0] - weight) / (1.0 - weight)).clamp(0.0, 1.0);
            let r = r2.sqrt();
            Vector3::new(r * phi.cos(), r * phi.sin(), (1.0 - r2).sqrt())
        };
        if incident.z <= 0.0 {
            return None;
        }
        let pdf = self.incident_pdf(scattered, &incident);
        (pdf > 0.0 && pdf.is_finite()).then_some((incident, pdf))
    }

    /// The mixture density (sr⁻¹) with which [`Pbrdf::sample_incident`] draws unit `incident`
    /// for unit `scattered`.
    pub fn incident_pdf(&self, scattered: &Vector3<f64>, incident: &Vector3<f64>) -> f64 {
        if incident.z <= 0.0 {
            return 0.0;
        }
        let weight = self.specular_sampling_weight();
        let cosine = incident.z * FRAC_1_PI;
        let half = incident + scattered;
        let lobe = if half.z > 0.0 {
            let h = half.normalize();
            let tan2 = (h.x * h.x + h.y * h.y) / (h.z * h.z);
            let density = self.prepared_distribution().slope_pdf(tan2) / h.z.powi(3);
            density / (4.0 * incident.dot(&h))
        } else {
            0.0
        };
        weight * lobe + (1.0 - weight) * cosine
    }
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
        for distribution in [
            SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
            SlopeDistribution::Gaussian { sigma: 0.1 },
        ] {
            let pbrdf = Pbrdf::new(
                distribution,
                Shadowing::Smith,
                RefractiveIndex::new(1.5, 0.1),
                0.2,
            )
            .unwrap();
            let w_r = Vector3::new(0.5f64.sin(), 0.0, 0.5f64.cos());
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            // Fraction of samples inside a cap around the specular direction, against the
            // integral of the pdf over the cap by a fine quadrature.
            let axis = Vector3::new(-w_r.x, 0.0, w_r.z);
            let cap = 0.3f64.cos();
            let n = 400_000;
            let mut inside = 0usize;
            for _ in 0..n {
                let u = [rng.random(), rng.random()];
                if let Some((w, _)) = pbrdf.sample_incident(&w_r, u) {
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
            // Samples below the horizon are lost, so the pdf integrates to ≤ 1.
            assert!(
                total <= 1.0 + 1e-3 && total > 0.9,
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
}
