//! The Stokes vector leaving a surface point toward the camera, in the pixel frame:
//!
//!   S_j = ε_j(θ_r) L_bb(T) + ∫ F_j0(ω_i→ω_r) L_env(ω_i) cosθ_i dΩ_i      (DESIGN §1.5)
//!
//! evaluated in the local frame of the shading normal (tables of [`super::tables`]), then rotated
//! from the psps frame of ω_r (s = unit(n × ω_r)) into the pixel frame (x = image right made
//! perpendicular to the ray, y = x × … = image up, propagation toward the camera): with
//! ψ = atan2(s·y_pix, s·x_pix), S' = rotate_stokes(S, −ψ) (DESIGN §1.6).

use super::tables::{MaterialTables, RadianceTable, THETA_MAX};
use crate::optics::{rotate_stokes, Stokes};
use crate::scene::camera::Camera;
use nalgebra::Vector3;

/// Everything shading needs that is shared by all pixels.
pub struct Shader<'a> {
    pub camera: &'a Camera,
    /// Per material.
    pub tables: &'a [MaterialTables],
    pub radiance: &'a RadianceTable,
}

impl Shader<'_> {
    /// (S0, S1, S2) in the pixel frame leaving `point` with unit shading normal `normal` at
    /// `temperature`, material `material`; `back` shades the other side of the surface (the
    /// camera sees a face from behind). A normal that faces away from the camera otherwise (an
    /// interpolated normal at a silhouette) is read at grazing.
    pub fn shade(
        &self,
        material: usize,
        point: &Vector3<f64>,
        normal: &Vector3<f64>,
        back: bool,
        temperature: f64,
    ) -> [f64; 3] {
        let w_r = (self.camera.position - point).normalize();
        let n = if back { -normal } else { *normal };
        let cos_r = n.dot(&w_r);

        // Local frame: e_x uphill (world up projected on the tangent plane), e_y = n × e_x.
        let up = Vector3::z();
        let cos_tilt = n.dot(&up).clamp(-1.0, 1.0);
        let tangential = w_r - n * cos_r;
        let uphill = up - n * cos_tilt;
        let (e_x, phi) = if uphill.norm_squared() > 1e-18 {
            let e_x = uphill.normalize();
            let e_y = n.cross(&e_x);
            (e_x, tangential.dot(&e_y).atan2(tangential.dot(&e_x)))
        } else if tangential.norm_squared() > 1e-18 {
            // Horizontal surface: no uphill; every azimuth is alike.
            (tangential.normalize(), 0.0)
        } else {
            (any_perpendicular(&n), 0.0)
        };
        // psps s axis of ω_r: unit(n × ω_r); at θ_r = 0 its limit along the azimuth φ.
        let s_axis = if tangential.norm_squared() > 1e-18 {
            n.cross(&tangential).normalize()
        } else {
            let e_y = n.cross(&e_x);
            let (sin_p, cos_p) = phi.sin_cos();
            n.cross(&(e_x * cos_p + e_y * sin_p))
        };

        let tables = &self.tables[material];
        // Silhouettes: interpolated normals may face slightly away; read the grazing limit.
        let cos_table = cos_r.max(THETA_MAX.cos());
        let e = tables.emissivity(cos_table);
        let r = tables.reflected(cos_tilt.acos(), cos_table, phi);
        let l = self.radiance.radiance(temperature);
        let local = Stokes::new(e[0] * l + r[0], e[1] * l + r[1], r[2], 0.0);

        let right = self.camera.right;
        let x_pix = (right - w_r * right.dot(&w_r)).normalize();
        let y_pix = w_r.cross(&x_pix);
        let psi = s_axis.dot(&y_pix).atan2(s_axis.dot(&x_pix));
        let pixel = rotate_stokes(&local, -psi);
        [pixel[0], pixel[1], pixel[2]]
    }
}

fn any_perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&helper).normalize()
}

/// DoLP = √(S1² + S2²)/S0 (0 where S0 ≤ 0) and AoP = ½ atan2(S2, S1) in (−π/2, π/2], radians
/// counter-clockwise from image right (DESIGN §1.6).
#[inline]
pub fn dolp_aop(s: [f64; 3]) -> (f64, f64) {
    let linear = s[1].hypot(s[2]);
    let dolp = if s[0] > 0.0 { linear / s[0] } else { 0.0 };
    let mut aop = 0.5 * s[2].atan2(s[1]);
    if aop <= -std::f64::consts::FRAC_PI_2 {
        aop += std::f64::consts::PI;
    }
    (dolp, aop)
}

/// Polarizer image I(α) = ½(S0 + S1 cos2α + S2 sin2α) (DESIGN §1.6).
#[inline]
pub fn polarizer(s: [f64; 3], alpha: f64) -> f64 {
    let (sin2, cos2) = (2.0 * alpha).sin_cos();
    0.5 * (s[0] + s[1] * cos2 + s[2] * sin2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};

    #[test]
    fn aop_and_polarizers_follow_the_stokes_convention() {
        // Horizontal (along image right) linear polarization.
        let (d, a) = dolp_aop([2.0, 1.0, 0.0]);
        assert!((d - 0.5).abs() < 1e-15 && a.abs() < 1e-15);
        // Vertical: AoP = +π/2 (not −π/2).
        let (_, a) = dolp_aop([1.0, -1.0, 0.0]);
        assert!((a - FRAC_PI_2).abs() < 1e-15);
        let (_, a) = dolp_aop([1.0, 0.0, 1.0]);
        assert!((a - FRAC_PI_4).abs() < 1e-15);
        let s = [1.0, 0.3, -0.2];
        assert!((polarizer(s, 0.0) + polarizer(s, FRAC_PI_2) - 1.0).abs() < 1e-15);
        assert!((polarizer(s, 0.0) - polarizer(s, FRAC_PI_2) - 0.3).abs() < 1e-15);
        assert!((polarizer(s, FRAC_PI_4) - polarizer(s, 3.0 * FRAC_PI_4) + 0.2).abs() < 1e-15);
    }
}
