//! Guided-filter residual interpolation (after Ahmed, Zhao, Gruev, Zhang & Bermak 2017); the
//! method is described in the module docs of `render::dofp`.

use super::lattice_origin;
use super::pad::{padded, Grid};

/// Lattice radius of the guided filter's window: 5 × 5 samples of one orientation (9 × 9 pixels).
const RADIUS: usize = 2;
/// Padding: the regression and its averaging windows (2 × 2·RADIUS) and the interpolation
/// between lattice samples (1 + 1), rounded up to keep the pattern (even).
const PAD: usize = 10;
/// The guided filter's regularization relative to the mosaic's peak: a window whose guide
/// varies by less than ~1e-3 of the peak is treated as flat (slope → 0) rather than fitted.
const EPS_RELATIVE: f64 = 1e-3;

/// The guide: the mean of the four orientations as Newton's method demosaicks them (S0/2 at full
/// resolution, edges kept), padded like the mosaic. A guide must carry the image's edges and none
/// of the 2×2 pattern; the 3 × 3 binomial filter of the mosaic (which weighs the four orientations
/// ¼ each) does too, but blurs the edges it should carry: on the car it gave 4–5 dB less in S1
/// and S2 than this guide.
fn guide(width: usize, height: usize, raw: &[f64]) -> Grid {
    let mean: Vec<f64> = super::newton::demosaic(width, height, raw)
        .iter()
        .map(|p| 0.25 * (p[0] + p[1] + p[2] + p[3]))
        .collect();
    padded(width, height, &mean, PAD)
}

/// Means over (2r + 1)² windows of an `nx` × `ny` lattice, truncated at its edges.
fn box_mean(values: &[f64], nx: usize, ny: usize, r: usize) -> Vec<f64> {
    let pass = |input: &[f64], horizontal: bool| -> Vec<f64> {
        let mut out = vec![0.0; nx * ny];
        for j in 0..ny {
            for i in 0..nx {
                let (c, n) = if horizontal { (i, nx) } else { (j, ny) };
                let (lo, hi) = (c.saturating_sub(r), (c + r).min(n - 1));
                let at = |k: usize| {
                    if horizontal {
                        input[j * nx + k]
                    } else {
                        input[k * nx + i]
                    }
                };
                out[j * nx + i] = (lo..=hi).map(at).sum::<f64>() / (hi - lo + 1) as f64;
            }
        }
        out
    };
    pass(&pass(values, true), false)
}

/// One orientation's lattice in the padded grid: origin, size, and the samples and guide on it.
struct Lattice {
    x0: usize,
    y0: usize,
    nx: usize,
    ny: usize,
}

impl Lattice {
    fn of(k: usize, grid: &Grid) -> Lattice {
        let (x0, y0) = lattice_origin(k);
        Lattice {
            x0,
            y0,
            nx: (grid.width - x0).div_ceil(2),
            ny: (grid.height - y0).div_ceil(2),
        }
    }

    fn gather(&self, grid: &Grid) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.nx * self.ny);
        for j in 0..self.ny {
            for i in 0..self.nx {
                out.push(grid.values[(self.y0 + 2 * j) * grid.width + self.x0 + 2 * i]);
            }
        }
        out
    }

    /// Bilinear value of lattice data at pixel (x, y) of the padded grid, which lies on or between
    /// lattice samples (never beyond the lattice: the callers stay PAD inside the grid).
    fn at(&self, data: &[f64], x: usize, y: usize) -> f64 {
        let (u, v) = (x - self.x0, y - self.y0);
        let (i0, j0) = (u / 2, v / 2);
        let (i1, j1) = (i0 + u % 2, j0 + v % 2);
        let d = |i: usize, j: usize| data[j * self.nx + i];
        0.25 * (d(i0, j0) + d(i1, j0) + d(i0, j1) + d(i1, j1))
    }
}

/// Orientation `k` at every pixel of the padded grid's image region: the guided filter's
/// tentative estimate ā G + b̄ plus the bilinearly interpolated residual of the samples.
fn orientation_plane(raw: &Grid, g: &Grid, k: usize, eps: f64, out: &mut [[f64; 4]], width: usize) {
    let lattice = Lattice::of(k, raw);
    let (nx, ny) = (lattice.nx, lattice.ny);
    let (p, gl) = (lattice.gather(raw), lattice.gather(g));
    let product = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).collect::<Vec<_>>();
    let mean = |v: &[f64]| box_mean(v, nx, ny, RADIUS);
    let (mg, mp) = (mean(&gl), mean(&p));
    let (mgg, mgp) = (mean(&product(&gl, &gl)), mean(&product(&gl, &p)));
    let a: Vec<f64> = (0..nx * ny)
        .map(|i| (mgp[i] - mg[i] * mp[i]) / ((mgg[i] - mg[i] * mg[i]).max(0.0) + eps))
        .collect();
    let b: Vec<f64> = (0..nx * ny).map(|i| mp[i] - a[i] * mg[i]).collect();
    let (a, b) = (mean(&a), mean(&b));
    let residual: Vec<f64> = (0..nx * ny).map(|i| p[i] - (a[i] * gl[i] + b[i])).collect();
    for (index, pixel) in out.iter_mut().enumerate() {
        let (x, y) = (index % width + PAD, index / width + PAD);
        if super::orientation(x, y) == k {
            pixel[k] = raw.at(x, y, 0, 0);
            continue;
        }
        let tentative = lattice.at(&a, x, y) * g.at(x, y, 0, 0) + lattice.at(&b, x, y);
        pixel[k] = tentative + lattice.at(&residual, x, y);
    }
}

/// Residual demosaicking of a `width` × `height` mosaic (both ≥ 2).
pub(super) fn demosaic(width: usize, height: usize, raw: &[f64]) -> Vec<[f64; 4]> {
    let grid = padded(width, height, raw, PAD);
    let g = guide(width, height, raw);
    let peak = raw.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let eps = (EPS_RELATIVE * peak).powi(2) + f64::MIN_POSITIVE;
    let mut out = vec![[0.0f64; 4]; width * height];
    for k in 0..4 {
        orientation_plane(&grid, &g, k, eps, &mut out, width);
    }
    out
}
