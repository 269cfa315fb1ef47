//! The mosaic extended beyond its border, for the methods whose stencils reach several pixels.
//!
//! Every pixel outside the image takes the odd (point) reflection of its own orientation's
//! lattice about that lattice's outermost sample: along a row, pixel x < 0 gets
//! 2 f(x₀) − f(2x₀ − x), x₀ ∈ {0, 1} the first sample of x's parity, and likewise past the last
//! sample; rows first, then columns of the widened image. A reflection by an even distance keeps
//! the 2×2 pattern, and the point reflection continues a channel that is linear in x and y
//! exactly (an even reflection would fold it into a ridge), so methods that are exact for linear
//! images stay exact up to the border. Where the image is too narrow for the mirror sample
//! (fewer than `pad + 3` pixels) the mirror is clamped to the farthest sample of that parity:
//! finite, no longer exact.

/// A padded copy of a mosaic, in f64, with the image at (`pad`, `pad`).
#[derive(Clone)]
pub(super) struct Grid {
    pub width: usize,
    pub height: usize,
    pub values: Vec<f64>,
}

impl Grid {
    /// Value at (x, y) displaced by (dx, dy); the callers keep inside the grid.
    #[inline]
    pub fn at(&self, x: usize, y: usize, dx: isize, dy: isize) -> f64 {
        let xi = (x as isize + dx) as usize;
        let yi = (y as isize + dy) as usize;
        self.values[yi * self.width + xi]
    }

    pub fn filled(width: usize, height: usize, value: f64) -> Grid {
        Grid {
            width,
            height,
            values: vec![value; width * height],
        }
    }
}

/// (pivot, mirror) indices along an axis of `n ≥ 2` samples for position `x` (maybe outside):
/// the value there is 2 f(pivot) − f(mirror), both of x's parity; (x, x) inside.
fn reflect(x: isize, n: usize) -> (usize, usize) {
    let n = n as isize;
    let parity = x.rem_euclid(2);
    let first = parity;
    let last = if (n - 1).rem_euclid(2) == parity {
        n - 1
    } else {
        n - 2
    };
    let (pivot, mirror) = if x < 0 {
        (first, 2 * first - x)
    } else if x >= n {
        (last, 2 * last - x)
    } else {
        (x, x)
    };
    (pivot as usize, mirror.clamp(first, last) as usize)
}

/// The mosaic `raw` (`width` × `height`, both ≥ 2) extended by `pad` (even) on every side.
pub(super) fn padded(width: usize, height: usize, raw: &[f64], pad: usize) -> Grid {
    debug_assert!(width >= 2 && height >= 2 && pad.is_multiple_of(2));
    let (pw, ph) = (width + 2 * pad, height + 2 * pad);
    let offset = pad as isize;
    // Rows of the image, widened.
    let mut wide = vec![0.0; pw * height];
    for y in 0..height {
        let row = &raw[y * width..(y + 1) * width];
        for x in 0..pw {
            let (p, m) = reflect(x as isize - offset, width);
            wide[y * pw + x] = 2.0 * row[p] - row[m];
        }
    }
    let mut grid = Grid::filled(pw, ph, 0.0);
    for y in 0..ph {
        let (p, m) = reflect(y as isize - offset, height);
        for x in 0..pw {
            grid.values[y * pw + x] = 2.0 * wide[p * pw + x] - wide[m * pw + x];
        }
    }
    grid
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padding_continues_each_lattice_linearly_and_keeps_the_pattern() {
        let (w, h, pad) = (15, 16, 12);
        let channel = |k: usize, x: f64, y: f64| 3.0 + k as f64 - 0.7 * x + (0.2 + k as f64) * y;
        let raw: Vec<f64> = (0..w * h)
            .map(|i| {
                let (x, y) = (i % w, i / w);
                channel(super::super::orientation(x, y), x as f64, y as f64)
            })
            .collect();
        let grid = padded(w, h, &raw, pad);
        for y in 0..grid.height {
            for x in 0..grid.width {
                let k = super::super::orientation(x, y);
                let (ix, iy) = (x as f64 - pad as f64, y as f64 - pad as f64);
                let got = grid.at(x, y, 0, 0);
                assert!((got - channel(k, ix, iy)).abs() < 1e-4, "({x},{y}) {got}");
            }
        }
    }

    #[test]
    fn narrow_images_pad_to_finite_values() {
        for (w, h) in [(2, 2), (3, 2), (2, 5), (4, 3)] {
            let raw: Vec<f64> = (0..w * h).map(|i| i as f64).collect();
            let grid = padded(w, h, &raw, 10);
            assert!(grid.values.iter().all(|v| v.is_finite()), "{w}x{h}");
        }
    }
}
