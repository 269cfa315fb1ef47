//! Directions in the local surface frame (macro normal ẑ) and the psps polarization frames attached
//! to them (DESIGN §1.1, §1.3).

use super::ModelError;
use nalgebra::Vector3;

/// A unit direction pointing away from the surface, with the horizontal axis ê_φ = unit(ẑ × ω) =
/// (−sin φ, cos φ, 0) that fixes its psps frame, and ê_θ = ê_φ × ω = (cosθ cosφ, cosθ sinφ, −sinθ).
/// The axes are kept explicitly so that θ = 0 takes the limit θ → 0⁺ along the given azimuth φ
/// (SCATMECH's choice), where ẑ × ω itself vanishes. Light leaving along ω (k = ω) has its psps
/// s axis unit(ẑ × k) = ê_φ; light arriving from ω (k = −ω) has s = −ê_φ; p = k × s in both cases.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction {
    pub vector: Vector3<f64>,
    pub azimuthal_axis: Vector3<f64>,
    pub polar_axis: Vector3<f64>,
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
            polar_axis: Vector3::new(cos_t * cos_p, cos_t * sin_p, -sin_t),
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
            polar_axis: azimuthal_axis.cross(&vector),
        }
    }

    #[inline]
    pub fn cos_theta(&self) -> f64 {
        self.vector.z
    }
}

/// The facet s axis ω_i × h ∝ ω_i × ω_r (h × k_in, ⊥ to both propagation directions) in the psps
/// frame of the light incident from `incident`, with `scattered` = ω_r: (cos η_i, sin η_i) up to a
/// common positive factor. There k = −ω_i, s = −ê_φ, p = k × s = −ê_θ, so with the triple-product identities
/// cos η ∝ (ω_i × ω_r)·(−ê_φ) = −ω_r·ê_θ and sin η ∝ (ω_i × ω_r)·(−ê_θ) = ω_r·ê_φ.
#[inline]
pub(crate) fn facet_axis_in_incident_frame(
    incident: &Direction,
    scattered: &Vector3<f64>,
) -> (f64, f64) {
    (
        -scattered.dot(&incident.polar_axis),
        scattered.dot(&incident.azimuthal_axis),
    )
}

/// The facet s axis ω_i × ω_r in the psps frame of the light scattered along `scattered`, with
/// `incident` = ω_i (k = ω_r, s = ê_φ, p = −ê_θ): cos η ∝ −ω_i·ê_θ, sin η ∝ −ω_i·ê_φ (see
/// [`facet_axis_in_incident_frame`]).
#[inline]
pub(crate) fn facet_axis_in_scattered_frame(
    incident: &Vector3<f64>,
    scattered: &Direction,
) -> (f64, f64) {
    (
        -incident.dot(&scattered.polar_axis),
        -incident.dot(&scattered.azimuthal_axis),
    )
}

/// (cos 2η, sin 2η) from (cos η, sin η) scaled by any common factor: ((c²−s²)/(c²+s²), 2cs/(c²+s²)),
/// no square root needed. At exact retroreflection (ω_i = ω_r) the facet plane is undefined and
/// any facet s axis gives the same matrix; take the frame's own s axis there.
#[inline]
pub(crate) fn double_angle((c, s): (f64, f64)) -> (f64, f64) {
    let norm2 = c * c + s * s;
    if norm2 < 1e-30 {
        return (1.0, 0.0);
    }
    let inverse_norm2 = 1.0 / norm2;
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
    fn polar_axis_completes_a_right_handed_frame() {
        for d in [
            Direction::from_angles(0.7, 2.1),
            Direction::from_angles(0.0, 0.5),
            Direction::from_unit_vector(Vector3::new(0.3, -0.4, 0.5).normalize()),
        ] {
            // (ω, ê_θ, ê_φ) is the right-handed spherical frame (ê_r, ê_θ, ê_φ).
            assert!((d.vector.cross(&d.polar_axis) - d.azimuthal_axis).norm() < 1e-15);
            assert!((d.polar_axis.norm() - 1.0).abs() < 1e-15);
        }
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
