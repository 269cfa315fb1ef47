//! Bilinear demosaicking: every orientation's lattice (spacing 2) bilinearly interpolated to every
//! pixel, the nearest lattice rows/columns beyond the last sample at the image border.

use super::lattice_origin;

/// Bilinear weights along one axis: the two lattice indices around pixel `p` on the lattice
/// `origin + 2i` (i < n) and the weight of the second.
fn axis(p: usize, origin: usize, n: usize) -> (usize, usize, f64) {
    let u = (p as f64 - origin as f64) / 2.0;
    let last = n.saturating_sub(1);
    if u <= 0.0 {
        return (0, 0, 0.0);
    }
    let i = (u.floor() as usize).min(last);
    let j = (i + 1).min(last);
    (i, j, if j == i { 0.0 } else { u - i as f64 })
}

/// Demosaicked (I0, I45, I90, I135) per pixel from a raw mosaic of `width` × `height`.
pub(super) fn demosaic(width: usize, height: usize, raw: &[f64]) -> Vec<[f64; 4]> {
    let planes: Vec<Vec<f64>> = (0..4)
        .map(|k| interpolate_orientation(width, height, raw, k))
        .collect();
    (0..width * height)
        .map(|p| [planes[0][p], planes[1][p], planes[2][p], planes[3][p]])
        .collect()
}

/// Orientation `k`'s samples of the mosaic, bilinearly interpolated to every pixel (zero where
/// the image holds no sample of `k`: a single row or column).
fn interpolate_orientation(width: usize, height: usize, raw: &[f64], k: usize) -> Vec<f64> {
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
