//! Polarization frames — the ONE place they live (docs/design.md §1.1, §1.3, §1.6, §1.7).
//!
//! Convention (SCATMECH "psps"): light propagating along k at a surface with normal n has
//! s = unit(n × k) and p = k × s; the Stokes vector (S0, S1, S2, S3) is referred to (s, p) with
//! S1 > 0 s-polarized, S2 at +45° from s toward p, S3 > 0 left-circular. A frame is therefore fixed
//! by its s axis and k alone: re-expressing a Stokes vector in another frame about the same k is a
//! rotation by the angle η from the old s toward the old p ([`FrameTurn`], Mueller L(η)).
//!
//! Local directions ([`Direction`]) carry their own axes so that θ = 0 takes the limit θ → 0⁺
//! along the given azimuth (SCATMECH's choice). World-space frames of the renderer use
//! [`OutgoingFrame`] (the psps frame of a direction leaving a surface) and
//! [`rotation_between_frames`].

use super::polarization::{FrameTurn, Stokes};
use crate::elementary::sin_cos_degrees;
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
        Direction::from_sines_and_cosines(theta.sin_cos(), phi.sin_cos())
    }

    /// From zenith θ and azimuth φ in degrees (exact at multiples of 90°; see
    /// [`sin_cos_degrees`]).
    #[inline]
    pub fn from_degrees(theta_deg: f64, phi_deg: f64) -> Direction {
        Direction::from_sines_and_cosines(sin_cos_degrees(theta_deg), sin_cos_degrees(phi_deg))
    }

    #[inline(always)]
    pub(crate) fn from_sines_and_cosines(
        (sin_t, cos_t): (f64, f64),
        (sin_p, cos_p): (f64, f64),
    ) -> Direction {
        Direction {
            vector: Vector3::new(sin_t * cos_p, sin_t * sin_p, cos_t),
            azimuthal_axis: Vector3::new(-sin_p, cos_p, 0.0),
            polar_axis: Vector3::new(cos_t * cos_p, cos_t * sin_p, -sin_t),
        }
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

/// The frame of light leaving a surface point with unit normal `normal` along unit `omega`, as the
/// open-world tables index it: e_x uphill (world up projected on the tangent plane; on a
/// horizontal surface the tangential part of ω, or any tangent), e_y = n × e_x, ω at azimuth φ from
/// e_x, and the psps s axis unit(n × ω) (at θ = 0 its limit along φ).
#[derive(Clone, Copy, Debug)]
pub struct OutgoingFrame {
    pub normal: Vector3<f64>,
    /// ω itself (unit, world).
    pub omega: Vector3<f64>,
    /// Uphill tangent e_x; (e_x, n × e_x, n) is right-handed.
    pub uphill: Vector3<f64>,
    /// n · ω.
    pub cos_theta: f64,
    /// n · world up.
    pub cos_tilt: f64,
    /// Azimuth of ω from uphill, in [−π, π].
    pub phi: f64,
    pub s_axis: Vector3<f64>,
}

impl OutgoingFrame {
    pub fn new(normal: &Vector3<f64>, omega: &Vector3<f64>) -> OutgoingFrame {
        let n = *normal;
        let cos_theta = n.dot(omega);
        let up = Vector3::z();
        let cos_tilt = n.dot(&up).clamp(-1.0, 1.0);
        let tangential = omega - n * cos_theta;
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
        let s_axis = if tangential.norm_squared() > 1e-18 {
            n.cross(&tangential).normalize()
        } else {
            let e_y = n.cross(&e_x);
            let (sin_p, cos_p) = phi.sin_cos();
            n.cross(&(e_x * cos_p + e_y * sin_p))
        };
        OutgoingFrame {
            normal: n,
            omega: *omega,
            uphill: e_x,
            cos_theta,
            cos_tilt,
            phi,
            s_axis,
        }
    }

    /// World → local coordinates (e_x, e_y, n): the pBRDF's frame with the macro normal ẑ.
    #[inline]
    pub fn to_local(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let e_y = self.normal.cross(&self.uphill);
        Vector3::new(v.dot(&self.uphill), v.dot(&e_y), v.dot(&self.normal))
    }

    /// Local (e_x, e_y, n) → world coordinates.
    #[inline]
    pub fn to_world(&self, v: &Vector3<f64>) -> Vector3<f64> {
        let e_y = self.normal.cross(&self.uphill);
        self.uphill * v.x + e_y * v.y + self.normal * v.z
    }
}

/// A unit vector perpendicular to unit `n`.
pub fn any_perpendicular(n: &Vector3<f64>) -> Vector3<f64> {
    let helper = if n.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    n.cross(&helper).normalize()
}

/// The turn η with which a Stokes vector referred to s axis `from_s` is re-expressed in the frame
/// with s axis `to_s`, both perpendicular to the propagation direction `k`:
/// S_to = L(η) S_from, η = atan2(to_s · p_from, to_s · from_s), p_from = k × from_s.
#[inline]
pub fn rotation_between_frames(
    from_s: &Vector3<f64>,
    to_s: &Vector3<f64>,
    k: &Vector3<f64>,
) -> FrameTurn {
    let p_from = k.cross(from_s);
    FrameTurn::from_cos_sin(to_s.dot(from_s), to_s.dot(&p_from))
}

/// The turn from the psps frame (s axis `s_axis`) of light leaving along `toward_camera` into the
/// pixel frame of docs/design.md §1.6: x = image right made perpendicular to the ray, y = ω × x
/// (y completing image up, propagation toward the camera). With ψ = atan2(s·y_pix, s·x_pix),
/// the turn is by −ψ.
#[inline]
pub fn camera_frame_turn(
    s_axis: &Vector3<f64>,
    toward_camera: &Vector3<f64>,
    image_right: &Vector3<f64>,
) -> FrameTurn {
    let w_r = toward_camera;
    let x_pix = (image_right - w_r * image_right.dot(w_r)).normalize();
    let y_pix = w_r.cross(&x_pix);
    FrameTurn::from_cos_sin(s_axis.dot(&x_pix), -s_axis.dot(&y_pix))
}

/// A Stokes vector leaving along `toward_camera` with psps s axis `s_axis`, in the pixel frame
/// ([`camera_frame_turn`]).
#[inline]
pub fn stokes_to_camera_frame(
    local: &Stokes,
    s_axis: &Vector3<f64>,
    toward_camera: &Vector3<f64>,
    image_right: &Vector3<f64>,
) -> Stokes {
    camera_frame_turn(s_axis, toward_camera, image_right).apply(local)
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
    fn frame_rotation_composes_and_matches_the_camera_rotation() {
        let k = Vector3::new(0.2, -0.5, 0.8).normalize();
        let a = any_perpendicular(&k);
        let b = k.cross(&a);
        let to = (a * 0.3f64.cos() + b * 0.3f64.sin()).normalize();
        // `to` is 0.3 rad from `a` toward its p axis k × a = b.
        assert!((rotation_between_frames(&a, &to, &k).angle() - 0.3).abs() < 1e-15);
        let stokes = Stokes::new(1.0, 0.4, -0.2, 0.1);
        let direct = rotation_between_frames(&a, &to, &k).apply(&stokes);
        let right = Vector3::new(1.0, 0.2, 0.0);
        let via_camera = stokes_to_camera_frame(&stokes, &a, &k, &right);
        let x_pix = (right - k * right.dot(&k)).normalize();
        let camera_eta = rotation_between_frames(&a, &x_pix, &k);
        assert!((via_camera - camera_eta.apply(&stokes)).norm() < 1e-14);
        assert!((direct[3] - stokes[3]).abs() == 0.0);
    }

    #[test]
    fn outgoing_frame_is_right_handed_and_its_s_axis_is_n_cross_omega() {
        let n = Vector3::new(0.3, 0.1, 0.9).normalize();
        let w = Vector3::new(-0.2, 0.7, 0.5).normalize();
        let f = OutgoingFrame::new(&n, &w);
        let local = f.to_local(&w);
        assert!((f.to_world(&local) - w).norm() < 1e-15);
        assert!((local.z - n.dot(&w)).abs() < 1e-15);
        assert!((local.y.atan2(local.x) - f.phi).abs() < 1e-14);
        assert!((f.s_axis - n.cross(&w).normalize()).norm() < 1e-15);
        // The local Direction's s axis (unit(ẑ × ω)) is the same vector.
        let d = Direction::from_unit_vector(local);
        assert!((f.to_world(&d.azimuthal_axis) - f.s_axis).norm() < 1e-14);
    }
}
