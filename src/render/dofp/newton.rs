//! Newton's polynomial interpolation in the polarization-difference domain (Li, Zhao, Pan &
//! Kong 2019); the method is described in the module docs of `render::dofp`.

use super::orientation;
use super::pad::{padded, Grid};

/// Padding: the reach of the two stages (3 per Newton estimate, 2 more per classifier window,
/// stage 2 reading stage-1 results 3 away).
const PAD: usize = 10;
/// The edge classifier's ratio τ: above it one direction's polarization difference wins outright
/// (the value of the authors' reference implementation).
const TAU: f64 = 5.8;
/// Keeps the gradient weights finite in flat regions.
const WEIGHT_EPS: f64 = 1e-15;

/// The orientation sampled at the pixel (dx, dy) away from (x, y).
fn channel(x: usize, y: usize, dx: usize, dy: usize) -> usize {
    orientation(x + dx, y + dy)
}

/// Newton estimate at (x, y) of the orientation B sampled at odd steps along `dir`; even steps
/// hold A, the pixel's own orientation, from `own`, odd steps B from `other`.
///
/// Newton's form through the two A samples at s ± 1 plus its remainder term
/// f[x₀, x₁, x](x − x₀)(x − x₁) = −f″/2 estimates A at the B pixel s; the remainder's curvature
/// is B's own second difference there (the polarization-difference model: the channels share
/// their high-frequency content, the difference B − A is smooth). The differences B − Â at
/// s = ±1 are then interpolated linearly to the pixel and added to its A sample.
fn along(own: &Grid, other: &Grid, x: usize, y: usize, dir: (isize, isize)) -> f64 {
    let line = |s: isize| {
        let grid = if s % 2 == 0 { own } else { other };
        grid.at(x, y, s * dir.0, s * dir.1)
    };
    let a_at = |s: isize| {
        0.5 * (line(s - 1) + line(s + 1)) - 0.125 * (line(s - 2) - 2.0 * line(s) + line(s + 2))
    };
    let difference = |s: isize| line(s) - a_at(s);
    line(0) + 0.5 * (difference(-1) + difference(1))
}

/// Sum of |estimate − sample| over the pixel's own-orientation neighbours 2 apart (3 × 3 of them):
/// the polarization difference an interpolation direction produces around the pixel.
fn classifier(estimate: &Grid, raw: &Grid, x: usize, y: usize) -> f64 {
    let mut sum = 0.0;
    for dy in [-2, 0, 2] {
        for dx in [-2, 0, 2] {
            sum += (estimate.at(x, y, dx, dy) - raw.at(x, y, dx, dy)).abs();
        }
    }
    sum
}

/// Gradient of the raw mosaic at (x, y) along `dir`: first difference across the pixel plus the
/// second difference of its own orientation.
fn gradient(raw: &Grid, x: usize, y: usize, dir: (isize, isize)) -> f64 {
    let at = |s: isize| raw.at(x, y, s * dir.0, s * dir.1);
    (at(-1) - at(1)).abs() + (2.0 * at(0) - at(-2) - at(2)).abs()
}

/// Fusion of two directional estimates (x, y): the classifier picks one outright when its
/// polarization difference is τ times smaller, otherwise the inverse-gradient weighted mean.
fn fuse(
    raw: &Grid,
    first: &Grid,
    second: &Grid,
    x: usize,
    y: usize,
    dirs: [(isize, isize); 2],
) -> f64 {
    let (e1, e2) = (first.at(x, y, 0, 0), second.at(x, y, 0, 0));
    let (c1, c2) = (classifier(first, raw, x, y), classifier(second, raw, x, y));
    if c1 > TAU * c2 {
        return e2;
    }
    if c2 > TAU * c1 {
        return e1;
    }
    let w1 = 1.0 / (gradient(raw, x, y, dirs[0]) + WEIGHT_EPS);
    let w2 = 1.0 / (gradient(raw, x, y, dirs[1]) + WEIGHT_EPS);
    (w1 * e1 + w2 * e2) / (w1 + w2)
}

const HORIZONTAL: (isize, isize) = (1, 0);
const VERTICAL: (isize, isize) = (0, 1);
const DIAGONAL: (isize, isize) = (1, 1);
const ANTI_DIAGONAL: (isize, isize) = (1, -1);

/// Stage one (Fig. 6 of the paper): the row neighbour's orientation along the row, the column
/// neighbour's along the column, the diagonal neighbour's along both diagonals, fused. Returns
/// the estimates per orientation (each pixel's own orientation holds its sample).
fn stage_one(raw: &Grid) -> [Grid; 4] {
    let (w, h) = (raw.width, raw.height);
    let mut planes: [Grid; 4] = std::array::from_fn(|_| Grid {
        width: w,
        height: h,
        values: raw.values.clone(),
    });
    let mut diagonal = [Grid::filled(w, h, 0.0), Grid::filled(w, h, 0.0)];
    for y in 3..h - 3 {
        for x in 3..w - 3 {
            let i = y * w + x;
            planes[channel(x, y, 1, 0)].values[i] = along(raw, raw, x, y, HORIZONTAL);
            planes[channel(x, y, 0, 1)].values[i] = along(raw, raw, x, y, VERTICAL);
            diagonal[0].values[i] = along(raw, raw, x, y, DIAGONAL);
            diagonal[1].values[i] = along(raw, raw, x, y, ANTI_DIAGONAL);
        }
    }
    for y in 5..h - 5 {
        for x in 5..w - 5 {
            let fused = fuse(
                raw,
                &diagonal[0],
                &diagonal[1],
                x,
                y,
                [DIAGONAL, ANTI_DIAGONAL],
            );
            planes[channel(x, y, 1, 1)].values[y * w + x] = fused;
        }
    }
    planes
}

/// Stage two: the row neighbour's orientation again along the column, through the stage-one
/// diagonal estimates of the column neighbours (and the column neighbour's along the row), each
/// fused with its stage-one estimate.
fn stage_two(raw: &Grid, first: &[Grid; 4]) -> [Grid; 4] {
    let (w, h) = (raw.width, raw.height);
    let mut out = first.clone();
    // Per pixel: [row-neighbour orientation, column-neighbour orientation] × [along row, column].
    let mut row_channel = [Grid::filled(w, h, 0.0), Grid::filled(w, h, 0.0)];
    let mut column_channel = [Grid::filled(w, h, 0.0), Grid::filled(w, h, 0.0)];
    for y in 8..h - 8 {
        for x in 8..w - 8 {
            let i = y * w + x;
            let (hk, vk) = (channel(x, y, 1, 0), channel(x, y, 0, 1));
            row_channel[0].values[i] = first[hk].values[i];
            row_channel[1].values[i] = along(raw, &first[hk], x, y, VERTICAL);
            column_channel[0].values[i] = along(raw, &first[vk], x, y, HORIZONTAL);
            column_channel[1].values[i] = first[vk].values[i];
        }
    }
    let dirs = [HORIZONTAL, VERTICAL];
    for y in PAD..h - PAD {
        for x in PAD..w - PAD {
            let i = y * w + x;
            let (hk, vk) = (channel(x, y, 1, 0), channel(x, y, 0, 1));
            out[hk].values[i] = fuse(raw, &row_channel[0], &row_channel[1], x, y, dirs);
            out[vk].values[i] = fuse(raw, &column_channel[0], &column_channel[1], x, y, dirs);
        }
    }
    out
}

/// Newton demosaicking of a `width` × `height` mosaic (both ≥ 2).
pub(super) fn demosaic(width: usize, height: usize, raw: &[f64]) -> Vec<[f64; 4]> {
    let grid = padded(width, height, raw, PAD);
    let planes = stage_two(&grid, &stage_one(&grid));
    let pw = grid.width;
    (0..width * height)
        .map(|p| {
            let i = (p / width + PAD) * pw + p % width + PAD;
            [0, 1, 2, 3].map(|k| planes[k].values[i])
        })
        .collect()
}
