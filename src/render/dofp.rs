//! A division-of-focal-plane (DoFP) polarization camera: every pixel has its own
//! wire-grid polarizer, repeating over 2×2 superpixels, so each pixel records one of I0, I45, I90,
//! I135 and the other three must be interpolated ("demosaicked") before Stokes images exist.
//!
//! **Pattern** (as Sony's Polarsens sensors and most LWIR DoFP cameras lay it out), with x to the
//! right and row 0 at the top:
//! ```text
//!   row 0:  90°   45°   90°   45° …
//!   row 1: 135°    0°  135°    0° …
//! ```
//! **Demosaicking**: each orientation's samples form a lattice of spacing 2; every pixel takes the
//! bilinear interpolation of its orientation lattices (nearest lattice rows/columns at the image
//! border), then S0 = ½(I0 + I45 + I90 + I135), S1 = I0 − I90, S2 = I45 − I135. Bilinear
//! demosaicking is the common baseline: exact for images linear in x and y, and it produces the
//! false polarization at edges that real DoFP data shows (instantaneous field-of-view error).

/// Polarizer index (0 → 0°, 1 → 45°, 2 → 90°, 3 → 135°) of pixel (x, y).
#[inline]
pub fn orientation(x: usize, y: usize) -> usize {
    match (y % 2, x % 2) {
        (0, 0) => 2,
        (0, _) => 1,
        (_, 0) => 3,
        _ => 0,
    }
}

/// The raw mosaic: each pixel's recorded polarizer image at its own orientation. `polarizers`
/// holds (I0, I45, I90, I135) per pixel, row-major.
pub fn mosaic(width: usize, polarizers: &[[f32; 4]]) -> Vec<f32> {
    polarizers
        .iter()
        .enumerate()
        .map(|(i, p)| p[orientation(i % width, i / width)])
        .collect()
}

/// The lattice offset (x0, y0) of orientation `k` within a superpixel.
fn lattice_origin(k: usize) -> (usize, usize) {
    match k {
        2 => (0, 0),
        1 => (1, 0),
        3 => (0, 1),
        _ => (1, 1),
    }
}

/// Bilinear weights along one axis: the two lattice indices around pixel `p` on the lattice
/// `origin + 2i` (i < n) and the weight of the second.
fn axis(p: usize, origin: usize, n: usize) -> (usize, usize, f32) {
    let u = (p as f32 - origin as f32) / 2.0;
    let last = n.saturating_sub(1);
    if u <= 0.0 {
        return (0, 0, 0.0);
    }
    let i = (u.floor() as usize).min(last);
    let j = (i + 1).min(last);
    (i, j, if j == i { 0.0 } else { u - i as f32 })
}

/// Demosaicked (I0, I45, I90, I135) per pixel from a raw mosaic of `width` × `height`.
pub fn demosaic(width: usize, height: usize, raw: &[f32]) -> Vec<[f32; 4]> {
    let planes: Vec<Vec<f32>> = (0..4)
        .map(|k| interpolate_orientation(width, height, raw, k))
        .collect();
    (0..width * height)
        .map(|p| [planes[0][p], planes[1][p], planes[2][p], planes[3][p]])
        .collect()
}

/// Orientation `k`'s samples of the mosaic, bilinearly interpolated to every pixel.
fn interpolate_orientation(width: usize, height: usize, raw: &[f32], k: usize) -> Vec<f32> {
    let (x0, y0) = lattice_origin(k);
    let nx = width.saturating_sub(x0).div_ceil(2);
    let ny = height.saturating_sub(y0).div_ceil(2);
    if nx == 0 || ny == 0 {
        return vec![0.0; width * height];
    }
    let sample = |i: usize, j: usize| raw[(y0 + 2 * j) * width + x0 + 2 * i];
    let mut plane = Vec::with_capacity(width * height);
    for y in 0..height {
        let (j0, j1, fy) = axis(y, y0, ny);
        for x in 0..width {
            let (i0, i1, fx) = axis(x, x0, nx);
            let top = sample(i0, j0) * (1.0 - fx) + sample(i1, j0) * fx;
            let bottom = sample(i0, j1) * (1.0 - fx) + sample(i1, j1) * fx;
            plane.push(top * (1.0 - fy) + bottom * fy);
        }
    }
    plane
}

/// Stokes (S0, S1, S2) from the four polarizer images.
#[inline]
pub fn stokes_from_polarizers(i: [f32; 4]) -> [f32; 3] {
    [0.5 * (i[0] + i[1] + i[2] + i[3]), i[0] - i[2], i[1] - i[3]]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_superpixel_holds_each_orientation_once() {
        for (x, y) in [(0, 0), (2, 4), (10, 6)] {
            let mut seen = [
                orientation(x, y),
                orientation(x + 1, y),
                orientation(x, y + 1),
            ]
            .to_vec();
            seen.push(orientation(x + 1, y + 1));
            seen.sort();
            assert_eq!(seen, vec![0, 1, 2, 3]);
        }
        assert_eq!((orientation(0, 0), orientation(1, 0)), (2, 1));
        assert_eq!((orientation(0, 1), orientation(1, 1)), (3, 0));
    }

    #[test]
    fn demosaicking_reproduces_images_linear_in_x_and_y() {
        let (w, h) = (9, 7);
        // I_k(x, y) = a_k + b_k x + c_k y.
        let truth = |x: usize, y: usize| {
            [0usize, 1, 2, 3]
                .map(|k| 10.0 + k as f32 + 0.5 * x as f32 - 0.25 * (k as f32) * y as f32)
        };
        let polarizers: Vec<[f32; 4]> = (0..w * h).map(|i| truth(i % w, i / w)).collect();
        let back = demosaic(w, h, &mosaic(w, &polarizers));
        // Exact wherever a pixel lies between lattice samples (not beyond the last one).
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                for (k, want) in truth(x, y).iter().enumerate() {
                    assert!((back[y * w + x][k] - want).abs() < 1e-4, "({x},{y}) k={k}");
                }
            }
        }
    }
}
