//! Ray queries against every triangle of the scene (docs/design.md §1.7): closest hit and occlusion, through
//! the bounding-volume hierarchy of `parry3d-f64` (dimforge's collision library: a maintained,
//! double-precision BVH with two-sided triangle ray casts, so the hit distances agree with the
//! f64 geometry the shading uses; see the README for why it was chosen).

use crate::scene::mesh::{ShadedMesh, SurfaceHit};
use nalgebra::Vector3;
use parry3d_f64::math::Vector as ParryVector;
use parry3d_f64::partitioning::TraversalAction;
use parry3d_f64::query::{Ray, RayCast};
use parry3d_f64::shape::TriMesh;

/// The scene's triangles in a BVH, plus the mesh they index (for hit attributes).
pub struct Accelerator<'a> {
    mesh: &'a ShadedMesh,
    bvh: Option<TriMesh>,
    /// Rays start this far off the surface (along its geometric normal) so that they do not hit
    /// the triangle they leave: 1e-6 of the scene's extent, far above f64 rounding of positions.
    pub offset: f64,
}

/// The mesh's triangles do not make a hierarchy (parry refuses the mesh).
#[derive(Debug, thiserror::Error)]
#[error("cannot build the ray-tracing hierarchy: {0}")]
pub struct AccelError(parry3d_f64::shape::TriMeshBuilderError);

fn to_parry(v: &Vector3<f64>) -> ParryVector {
    ParryVector::new(v.x, v.y, v.z)
}

impl<'a> Accelerator<'a> {
    /// Builds the hierarchy over every triangle of `mesh`; `extent` is the scene's size (m).
    pub fn new(mesh: &'a ShadedMesh, extent: f64) -> Result<Accelerator<'a>, AccelError> {
        let bvh = if mesh.triangles.is_empty() {
            None
        } else {
            let vertices = mesh.positions.iter().map(to_parry).collect();
            Some(TriMesh::new(vertices, mesh.triangles.clone()).map_err(AccelError)?)
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
        let slab = SlabRay::new(origin, direction);
        // parry's own traversal (best first) and triangle test, with the node test below: its
        // f64 build tests nodes with the general `Aabb::cast_local_ray` (a division and branches
        // per axis), which took a quarter of a render; its f32 build already uses this form.
        let (triangle, t) = bvh.bvh().find_best(
            f64::MAX,
            |node, _| slab.entry(&node.mins(), &node.maxs()),
            |triangle, best| bvh.triangle(triangle).cast_local_ray(&ray, best, false),
        )?;
        let point = origin + direction * t;
        let (b1, b2) = self.barycentric(triangle as usize, &point);
        Some(self.mesh.interpolate(triangle as usize, b1, b2))
    }

    /// Whether anything lies on the ray from `origin` along unit `direction` (a shadow ray): the
    /// first triangle hit ends the search, where parry's `intersects_local_ray` looks for the
    /// closest.
    pub fn occluded(&self, origin: &Vector3<f64>, direction: &Vector3<f64>) -> bool {
        let Some(bvh) = self.bvh.as_ref() else {
            return false;
        };
        let ray = Ray::new(to_parry(origin), to_parry(direction));
        let slab = SlabRay::new(origin, direction);
        let mut hit = false;
        bvh.bvh().traverse(|node| {
            if slab.entry(&node.mins(), &node.maxs()) == f64::MAX {
                TraversalAction::Prune
            } else if let Some(triangle) = node.leaf_data() {
                hit = bvh.triangle(triangle).intersects_local_ray(&ray, f64::MAX);
                if hit {
                    TraversalAction::EarlyExit
                } else {
                    TraversalAction::Prune
                }
            } else {
                TraversalAction::Continue
            }
        });
        hit
    }

    /// A sphere (centre, radius) holding every triangle, with a margin of ten ray offsets, or
    /// `None` for an empty mesh: a ray that misses it hits nothing.
    pub fn bounding_sphere(&self) -> Option<(Vector3<f64>, f64)> {
        let used = || (self.mesh.triangles.iter()).flat_map(|t| t.map(|v| v as usize));
        let first = self.mesh.positions[used().next()?];
        let (lo, hi) = used().fold((first, first), |(lo, hi), v| {
            let p = &self.mesh.positions[v];
            (lo.inf(p), hi.sup(p))
        });
        let centre = 0.5 * (lo + hi);
        let radius = used()
            .map(|v| (self.mesh.positions[v] - centre).norm())
            .fold(0.0, f64::max);
        Some((centre, radius * (1.0 + 1e-9) + 10.0 * self.offset))
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

/// A ray prepared for slab tests against axis-aligned boxes (Kay and Kajiya): its origin and
/// the reciprocals of its direction, so that a box costs six multiplications.
struct SlabRay {
    origin: [f64; 3],
    inverse_direction: [f64; 3],
}

impl SlabRay {
    fn new(origin: &Vector3<f64>, direction: &Vector3<f64>) -> SlabRay {
        SlabRay {
            origin: [origin.x, origin.y, origin.z],
            inverse_direction: [1.0 / direction.x, 1.0 / direction.y, 1.0 / direction.z],
        }
    }

    /// The ray parameter where it enters the box [`mins`, `maxs`] (negative when it starts
    /// inside), or `f64::MAX` when it misses the box or the box lies behind it. A zero direction
    /// component gives ±∞ per slab, which the comparisons handle; `f64::min`/`max` skip the NaN
    /// of 0 × ∞ (a ray in a slab's plane), treating that slab as no constraint.
    #[inline]
    fn entry(&self, mins: &ParryVector, maxs: &ParryVector) -> f64 {
        let (lo, hi) = ([mins.x, mins.y, mins.z], [maxs.x, maxs.y, maxs.z]);
        let (mut near, mut far) = (f64::NEG_INFINITY, f64::INFINITY);
        for axis in 0..3 {
            let t1 = (lo[axis] - self.origin[axis]) * self.inverse_direction[axis];
            let t2 = (hi[axis] - self.origin[axis]) * self.inverse_direction[axis];
            near = near.max(t1.min(t2));
            far = far.min(t1.max(t2));
        }
        if far >= near && far >= 0.0 {
            near
        } else {
            f64::MAX
        }
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

    /// The slab-tested traversal finds the same first triangle at the same distance as parry's
    /// own ray cast, and the any-hit shadow query agrees with it, on random rays from inside,
    /// outside and on the surface of an icosphere over a plane (rays grazing both included).
    #[test]
    fn queries_agree_with_parry_ray_casts() {
        use crate::scene::procedural::{icosphere, plane};
        use parry3d_f64::shape::CompositeShapeRef;
        use rand::{Rng, SeedableRng};
        let (sphere, ground) = (icosphere(1.0, 3), plane([8.0, 8.0], [2, 2]));
        let mut positions: Vec<Vector3<f64>> = sphere
            .positions
            .iter()
            .map(|p| p + Vector3::new(0.0, 0.0, 1.02))
            .collect();
        let offset = positions.len() as u32;
        positions.extend(ground.positions.iter().copied());
        let mut triangles: Vec<[u32; 3]> = sphere.faces.iter().map(|f| f.vertices).collect();
        triangles.extend(ground.faces.iter().map(|f| f.vertices.map(|v| v + offset)));
        let mesh = ShadedMesh {
            normals: vec![Vector3::z(); positions.len()],
            temperatures: vec![300.0; positions.len()],
            triangle_surface: vec![0; triangles.len()],
            positions,
            triangles,
        };
        let accel = Accelerator::new(&mesh, 8.0).unwrap();
        let parry = accel.bvh.as_ref().unwrap();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let (mut hits, mut misses) = (0, 0);
        for i in 0..20_000 {
            let origin = Vector3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                if i % 3 == 0 {
                    0.0
                } else {
                    rng.random_range(-0.5..3.0)
                },
            );
            let direction = Vector3::new(
                rng.random_range(-1.0..1.0),
                rng.random_range(-1.0..1.0),
                if i % 5 == 0 {
                    0.0
                } else {
                    rng.random_range(-1.0..1.0)
                },
            )
            .normalize();
            let ray = Ray::new(to_parry(&origin), to_parry(&direction));
            let expected = CompositeShapeRef(parry).cast_local_ray(&ray, f64::MAX, false);
            let ours = accel.closest_hit(&origin, &direction);
            match (expected, ours) {
                (Some((triangle, t)), Some(hit)) => {
                    hits += 1;
                    assert!(
                        (hit.point - (origin + direction * t)).norm() < 1e-9,
                        "ray {i}: {:?} vs {t} on {triangle}",
                        hit.point
                    );
                }
                (None, None) => misses += 1,
                (expected, ours) => panic!("ray {i}: parry {expected:?}, ours {ours:?}"),
            }
            assert_eq!(
                accel.occluded(&origin, &direction),
                expected.is_some(),
                "ray {i}"
            );
        }
        assert!(hits > 5000 && misses > 5000, "{hits} hits, {misses} misses");
    }
}
