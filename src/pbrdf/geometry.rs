//! Directions in the local surface frame (macro normal ẑ) and the psps polarization frames attached
//! to them (DESIGN §1.1, §1.3).

use super::ModelError;
use nalgebra::Vector3;

/// A unit direction pointing away from the surface, with the horizontal axis ê_φ = unit(ẑ × ω) =
/// (−sin φ, cos φ, 0) that fixes its psps frame. ê_φ is kept explicitly so that θ = 0 takes the
/// limit θ → 0⁺ along the given azimuth φ (SCATMECH's choice), where ẑ × ω itself vanishes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction {
    pub vector: Vector3<f64>,
    pub azimuthal_axis: Vector3<f64>,
}

impl Direction {
    /// From zenith θ and azimuth φ in radians.
    #[inline]
    pub fn from_angles(theta: f64, phi: f64) -> Direction {
        let (sin_t, cos_t) = theta.sin_cos();
        let (sin_p, cos_p) = phi.sin_cos();
        Direction {
            vector: Vector3::new(sin_t * cos_p, sin_t * sin_p, cos_t),
            azimuthal_axis: Vector3::new(-sin_p, cos_p, 0.0),
        }
    }

    /// From zenith and azimuth in degrees, refusing zenith outside [0°, 90°) and non-finite values.
    pub fn from_degrees_checked(
        name: &'static str,
        theta_deg: f64,
        phi_deg: f64,
    ) -> Result<Direction, ModelError> {
        if !(theta_deg.is_finite() && (0.0..90.0).contains(&theta_deg)) {
            return Err(ModelError::Zenith {
                name,
                value: theta_deg,
            });
        }
        if !phi_deg.is_finite() {
            return Err(ModelError::Azimuth {
                name,
                value: phi_deg,
            });
        }
        Ok(Direction::from_angles(
            theta_deg.to_radians(),
            phi_deg.to_radians(),
        ))
    }

    /// From a unit vector; at the pole the azimuth is taken as 0.
    #[inline]
    pub fn from_unit_vector(vector: Vector3<f64>) -> Direction {
        let horizontal = (vector.x * vector.x + vector.y * vector.y).sqrt();
        let azimuthal_axis = if horizontal > 0.0 {
            Vector3::new(-vector.y / horizontal, vector.x / horizontal, 0.0)
        } else {
            Vector3::new(0.0, 1.0, 0.0)
        };
        Direction {
            vector,
            azimuthal_axis,
        }
    }

    #[inline]
    pub fn cos_theta(&self) -> f64 {
        self.vector.z
    }

    /// The psps s axis of light leaving along this direction (k = ω): s = unit(ẑ × k) = ê_φ.
    /// Light arriving from this direction (k = −ω) has s = −ê_φ. p = k × s in both cases.
    #[inline]
    pub fn outgoing_s_axis(&self) -> Vector3<f64> {
        self.azimuthal_axis
    }
}

/// cos 2η and sin 2η of the rotation from the psps frame (s, p = k × s) of propagation k to the
/// facet frame whose s axis is `facet_s` (any length, ⊥ k): cos η = ŝ_loc·s, sin η = ŝ_loc·p.
/// Returned from the unnormalized vector as ((c²−s²)/(c²+s²), 2cs/(c²+s²)), no square root needed.
#[inline]
pub(crate) fn frame_rotation(
    facet_s: &Vector3<f64>,
    s_axis: &Vector3<f64>,
    k: &Vector3<f64>,
) -> (f64, f64) {
    let p_axis = k.cross(s_axis);
    let c = facet_s.dot(s_axis);
    let s = facet_s.dot(&p_axis);
    let inverse_norm2 = 1.0 / (c * c + s * s);
    ((c * c - s * s) * inverse_norm2, 2.0 * c * s * inverse_norm2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuthal_axis_is_z_cross_omega_away_from_the_pole() {
        let d = Direction::from_angles(0.7, 2.1);
        let z_cross = Vector3::z().cross(&d.vector).normalize();
        assert!((z_cross - d.azimuthal_axis).norm() < 1e-15);
        let back = Direction::from_unit_vector(d.vector);
        assert!((back.azimuthal_axis - d.azimuthal_axis).norm() < 1e-15);
    }

    #[test]
    fn normal_direction_keeps_the_given_azimuth() {
        let d = Direction::from_angles(0.0, 0.5);
        assert!(
            (d.azimuthal_axis - Vector3::new(-(0.5f64.sin()), 0.5f64.cos(), 0.0)).norm() < 1e-15
        );
    }

    #[test]
    fn checked_angles_refuse_out_of_range() {
        assert!(Direction::from_degrees_checked("theta_i", 90.0, 0.0).is_err());
        assert!(Direction::from_degrees_checked("theta_i", -1.0, 0.0).is_err());
        assert!(Direction::from_degrees_checked("theta_i", f64::NAN, 0.0).is_err());
        assert!(Direction::from_degrees_checked("phi_i", 10.0, f64::INFINITY).is_err());
        assert!(Direction::from_degrees_checked("theta_i", 89.9, -720.0).is_ok());
    }
}
