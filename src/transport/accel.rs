//! Ray queries against every triangle of the scene (DESIGN §1.7): closest hit and occlusion, through
//! the bounding-volume hierarchy of `parry3d-f64` (dimforge's collision library: a maintained,
//! double-precision BVH with two-sided triangle ray casts, so the hit distances agree with the
//! f64 geometry the shading uses; see the README for why it was chosen).

use crate::scene::mesh::{ShadedMesh, SurfaceHit};
use nalgebra::Vector3;
use parry3d_f64::math::Vector as ParryVector;
use parry3d_f64::query::{Ray, RayCast};
use parry3d_f64::shape::{CompositeShapeRef, TriMesh};

/// The scene's triangles in a BVH, plus the mesh they index (for hit attributes).
pub struct Accelerator<'a> {
    mesh: &'a ShadedMesh,
    bvh: Option<TriMesh>,
    /// Rays start this far off the surface (along its geometric normal) so that they do not hit
    /// the triangle they leave: 1e-6 of the scene's extent, far above f64 rounding of positions.
    pub offset: f64,
}

fn to_parry(v: &Vector3<f64>) -> ParryVector {
    ParryVector::new(v.x, v.y, v.z)
}

impl<'a> Accelerator<'a> {
    /// Builds the hierarchy over every triangle of `mesh`; `extent` is the scene's size (m).
    pub fn new(mesh: &'a ShadedMesh, extent: f64) -> Result<Accelerator<'a>, String> {
        let bvh = if mesh.triangles.is_empty() {
            None
        } else {
            let vertices = mesh.positions.iter().map(to_parry).collect();
            Some(
                TriMesh::new(vertices, mesh.triangles.clone())
                    .map_err(|e| format!("cannot build the ray-tracing hierarchy: {e}"))?,
            )
        };
        Ok(Accelerator {
            mesh,
            bvh,
            offset: (1e-6 * extent).max(1e-9),
        })
    }

    /// The first surface hit by the ray from `origin` along unit `direction` (any side of any
    /// triangle), with its interpolated attributes.
    pub fn closest_hit(
        &self,
        origin: &Vector3<f64>,
        direction: &Vector3<f64>,
    ) -> Option<SurfaceHit> {
        let bvh = self.bvh.as_ref()?;
        let ray = Ray::new(to_parry(origin), to_parry(direction));
        let (triangle, t) = CompositeShapeRef(bvh).cast_local_ray(&ray, f64::MAX, false)?;
        let point = origin + direction * t;
        let (b1, b2) = self.barycentric(triangle as usize, &point);
        Some(self.mesh.interpolate(triangle as usize, b1, b2))
    }

    /// Whether anything lies on the ray from `origin` along unit `direction`.
    pub fn occluded(&self, origin: &Vector3<f64>, direction: &Vector3<f64>) -> bool {
        self.bvh.as_ref().is_some_and(|bvh| {
            let ray = Ray::new(to_parry(origin), to_parry(direction));
            bvh.intersects_local_ray(&ray, f64::MAX)
        })
    }

    /// (b1, b2) of `point` on triangle `t` (in its plane), clamped into the triangle.
    fn barycentric(&self, t: usize, point: &Vector3<f64>) -> (f64, f64) {
        let [i0, i1, i2] = self.mesh.triangles[t].map(|v| v as usize);
        let p = &self.mesh.positions;
        let (e1, e2, d) = (p[i1] - p[i0], p[i2] - p[i0], point - p[i0]);
        let (d11, d12, d22) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
        let (d1, d2) = (d.dot(&e1), d.dot(&e2));
        let det = d11 * d22 - d12 * d12;
        if det <= 0.0 {
            return (1.0 / 3.0, 1.0 / 3.0);
        }
        let b1 = ((d22 * d1 - d12 * d2) / det).clamp(0.0, 1.0);
        let b2 = ((d11 * d2 - d12 * d1) / det).clamp(0.0, 1.0 - b1);
        (b1, b2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> ShadedMesh {
        ShadedMesh {
            positions: vec![
                Vector3::new(-1.0, -1.0, 0.0),
                Vector3::new(1.0, -1.0, 0.0),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::new(-1.0, 1.0, 0.0),
            ],
            normals: vec![Vector3::z(); 4],
            temperatures: vec![300.0, 310.0, 320.0, 330.0],
            triangles: vec![[0, 1, 2], [0, 2, 3]],
            triangle_surface: vec![0, 0],
        }
    }

    #[test]
    fn hits_either_side_at_the_right_point_with_interpolated_attributes() {
        let mesh = square();
        let accel = Accelerator::new(&mesh, 3.0).unwrap();
        let down = Vector3::new(0.0, 0.0, -1.0);
        let hit = accel
            .closest_hit(&Vector3::new(0.5, -0.25, 2.0), &down)
            .unwrap();
        assert!((hit.point - Vector3::new(0.5, -0.25, 0.0)).norm() < 1e-12);
        // Bilinear data on a linear split: T = 315 + 5x + 10y... on triangle 0 (x ≥ y).
        let b = hit.barycentric;
        let expected = 300.0 * b[0] + 310.0 * b[1] + 320.0 * b[2];
        assert!((hit.temperature - expected).abs() < 1e-9);
        assert_eq!(hit.triangle, 0);
        // From below (back face).
        let up = Vector3::new(0.0, 0.0, 1.0);
        let hit = accel
            .closest_hit(&Vector3::new(-0.5, 0.25, -1.0), &up)
            .unwrap();
        assert_eq!(hit.triangle, 1);
        assert!(accel.occluded(&Vector3::new(-0.5, 0.25, -1.0), &up));
        assert!(!accel.occluded(&Vector3::new(3.0, 0.0, -1.0), &up));
        assert!(accel
            .closest_hit(&Vector3::new(0.0, 0.0, 1.0), &up)
            .is_none());
    }
}
