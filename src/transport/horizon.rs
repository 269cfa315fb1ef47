//! Horizon maps of a terrain heightfield (docs/design.md §1.8, **Exposure**): for every grid point,
//! how high the terrain itself rises above the horizontal in each of 16 azimuths, so that its
//! self-occlusion (sky view and sun shadows) needs no ray against its millions of triangles.
//!
//! **Directions.** The 16 lattice steps (±1, 0), (0, ±1), (±1, ±1), (±2, ±1), (±1, ±2) in grid
//! units: every march from a grid point lands exactly on grid points, so a horizon is a maximum
//! over heights that exist, with no interpolation in space. In world space a step is
//! di·axis_i + dj·axis_j (non-square cells and the object's z-rotation included); azimuths here are
//! atan2(y, x) of world direction vectors (x east, y north: counter-clockwise from east), the
//! frame of the thermal model's sun vectors.
//!
//! **Horizon.** For grid point p and step d, the horizon is the largest tan(elevation)
//! (z_k − z_p)/|p_k − p|_xy over the grid points p_k = p + k d, k ≥ 1, of the grid, clamped below at
//! 0: below the horizontal the thermal model counts the environment's ground, not the sky. Each
//! lattice line is solved in O(n) by Dozier, Bruno & Downey (1981, "A faster solution to the
//! horizon problem", Computers & Geosciences 7, 145–151): walking the line from its far end, a
//! point's horizon is found by following the horizon pointers of the points ahead of it
//! (j ← p + 1; while slope(p, hor\[j\]) ≥ slope(p, j): j ← hor\[j\]), exact, as the brute-force
//! maximum is (tested to the bit).
//!
//! **Queries.** A direction's horizon is interpolated linearly in azimuth between its two
//! neighbouring lattice directions (their world azimuths are not evenly spaced: 26.6°, 18.4°, …
//! on square cells). Points that are not grid points (other objects on the terrain) march the
//! terrain's triangulated surface instead, in steps of one cell, until even the highest point of
//! the field could no longer raise the horizon.
//!
//! **Memory.** 16 f32 per grid point, stored per point (one 64-byte row, so the 288 directions of
//! a vertex's sky read one cache line): 1601 × 1601 points take 164 MB.

use crate::scene::heightfield::Heightfield;
use nalgebra::Vector3;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The lattice steps (di, dj), counter-clockwise in grid space from +i.
const STEPS: [[i64; 2]; 16] = [
    [1, 0],
    [2, 1],
    [1, 1],
    [1, 2],
    [0, 1],
    [-1, 2],
    [-1, 1],
    [-2, 1],
    [-1, 0],
    [-2, -1],
    [-1, -1],
    [-1, -2],
    [0, -1],
    [1, -2],
    [1, -1],
    [2, -1],
];

/// No point ahead on the line (the far end's horizon pointer).
const NO_POINT: u32 = u32::MAX;

/// The horizon of every grid point of a heightfield in 16 azimuths (see the module docs).
pub struct HorizonMap<'a> {
    field: &'a Heightfield,
    /// The lattice steps in ascending world azimuth.
    steps: [[i64; 2]; 16],
    /// Their world azimuths atan2(y, x) in (−π, π], ascending.
    azimuth_rad: [f64; 16],
    /// Per grid point, the horizon tan in each direction of `steps` (≥ 0).
    horizon: Vec<[f32; 16]>,
}

impl<'a> HorizonMap<'a> {
    /// The horizons of every grid point of `field`, in parallel over the directions (each
    /// direction's lines in turn: 16 independent tasks keep two to a dozen cores busy, and a
    /// direction owns its output column, so no line writes where another does).
    pub fn new(field: &'a Heightfield) -> HorizonMap<'a> {
        let mut order: Vec<([i64; 2], f64)> = STEPS
            .iter()
            .map(|&s| {
                let w = world_step(field, s);
                (s, w.y.atan2(w.x))
            })
            .collect();
        order.sort_by(|a, b| a.1.total_cmp(&b.1));
        let steps: [[i64; 2]; 16] = std::array::from_fn(|k| order[k].0);
        let azimuth_rad: [f64; 16] = std::array::from_fn(|k| order[k].1);
        let [px, py] = field.points();
        let mut horizon = vec![[0f32; 16]; px * py];
        // A few directions at a time, so that the columns waiting to be interleaved into the
        // per-point rows stay a small fraction of the map.
        let batch = rayon::current_num_threads().clamp(1, 16);
        for first in (0..16).step_by(batch) {
            let last = (first + batch).min(16);
            let columns: Vec<Vec<f32>> = (first..last)
                .into_par_iter()
                .map(|k| direction_horizons(field, steps[k]))
                .collect();
            horizon
                .par_chunks_mut(4096)
                .enumerate()
                .for_each(|(chunk, rows)| {
                    for (r, row) in rows.iter_mut().enumerate() {
                        let g = chunk * 4096 + r;
                        for (k, column) in (first..last).zip(&columns) {
                            row[k] = column[g];
                        }
                    }
                });
        }
        HorizonMap {
            field,
            steps,
            azimuth_rad,
            horizon,
        }
    }

    /// The heightfield the map is of.
    pub fn field(&self) -> &Heightfield {
        self.field
    }

    /// The horizon tan at grid point `g` in the azimuth of `direction` (its z is ignored),
    /// interpolated linearly in azimuth between the two neighbouring lattice directions; ≥ 0.
    pub fn horizon_tan(&self, g: usize, direction: &Vector3<f64>) -> f64 {
        let phi = direction.y.atan2(direction.x);
        let a = &self.azimuth_rad;
        // The lattice directions on either side of phi, across the ±π seam when needed.
        let above = a.partition_point(|&x| x <= phi);
        let (lo, hi) = ((above + 15) % 16, above % 16);
        let a_lo = if above == 0 { a[15] - 2.0 * PI } else { a[lo] };
        let a_hi = if above == 16 { a[0] + 2.0 * PI } else { a[hi] };
        let w = (phi - a_lo) / (a_hi - a_lo);
        let row = &self.horizon[g];
        f64::from(row[lo]) * (1.0 - w) + f64::from(row[hi]) * w
    }

    /// Whether the terrain blocks `direction` (need not be unit) seen from grid point `g`: its
    /// elevation is below the horizon there. A direction below the horizontal is always blocked
    /// (the horizon is never below it) and the zenith never; the thermal model counts directions
    /// below the horizontal as the environment's ground and asks only about those above.
    pub fn blocks(&self, g: usize, direction: &Vector3<f64>) -> bool {
        self.blocks_under(g, direction, self.highest_tan(g))
    }

    /// The highest horizon tan of grid point `g` in any azimuth (≥ 0).
    pub fn highest_tan(&self, g: usize) -> f64 {
        f64::from(self.horizon[g].iter().fold(0f32, |m, &h| m.max(h)))
    }

    /// [`Self::blocks`] with the point's [`Self::highest_tan`] already known (a caller asking
    /// about many directions from one point).
    pub fn blocks_under(&self, g: usize, direction: &Vector3<f64>, highest_tan: f64) -> bool {
        let horizontal = horizontal_length(direction);
        // Above the point's highest horizon in any azimuth nothing blocks: most directions of a
        // sky-view rule over gently rolling ground, settled without the azimuth search.
        if direction.z >= highest_tan * horizontal {
            return false;
        }
        direction.z < self.horizon_tan(g, direction) * horizontal
    }

    /// The horizon tan seen from any point `p` (a vertex of another object standing on the
    /// terrain) in the azimuth of `direction`: the largest (z − p_z)/distance over the terrain's
    /// triangulated surface sampled every cell along that azimuth inside the grid, ≥ 0. The march
    /// ends once even the field's highest point could not raise the horizon, so a point above the
    /// whole field returns at once.
    pub fn horizon_tan_from(&self, p: &Vector3<f64>, direction: &Vector3<f64>) -> f64 {
        self.march_from(p, direction, None)
    }

    /// [`Self::blocks`] from any point: whether the terrain rises above `direction` seen from
    /// `p`. The march stops at the first sample above the direction, or once even the field's
    /// highest point could not reach it (a short walk for all but the lowest directions).
    pub fn blocks_from(&self, p: &Vector3<f64>, direction: &Vector3<f64>) -> bool {
        let horizontal = horizontal_length(direction);
        if horizontal == 0.0 {
            return false;
        }
        let elevation_tan = direction.z / horizontal;
        self.march_from(p, direction, Some(elevation_tan)) > elevation_tan
    }

    /// The largest horizon tan from `p` in the azimuth of `direction`, marching until it exceeds
    /// `enough` (when given) or no farther point could raise it (see [`Self::horizon_tan_from`]).
    fn march_from(&self, p: &Vector3<f64>, direction: &Vector3<f64>, enough: Option<f64>) -> f64 {
        let field = self.field;
        let horizontal = horizontal_length(direction);
        let rise = field.max_height_m - p.z;
        if rise <= 0.0 || horizontal == 0.0 {
            return 0.0;
        }
        let (ux, uy) = (direction.x / horizontal, direction.y / horizontal);
        let [u0, v0] = field.grid_coordinates(p.x, p.y);
        // Grid coordinates per metre along the azimuth (the axes are orthogonal).
        let [du, dv] = field
            .axis
            .map(|[ax, ay]| (ux * ax + uy * ay) / (ax * ax + ay * ay));
        let [nx, ny] = field.divisions.map(f64::from);
        let Some((t_in, t_out)) = clip(u0, du, nx).and_then(|(a, b)| {
            let (c, d) = clip(v0, dv, ny)?;
            Some((a.max(c), b.min(d)))
        }) else {
            return 0.0;
        };
        let step = field.cell_m[0].min(field.cell_m[1]);
        // Below `enough` nothing but exceeding it matters, so the walk ends where even the
        // highest point could not rise above it.
        let floor = enough.map_or(0.0, |e| e.max(0.0));
        let mut best = 0.0f64;
        let mut k = (t_in / step).ceil().max(1.0);
        while k * step <= t_out {
            let t = k * step;
            if rise / t <= best.max(floor) || enough.is_some_and(|e| best > e) {
                break;
            }
            if let Some(z) = field.surface_height(u0 + t * du, v0 + t * dv) {
                best = best.max((z - p.z) / t);
            }
            k += 1.0;
        }
        best
    }

    /// The stored horizon tan of grid point `g` along lattice step `step` (one of the 16).
    pub fn lattice_horizon(&self, g: usize, step: [i64; 2]) -> Option<f32> {
        let k = self.steps.iter().position(|&s| s == step)?;
        Some(self.horizon[g][k])
    }

    /// The unit world direction (horizontal) of each lattice step, in ascending azimuth.
    pub fn directions(&self) -> impl Iterator<Item = ([i64; 2], Vector3<f64>)> + '_ {
        self.steps.iter().map(|&s| {
            let w = world_step(self.field, s);
            (s, w / w.norm())
        })
    }
}

/// The distances t ≥ 0 along a ray x0 + t·dx that stay within [0, n], if any.
fn clip(x0: f64, dx: f64, n: f64) -> Option<(f64, f64)> {
    if dx == 0.0 {
        return (0.0..=n).contains(&x0).then_some((0.0, f64::INFINITY));
    }
    let (a, b) = ((0.0 - x0) / dx, (n - x0) / dx);
    let (lo, hi) = (a.min(b).max(0.0), a.max(b));
    (lo <= hi).then_some((lo, hi))
}

/// The world xy displacement of one lattice step (z = 0).
fn world_step(field: &Heightfield, [di, dj]: [i64; 2]) -> Vector3<f64> {
    let [a, b] = field.axis;
    let (di, dj) = (di as f64, dj as f64);
    Vector3::new(di * a[0] + dj * b[0], di * a[1] + dj * b[1], 0.0)
}

/// The slope from point `t` of a line to point `k > t` ahead of it, `step_m` the world length of a
/// step: the one formula of both the map and its brute-force check.
#[inline]
fn slope(z: &[f64], line: &[usize], t: usize, k: usize, step_m: f64) -> f64 {
    (z[line[k]] - z[line[t]]) / ((k - t) as f64 * step_m)
}

/// The horizon tan of every grid point along lattice `step` (Dozier et al.'s pointer walk along
/// each lattice line), indexed by grid point.
fn direction_horizons(field: &Heightfield, step: [i64; 2]) -> Vec<f32> {
    let [px, py] = field.points().map(|n| n as i64);
    let step_m = world_step(field, step).norm();
    let z = &field.heights_m;
    let inside = |i: i64, j: i64| (0..px).contains(&i) && (0..py).contains(&j);
    let mut out = vec![0f32; (px * py) as usize];
    let mut line: Vec<usize> = Vec::new();
    let mut ahead: Vec<u32> = Vec::new();
    for j0 in 0..py {
        for i0 in 0..px {
            // Each line once, from the point with no predecessor on it.
            if inside(i0 - step[0], j0 - step[1]) {
                continue;
            }
            line.clear();
            let (mut i, mut j) = (i0, j0);
            while inside(i, j) {
                line.push((j * px + i) as usize);
                (i, j) = (i + step[0], j + step[1]);
            }
            line_horizons(z, &line, step_m, &mut ahead, &mut out);
        }
    }
    out
}

/// Dozier's walk along one line (points in the direction of view): `ahead` is scratch for the
/// horizon pointers, `out` receives each point's clamped horizon tan.
fn line_horizons(z: &[f64], line: &[usize], step_m: f64, ahead: &mut Vec<u32>, out: &mut [f32]) {
    let n = line.len();
    ahead.clear();
    ahead.resize(n, NO_POINT);
    for t in (0..n.saturating_sub(1)).rev() {
        let mut j = t + 1;
        loop {
            let next = ahead[j];
            if next == NO_POINT
                || slope(z, line, t, next as usize, step_m) < slope(z, line, t, j, step_m)
            {
                break;
            }
            j = next as usize;
        }
        ahead[t] = j as u32;
        out[line[t]] = slope(z, line, t, j, step_m).max(0.0) as f32;
    }
    // The far end sees nothing of the terrain ahead.
    if let Some(&last) = line.last() {
        out[last] = 0.0;
    }
}

/// The length of a direction's horizontal part. Directions here are unit vectors, so the plain
/// square root cannot overflow (glibc's `hypot`, which guards against that, took 3 % of a
/// terrain's thermal run).
fn horizontal_length(d: &Vector3<f64>) -> f64 {
    (d.x * d.x + d.y * d.y).sqrt()
}

#[cfg(test)]
mod tests;
