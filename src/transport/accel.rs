//! Ray queries against every triangle of the scene (docs/design.md §1.7): closest hit and
//! occlusion through irpol's own bounding-volume hierarchy.
//!
//! Hand-written because the libraries measured slower or wrong for this use: parry3d-f64's tree
//! (used before) was the renderer's bottleneck — one triangle per leaf, 56-byte f64 nodes and a
//! deep tree cost ~60 node tests (~14 ns each, mostly cache misses) per secondary ray, and its
//! build is single-threaded (~5 s for 5 M triangles); the `bvh` crate culls back faces and has
//! no closest-hit pruning. Here: a binned surface-area-heuristic build in parallel of a binary
//! tree, collapsed into nodes of four children whose boxes (f32 bounds rounded outward, so that
//! no f64 hit is lost) a ray tests in one vectorized loop, nearest entered child first; up to
//! four triangles per leaf stored in leaf order, and a two-sided Möller–Trumbore test in f64.

mod build;
mod collapse;
#[cfg(test)]
mod tests;

use crate::scene::mesh::{ShadedMesh, SurfaceHit};
use build::MAX_DEPTH;
use collapse::{Wide, LANES};
use nalgebra::Vector3;
use rayon::prelude::*;

/// The scene's triangles in a BVH, plus the mesh they index (for hit attributes).
pub struct Accelerator<'a> {
    mesh: &'a ShadedMesh,
    /// Four children per node, depth first from the root.
    nodes: Vec<Wide>,
    /// The most nodes on a path from the root (the traversal's stack holds three per node).
    depth: usize,
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
        let (binary, prims) = build::build(mesh);
        // The collapse is sequential: it runs beside the (parallel) copy of the triangles.
        let ((nodes, depth), triangles) = rayon::join(
            || collapse::collapse(&binary),
            || {
                (prims.par_iter())
                    .map(|p| Triangle::new(mesh, p.index as usize))
                    .collect()
            },
        );
        drop(binary);
        let order = prims.iter().map(|p| p.index).collect();
        Accelerator {
            mesh,
            nodes,
            depth,
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
        let (slot, _, b1, b2) = self.closest(&Ray::new(origin, direction))?;
        Some(self.mesh.interpolate(self.order[slot] as usize, b1, b2))
    }

    /// The first triangle on `ray`: its leaf-order slot, the distance and the barycentrics.
    fn closest(&self, ray: &Ray) -> Option<(usize, f64, f64, f64)> {
        let mut best = f64::INFINITY;
        let mut found = None;
        // Inlined by request: the compiler's heuristics left a call per triangle (3–30 % slower
        // queries, measured once).
        self.traverse(
            ray,
            &mut best,
            #[inline(always)]
            |slot, best| {
                if let Some((t, b1, b2)) = self.triangles[slot].intersect(ray, *best) {
                    *best = t;
                    found = Some((slot, t, b1, b2));
                }
                false
            },
        );
        found
    }

    /// Whether anything lies on the ray from `origin` along unit `direction` (a shadow ray): the
    /// first triangle hit ends the search.
    pub fn occluded(&self, origin: &Vector3<f64>, direction: &Vector3<f64>) -> bool {
        let ray = Ray::new(origin, direction);
        let (mut hit, mut unbounded) = (false, f64::INFINITY);
        self.traverse(
            &ray,
            &mut unbounded,
            #[inline(always)]
            |slot, best| {
                hit = self.triangles[slot].intersect(&ray, *best).is_some();
                hit
            },
        );
        hit
    }

    /// Visits the triangles (leaf-order slots) of the leaves whose boxes the ray enters before
    /// `best`, nearer box first; `visit` may lower `best` and returns true to stop. A node's four
    /// boxes are tested together; the entered ones are sorted by entry, the nearest is visited
    /// and the others wait on the stack, each dropped if `best` has passed its entry since.
    #[inline]
    fn traverse(&self, ray: &Ray, best: &mut f64, visit: impl FnMut(usize, &mut f64) -> bool) {
        // The stack is zeroed on every query: a short one when the tree allows it. Zeroing the
        // long one (4.6 kB) cost ~40 ns per ray, more than the rest of a ray leaving the plane
        // of the Mitsuba scene; 48 entries against 24 cost ~3 ns.
        if 3 * self.depth <= SHORT_STACK {
            self.traverse_with::<SHORT_STACK>(ray, best, visit);
        } else {
            self.traverse_with::<LONG_STACK>(ray, best, visit);
        }
    }

    /// `traverse` with a stack of `N` entries, at least three per level of the tree.
    #[inline(always)]
    fn traverse_with<const N: usize>(
        &self,
        ray: &Ray,
        best: &mut f64,
        mut visit: impl FnMut(usize, &mut f64) -> bool,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        // (child, count, entry) as in a node's lane; the root is node 0, interior (count 0).
        let mut stack = [(0u32, 0u32, 0.0f64); N];
        let (mut depth, mut next) = (0, (0u32, 0u32));
        loop {
            let (child, count) = next;
            if count == 0 {
                let node = &self.nodes[child as usize];
                let (entries, mut mask) = ray.entries(node, *best);
                let mut entered = [(0u32, 0u32, 0.0f64); LANES];
                let mut n = 0;
                while mask != 0 {
                    let lane = mask.trailing_zeros() as usize;
                    mask &= mask - 1;
                    entered[n] = (node.child[lane], node.count[lane], entries[lane]);
                    n += 1;
                }
                if n > 0 {
                    sort_by_entry(&mut entered[..n]);
                    for &far in entered[1..n].iter().rev() {
                        stack[depth] = far;
                        depth += 1;
                    }
                    next = (entered[0].0, entered[0].1);
                    continue;
                }
            } else {
                let first = child as usize;
                for slot in first..first + count as usize {
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
                let (child, count, entry) = stack[depth];
                if entry <= *best {
                    next = (child, count);
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

/// The traversal stack: each node on the path from the root leaves up to three children
/// waiting. The long one holds any tree (no path is longer than `MAX_DEPTH` binary nodes, and
/// collapsing only shortens paths); the short one trees of depth ≤ 16 (the Mitsuba scene's is
/// 8, a plane of 5 M triangles 11).
const LONG_STACK: usize = 3 * MAX_DEPTH;
const SHORT_STACK: usize = 48;

/// A ray prepared for slab tests against boxes (Kay and Kajiya): the reciprocals of its
/// direction, so that a box costs six multiplications (a node's four in six vector ones).
struct Ray {
    origin: Vector3<f64>,
    direction: Vector3<f64>,
    /// The origin and the reciprocals once per lane, `[axis][lane]`, so that the slab test of a
    /// node's four boxes is plain element-wise arithmetic on four-element arrays (vectorized
    /// whatever the code it is inlined in).
    lanes_origin: [[f64; LANES]; 3],
    lanes_inverse: [[f64; LANES]; 3],
    /// Per axis, the boxes' corner the ray enters by: 0 (low) for a positive reciprocal.
    near_corner: [usize; 3],
}

impl Ray {
    fn new(origin: &Vector3<f64>, direction: &Vector3<f64>) -> Ray {
        let inverse = [0, 1, 2].map(|a| {
            let inverse = 1.0 / direction[a];
            if inverse.is_finite() {
                inverse
            } else {
                f64::MAX.copysign(direction[a])
            }
        });
        Ray {
            origin: *origin,
            direction: *direction,
            lanes_origin: [0, 1, 2].map(|a| [origin[a]; LANES]),
            lanes_inverse: inverse.map(|i| [i; LANES]),
            near_corner: inverse.map(|i| usize::from(i < 0.0)),
        }
    }

    /// Where the ray enters each of the node's four boxes (0 if it starts inside) and, as bits,
    /// which boxes it meets at some t in [0, `t_max`]. Each axis's entry is the plane of the
    /// near corner (the low one for a positive direction): rounding is monotonic, so that is the
    /// smaller of the two slab distances, as a min/max test finds, with two operations fewer.
    /// A zero direction component has a finite huge reciprocal, so that no 0 × ∞ makes a NaN
    /// and plain comparisons (single instructions) do; a ray in the plane of a box's face may
    /// then be let in at t = 0 (only work: the rounded-out bounds keep that plane clear of the
    /// box's triangles). An unused lane's inverted box (+∞ to −∞) enters at +∞ and leaves at
    /// −∞ on every axis. The exit is widened by 2γ₃ (pbrt's bound on the slab test's rounding)
    /// so that grazing hits stay. The slabs are computed in f64 from the f32 bounds (exact
    /// conversions): each lane is the binary tree's test of the same box.
    #[inline(always)]
    fn entries(&self, node: &Wide, t_max: f64) -> ([f64; LANES], u32) {
        let mut near = [0.0; LANES];
        let mut far = [t_max; LANES];
        for axis in 0..3 {
            let (origin, inverse) = (&self.lanes_origin[axis], &self.lanes_inverse[axis]);
            let enter = &node.bounds[self.near_corner[axis]][axis];
            let leave = &node.bounds[1 - self.near_corner[axis]][axis];
            for lane in 0..LANES {
                let t0 = (f64::from(enter[lane]) - origin[lane]) * inverse[lane];
                let t1 = (f64::from(leave[lane]) - origin[lane]) * inverse[lane];
                near[lane] = max(near[lane], t0);
                far[lane] = min(far[lane], t1);
            }
        }
        let mut mask = 0;
        for lane in 0..LANES {
            let entered = near[lane] <= far[lane] * (1.0 + 4.0 * f64::EPSILON);
            mask |= u32::from(entered) << lane;
        }
        (near, mask)
    }
}

/// Sorts a node's entered children (at most four, usually one or two) nearest first.
#[inline(always)]
fn sort_by_entry(entered: &mut [(u32, u32, f64)]) {
    for i in 1..entered.len() {
        let mut j = i;
        while j > 0 && entered[j].2 < entered[j - 1].2 {
            entered.swap(j, j - 1);
            j -= 1;
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
