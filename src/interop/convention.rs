//! Mitsuba's `measured_polarized` conventions against irpol's psps (docs/design.md §2.10): the
//! half/difference angles (θ_h, θ_d, φ_d) of a pair of directions and back, and a Mueller BRDF
//! re-expressed between the psps frames of docs/design.md §1.3 and the table's frames.
//!
//! The table refers both beams to x = unit(L × V) (input travelling along −L, output along V),
//! y = k × x, and counts S3 with the opposite sign (D = diag(1, 1, 1, −1)). So a psps Mueller
//! matrix M becomes T = D R_out M R_in⁻¹ D, where R_in, R_out turn each beam's psps frame into
//! x ([`rotation_between_frames`], the one place frames live); T back to psps is the inverse.

use crate::optics::{rotation_between_frames, Direction, FrameTurn, Mueller};
use nalgebra::Vector3;

/// L (toward the light) and V (toward the viewer) of a table node, in a frame with h in the
/// x–z plane: h = (sin θ_h, 0, cos θ_h), b = (0, 1, 0), t = (cos θ_h, 0, −sin θ_h),
/// L = cos θ_d h + sin θ_d (cos φ_d t + sin φ_d b), V = 2(L·h)h − L (docs/design.md §2.10).
pub fn node_directions(theta_h: f64, theta_d: f64, phi_d: f64) -> (Vector3<f64>, Vector3<f64>) {
    let (sin_h, cos_h) = theta_h.sin_cos();
    let (sin_d, cos_d) = theta_d.sin_cos();
    let (sin_p, cos_p) = phi_d.sin_cos();
    let h = Vector3::new(sin_h, 0.0, cos_h);
    let t = Vector3::new(cos_h, 0.0, -sin_h);
    let b = Vector3::y();
    let light = h * cos_d + (t * cos_p + b * sin_p) * sin_d;
    let view = h * (2.0 * light.dot(&h)) - light;
    (light, view)
}

/// (θ_h, θ_d, φ_d) of unit directions L, V as Mitsuba computes them: h = unit(L + V),
/// θ_h = acos(h·n), θ_d = acos(h·L), φ_d = atan2(b·L⊥, t·L⊥) ∈ (−π, π] with b = unit(n × h),
/// t = unit(b × h), L⊥ = L − (L·h)h. At h = n (where n × h vanishes) b is taken as ŷ, the
/// limit of the node construction of [`node_directions`].
pub fn half_difference_angles(light: &Vector3<f64>, view: &Vector3<f64>) -> (f64, f64, f64) {
    let h = (light + view).normalize();
    let theta_h = h.z.clamp(-1.0, 1.0).acos();
    let cos_d = h.dot(light).clamp(-1.0, 1.0);
    let theta_d = cos_d.acos();
    let n_cross_h = Vector3::z().cross(&h);
    let b = if n_cross_h.norm_squared() > 1e-24 {
        n_cross_h.normalize()
    } else {
        Vector3::y()
    };
    let t = b.cross(&h).normalize();
    let perpendicular = light - h * cos_d;
    let phi_d = perpendicular.dot(&b).atan2(perpendicular.dot(&t));
    (theta_h, theta_d, phi_d)
}

/// The table's x axis for a pair: unit(L × V); where L ∥ V the plane is undefined and every
/// axis gives the same matrix for a mirror-symmetric surface, so any perpendicular of L serves.
fn table_axis(light: &Vector3<f64>, view: &Vector3<f64>) -> Vector3<f64> {
    let cross = light.cross(view);
    if cross.norm_squared() > 1e-24 {
        cross.normalize()
    } else {
        crate::optics::frame::any_perpendicular(light)
    }
}

/// The turns from the psps frames of the incident beam (k = −L, s = −ê_φ(L)) and of the
/// scattered beam (k = V, s = ê_φ(V)) into the table's frame x.
fn turns(light: &Vector3<f64>, view: &Vector3<f64>) -> (FrameTurn, FrameTurn) {
    let x = table_axis(light, view);
    let incident = Direction::from_unit_vector(*light);
    let scattered = Direction::from_unit_vector(*view);
    let turn_in = rotation_between_frames(&-incident.azimuthal_axis, &x, &-light);
    let turn_out = rotation_between_frames(&scattered.azimuthal_axis, &x, view);
    (turn_in, turn_out)
}

/// D M D with D = diag(1, 1, 1, −1): the S3 sign flip between psps and Mitsuba (its own inverse).
pub fn flip_circular(m: &Mueller) -> Mueller {
    let mut out = *m;
    for i in 0..4 {
        out[(3, i)] = -out[(3, i)];
        out[(i, 3)] = -out[(i, 3)];
    }
    out
}

/// A psps Mueller BRDF for incident direction L and scattered V, as the table stores it.
pub fn table_from_psps(m: &Mueller, light: &Vector3<f64>, view: &Vector3<f64>) -> Mueller {
    let (turn_in, turn_out) = turns(light, view);
    flip_circular(&(turn_out.mueller() * m * turn_in.inverse().mueller()))
}

/// A table's Mueller BRDF at directions L, V, in the psps frames of docs/design.md §1.3.
pub fn psps_from_table(t: &Mueller, light: &Vector3<f64>, view: &Vector3<f64>) -> Mueller {
    let (turn_in, turn_out) = turns(light, view);
    turn_out.inverse().mueller() * flip_circular(t) * turn_in.mueller()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn node_directions_give_back_their_angles() {
        for &(th, td, pd) in &[
            (0.3, 0.5, 1.0),
            (1.2, 0.1, -2.9),
            (0.05, 1.3, 3.0),
            (0.7, 0.7, -0.4),
        ] {
            let (l, v) = node_directions(th, td, pd);
            assert!((l.norm() - 1.0).abs() < 1e-14 && (v.norm() - 1.0).abs() < 1e-14);
            let (a, b, c) = half_difference_angles(&l, &v);
            assert!((a - th).abs() < 1e-12 && (b - td).abs() < 1e-12 && (c - pd).abs() < 1e-12);
        }
    }

    #[test]
    fn the_angles_do_not_depend_on_the_pair_s_azimuth() {
        let (l, v) = node_directions(0.4, 0.6, 2.0);
        let turn = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), 1.1);
        let (a, b, c) = half_difference_angles(&(turn * l), &(turn * v));
        let (a0, b0, c0) = half_difference_angles(&l, &v);
        assert!((a - a0).abs() < 1e-12 && (b - b0).abs() < 1e-12 && (c - c0).abs() < 1e-12);
    }

    /// In the plane of incidence the table's x = L × V is the psps s axis of both beams, so
    /// only the circular sign differs: Mitsuba's specular reflection at cos 30°, N = 1.5+0.1i
    /// has m23/m22 = +0.0317 where psps has −0.0317 (docs/design.md §2.10).
    #[test]
    fn in_the_plane_of_incidence_only_the_circular_sign_changes() {
        let ior = crate::optics::RefractiveIndex::new(1.5, 0.1);
        let (r_s, r_p) =
            crate::optics::fresnel_amplitudes(30f64.to_radians().cos(), ior.permittivity());
        let m = crate::optics::fresnel_mueller(r_s, r_p);
        let l = Direction::from_degrees(30.0, 0.0).vector;
        let v = Direction::from_degrees(30.0, 180.0).vector;
        let t = table_from_psps(&m, &l, &v);
        assert!((m[(2, 3)] / m[(2, 2)] + 0.0317).abs() < 5e-4);
        assert!((t[(2, 3)] / t[(2, 2)] - 0.0317).abs() < 5e-4);
        assert!((t - flip_circular(&m)).norm() < 1e-15);
    }

    #[test]
    fn the_conversion_round_trips() {
        let m = Mueller::from_fn(|i, j| (i * 4 + j) as f64 * 0.1 - 0.7);
        let (l, v) = node_directions(0.6, 0.4, -1.3);
        let back = psps_from_table(&table_from_psps(&m, &l, &v), &l, &v);
        assert!((back - m).norm() < 1e-13);
    }
}
