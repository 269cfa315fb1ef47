//! The sun as the renderer sees it (docs/design.md §1.7): a disc of angular diameter 0.533° and uniform,
//! unpolarized radiance L_sun = E_sun/Ω, where E_sun is its band irradiance on a surface facing it
//! (its position and brightness: [`super::sun`]).
//!
//! Reflected sunlight, ∫_disc F(ω→ω_r) L_sun cosθ dΩ, is integrated over the disc by a fixed
//! quadrature whose size follows the lobe: one node at the centre for rough surfaces (the lobe is
//! flat across 0.27°), polar Gauss rules for smooth ones, so that a glint on glass is the lobe
//! integrated over the disc, not one direction. Visibility is estimated separately by shadow
//! rays to stratified points of the disc (a fraction V), and the sun term is V × the integral:
//! exact where the disc is wholly visible or hidden, so a lit or shadowed point has no noise and
//! only penumbrae are estimated.

use super::sun::{SunPosition, SUN_HALF_ANGLE_DEG};
use crate::optics::frame::any_perpendicular;
use crate::pbrdf::Pbrdf;
use gauss_quad::legendre::GaussLegendre;
use nalgebra::Vector3;
use std::f64::consts::PI;
use std::num::NonZeroUsize;

/// Angular radius of the solar disc, radians.
const SUN_ANGULAR_RADIUS: f64 = SUN_HALF_ANGLE_DEG * PI / 180.0;

/// The sun of a scene: where it is and how bright.
#[derive(Clone, Copy, Debug)]
pub struct Sun {
    /// Unit vector toward the disc centre (world frame).
    pub direction: Vector3<f64>,
    /// Band irradiance on a surface facing the sun, W m⁻².
    pub irradiance: f64,
}

/// Quadrature nodes over the disc: world directions and weights summing to one.
#[derive(Clone, Debug)]
pub struct DiscQuadrature {
    pub nodes: Vec<(Vector3<f64>, f64)>,
}

impl Sun {
    /// Elevation and azimuth (clockwise from north) of the disc centre: the inverse of
    /// [`super::sun_direction`].
    pub fn position(&self) -> SunPosition {
        let d = self.direction;
        SunPosition {
            elevation_deg: d.z.clamp(-1.0, 1.0).asin().to_degrees(),
            azimuth_deg: d.x.atan2(d.y).to_degrees().rem_euclid(360.0),
        }
    }

    /// The disc point of area fraction (u, v) ∈ [0, 1)²: radius r√u, angle 2πv.
    pub fn disc_point(&self, u: f64, v: f64) -> Vector3<f64> {
        let (e1, e2) = self.tangents();
        let rho = SUN_ANGULAR_RADIUS * u.sqrt();
        let (sin_p, cos_p) = (2.0 * PI * v).sin_cos();
        (self.direction + (e1 * cos_p + e2 * sin_p) * rho.tan()).normalize()
    }

    fn tangents(&self) -> (Vector3<f64>, Vector3<f64>) {
        let e1 = any_perpendicular(&self.direction);
        (e1, self.direction.cross(&e1))
    }

    /// The disc quadrature for `pbrdf`: one node where the reflected lobe is wide compared with
    /// the disc (mirror-angle width 2σ ≥ 10 disc radii: the centre rule errs by ~(r/2σ)²/8 <
    /// 1e-3 relative), else a polar rule, Gauss–Legendre in area and uniform in angle, with about
    /// three radial nodes per lobe width across the disc.
    pub fn quadrature(&self, pbrdf: &Pbrdf) -> DiscQuadrature {
        let lobe = 2.0 * pbrdf.distribution().sigma();
        let radial = (3.0 * SUN_ANGULAR_RADIUS / lobe).ceil().min(24.0) as usize;
        if lobe >= 10.0 * SUN_ANGULAR_RADIUS || radial <= 1 {
            return DiscQuadrature {
                nodes: vec![(self.direction, 1.0)],
            };
        }
        let angular = 2 * radial + 2;
        let Some(order) = NonZeroUsize::new(radial) else {
            return DiscQuadrature {
                nodes: vec![(self.direction, 1.0)],
            };
        };
        let rule = GaussLegendre::new(order);
        let mut nodes = Vec::with_capacity(radial * angular);
        for &(x, w) in rule.as_node_weight_pairs() {
            // Nodes on [−1, 1] with weights summing to 2 → area fraction u ∈ [0, 1].
            let u = 0.5 * (x + 1.0);
            for k in 0..angular {
                let v = (k as f64 + 0.5) / angular as f64;
                nodes.push((self.disc_point(u, v), 0.5 * w / angular as f64));
            }
        }
        DiscQuadrature { nodes }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn disc_quadrature_weights_sum_to_one_and_nodes_lie_on_the_disc() {
        use crate::optics::RefractiveIndex;
        use crate::pbrdf::{Shadowing, SlopeDistribution};
        let sun = Sun {
            direction: crate::emitter::sun_direction(35.0, 200.0),
            irradiance: 1.0,
        };
        let smooth = Pbrdf::new(
            SlopeDistribution::Gaussian { sigma: 0.002 },
            Shadowing::Smith,
            RefractiveIndex::new(1.5, 0.0),
            0.0,
        )
        .unwrap();
        let q = sun.quadrature(&smooth);
        assert!(q.nodes.len() > 10);
        let total: f64 = q.nodes.iter().map(|(_, w)| w).sum();
        assert!((total - 1.0).abs() < 1e-12);
        for (d, _) in &q.nodes {
            let angle = d.dot(&sun.direction).clamp(-1.0, 1.0).acos();
            assert!(angle <= SUN_ANGULAR_RADIUS * (1.0 + 1e-9));
        }
        // The mean of ρ² over the disc (uniform in area) is r²/2.
        let mean_r2: f64 = q
            .nodes
            .iter()
            .map(|(d, w)| w * d.dot(&sun.direction).clamp(-1.0, 1.0).acos().powi(2))
            .sum();
        assert!((mean_r2 / (0.5 * SUN_ANGULAR_RADIUS.powi(2)) - 1.0).abs() < 1e-6);
    }
}
