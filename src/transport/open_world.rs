//! The open-world integrator: the paper's model (docs/design.md §1.5), where every surface point sees the
//! whole sky and ground. The Stokes vector leaving a point along ω,
//!
//!   S_j = ε_j(θ) L_bb(T) + ∫ F_j0(ω_i→ω) L_env(ω_i) cosθ_i dΩ_i,
//!
//! is read from exact per-material tables ([`super::tables`]) in the local frame of the shading
//! normal, referred to the psps frame of ω ([`OutgoingFrame`]). It has no noise; the path
//! integrator ([`super::path`]) uses it as its control variate and adds only what occlusion,
//! inter-reflection and the sun change.

use super::tables::{MaterialTables, RadianceTable, THETA_MAX};
use crate::optics::{stokes_to_camera_frame, OutgoingFrame, Stokes};
use crate::scene::camera::Camera;
use nalgebra::Vector3;

/// Everything the open-world model needs that is shared by all points.
pub struct OpenWorld<'a> {
    /// Per material.
    pub tables: &'a [MaterialTables],
    pub radiance: &'a RadianceTable,
}

impl OpenWorld<'_> {
    /// Stokes vector (S0, S1, S2, S3 = 0) leaving a surface of `material` at `temperature` along
    /// `frame`'s ω, in the psps frame of ω (s = `frame.s_axis`). A normal facing away from ω (an
    /// interpolated normal at a silhouette) is read at grazing.
    #[inline]
    pub fn leaving(&self, material: usize, frame: &OutgoingFrame, temperature: f64) -> Stokes {
        let tables = &self.tables[material];
        let cos_table = frame.cos_theta.max(THETA_MAX.cos());
        let e = tables.emissivity_at(cos_table, temperature);
        let r = tables.reflected(frame.cos_tilt.acos(), cos_table, frame.phi);
        let l = self.radiance.radiance(temperature);
        Stokes::new(e[0] * l + r[0], e[1] * l + r[1], r[2], 0.0)
    }

    /// The open-world Stokes vector seen by `camera` at `point` (pixel frame, docs/design.md §1.6), with
    /// unit shading normal `normal` on the side seen (`path::Vertex::seen_from` turns it).
    pub fn toward_camera(
        &self,
        camera: &Camera,
        material: usize,
        point: &Vector3<f64>,
        normal: &Vector3<f64>,
        temperature: f64,
    ) -> [f64; 4] {
        let w_r = (camera.position - point).normalize();
        let frame = OutgoingFrame::new(normal, &w_r);
        let local = self.leaving(material, &frame, temperature);
        let pixel = stokes_to_camera_frame(&local, &frame.s_axis, &w_r, &camera.right);
        [pixel[0], pixel[1], pixel[2], pixel[3]]
    }
}
