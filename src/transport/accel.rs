//! Ray queries against every triangle of the scene (docs/design.md §1.7): closest hit and
//! occlusion through irpol's own bounding-volume hierarchy.
//!
//! Hand-written because the libraries measured slower or wrong for this use: parry3d-f64's tree
//! (used before) was the renderer's bottleneck — one triangle per leaf, 56-byte f64 nodes and a
//! deep tree cost ~60 node tests (~14 ns each, mostly cache misses) per secondary ray, and its
//! build is single-threaded (~5 s for 5 M triangles); the `bvh` crate culls back faces and has
//! no closest-hit pruning. Here: a binned surface-area-heuristic build in parallel, 32-byte
//! nodes with f32 bounds rounded outward (so that no f64 hit is lost), up to four triangles per
//! leaf stored in leaf order, and a two-sided Möller–Trumbore test in f64.

mod build;
#[cfg(test)]
mod tests;

use crate::scene::mesh::{ShadedMesh, SurfaceHit};
use build::{Node, MAX_DEPTH};
use nalgebra::Vector3;
use rayon::prelude::*;

/// The scene's triangles in a BVH, plus the mesh they index (for hit attributes).
pub struct Accelerator<'a> {
    mesh: &'a ShadedMesh,
    /// Depth first: an interior node's first child follows it.
    nodes: Vec<Node>,
    /// The triangles in leaf order (a leaf's are contiguous)…
    triangles: Vec<Triangle>,
    /// …and their indices in the mesh.
    order: Vec<u32>,
    /// Rays start this far off the surface (along its geometric normal) so that they do not hit
    /// the triangle they leave: 1e-6 of the scene's extent, far above f64 rounding of positions.
    pub offset: f64,
}

impl<'a> Accelerator<'a> {
    /// Builds the hierarchy over every triangle of `mesh`; `extent` is the scene's size (m).
    /// Any mesh makes one (zero-area triangles are kept and never hit).
    pub fn new(mesh: &'a ShadedMesh, extent: f64) -> Accelerator<'a> {
        let (nodes, prims) = build::build(mesh);
        let triangles = prims
            .par_iter()
            .map(|p| Triangle::new(mesh, p.index as usize))
            .collect();
        let order = prims.iter().map(|p| p.index).collect();
        Accelerator {
            mesh,
            nodes,
            triangles,
            order,
            offset: (1e-6 * extent).max(1e-9),
        }
    }

    /// The first surface hit by the ray from `origin` along unit `direction` (any side of any
    /// triangle, at t ≥ 0), with its interpolated attributes.
    pub fn closest_hit(
        &self,
        origin: &Vector3<f64>,
        direction: &Vector3<f64>,
    ) -> Option<SurfaceHit> {
        let ray = Ray::new(origin, direction);
        let mut best = f64::INFINITY;
        let mut found = None;
        self.traverse(&ray, &mut best, |slot, best| {
            if let Some((t, b1, b2)) = self.triangles[slot].intersect(&ray, *best) {
                *best = t;
                found = Some((slot, b1, b2));
            }
            false
        });
        let (slot, b1, b2) = found?;
        Some(self.mesh.interpolate(self.order[slot] as usize, b1, b2))
    }

    /// Whether anything lies on the ray from `origin` along unit `direction` (a shadow ray): the
    /// first triangle hit ends the search.
    pub fn occluded(&self, origin: &Vector3<f64>, direction: &Vector3<f64>) -> bool {
        let ray = Ray::new(origin, direction);
        let (mut hit, mut unbounded) = (false, f64::INFINITY);
        self.traverse(&ray, &mut unbounded, |slot, best| {
            hit = self.triangles[slot].intersect(&ray, *best).is_some();
            hit
        });
        hit
    }

    /// Visits the triangles (leaf-order slots) of the leaves whose boxes the ray enters before
    /// `best`, nearer box first; `visit` may lower `best` and returns true to stop. Both
    /// children's boxes are tested at their parent (two independent tests, and only the boxes
    /// entered are visited); a postponed box is dropped if `best` has passed its entry since.
    #[inline]
    fn traverse(&self, ray: &Ray, best: &mut f64, mut visit: impl FnMut(usize, &mut f64) -> bool) {
        let Some(root) = self.nodes.first() else {
            return;
        };
        if ray.entry(root, *best) == f64::INFINITY {
            return;
        }
        let mut stack = [(0u32, 0.0f64); MAX_DEPTH];
        let (mut depth, mut at) = (0, 0);
        loop {
            let node = &self.nodes[at];
            let count = node.count();
            if count == 0 {
                let (first, second) = (at + 1, at + node.link as usize);
                let near_first = ray.entry(&self.nodes[first], *best);
                let near_second = ray.entry(&self.nodes[second], *best);
                let ((near, t_near), (far, t_far)) = if near_second < near_first {
                    ((second, near_second), (first, near_first))
                } else {
                    ((first, near_first), (second, near_second))
                };
                if t_far != f64::INFINITY {
                    stack[depth] = (far as u32, t_far);
                    depth += 1;
                }
                if t_near != f64::INFINITY {
                    at = near;
                    continue;
                }
            } else {
                let first = node.link as usize;
                for slot in first..first + count {
                    if visit(slot, best) {
                        return;
                    }
                }
            }
            loop {
                if depth == 0 {
                    return;
                }
                depth -= 1;
                let (next, entry) = stack[depth];
                if entry <= *best {
                    at = next as usize;
                    break;
                }
            }
        }
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
}

/// A ray prepared for slab tests against boxes (Kay and Kajiya): the reciprocals of its
/// direction, so that a box costs six multiplications.
struct Ray {
    origin: Vector3<f64>,
    direction: Vector3<f64>,
    inverse: [f64; 3],
}

impl Ray {
    fn new(origin: &Vector3<f64>, direction: &Vector3<f64>) -> Ray {
        Ray {
            origin: *origin,
            direction: *direction,
            inverse: [0, 1, 2].map(|a| {
                let inverse = 1.0 / direction[a];
                if inverse.is_finite() {
                    inverse
                } else {
                    f64::MAX.copysign(direction[a])
                }
            }),
        }
    }

    /// Where the ray enters the node's box (0 if it starts inside), or ∞ if it meets the box
    /// at no t in [0, `t_max`]. A zero direction component has a finite huge reciprocal, so
    /// that no 0 × ∞ makes a NaN and plain comparisons (single instructions) do; a ray in the
    /// plane of a box's face may then be let in at t = 0 (only work: the rounded-out bounds keep
    /// that plane clear of the box's triangles). The exit is widened by 2γ₃ (pbrt's bound on the
    /// slab test's rounding) so that grazing hits stay.
    #[inline(always)]
    fn entry(&self, node: &Node, t_max: f64) -> f64 {
        let slab = |axis: usize| {
            let lo = (f64::from(node.lo[axis]) - self.origin[axis]) * self.inverse[axis];
            let hi = (f64::from(node.hi[axis]) - self.origin[axis]) * self.inverse[axis];
            if lo < hi {
                (lo, hi)
            } else {
                (hi, lo)
            }
        };
        let ((x0, x1), (y0, y1), (z0, z1)) = (slab(0), slab(1), slab(2));
        let near = max(max(x0, y0), max(z0, 0.0));
        let far = min(min(x1, y1), min(z1, t_max));
        if near <= far * (1.0 + 4.0 * f64::EPSILON) {
            near
        } else {
            f64::INFINITY
        }
    }
}

/// The larger of two numbers as one instruction (no NaN reaches it).
#[inline(always)]
fn max(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

#[inline(always)]
fn min(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// A triangle as the intersection test wants it: a vertex and the two edges from it.
#[derive(Clone, Copy, Debug)]
struct Triangle {
    p0: Vector3<f64>,
    e1: Vector3<f64>,
    e2: Vector3<f64>,
}

impl Triangle {
    fn new(mesh: &ShadedMesh, t: usize) -> Triangle {
        let [p0, p1, p2] = mesh.triangles[t].map(|v| mesh.positions[v as usize]);
        Triangle {
            p0,
            e1: p1 - p0,
            e2: p2 - p0,
        }
    }

    /// Möller–Trumbore, two-sided: (t, b1, b2) where the ray meets the triangle at
    /// 0 ≤ t < `t_max` (a point p0 + b1 e1 + b2 e2, edges included), or `None`. A ray in the
    /// triangle's plane and a zero-area triangle give a zero determinant: no hit. The negated
    /// comparisons also refuse the NaN of a determinant so small its reciprocal overflows.
    #[inline(always)]
    fn intersect(&self, ray: &Ray, t_max: f64) -> Option<(f64, f64, f64)> {
        let p = ray.direction.cross(&self.e2);
        let det = self.e1.dot(&p);
        if det == 0.0 {
            return None;
        }
        let inverse = 1.0 / det;
        let s = ray.origin - self.p0;
        let b1 = s.dot(&p) * inverse;
        if !(0.0..=1.0).contains(&b1) {
            return None;
        }
        let q = s.cross(&self.e1);
        let b2 = ray.direction.dot(&q) * inverse;
        if !(b2 >= 0.0 && b1 + b2 <= 1.0) {
            return None;
        }
        let t = self.e2.dot(&q) * inverse;
        (t >= 0.0 && t < t_max).then_some((t, b1, b2))
    }
}
