//! Z-buffered triangle rasterization with perspective-correct barycentrics, one sample at each
//! pixel centre. Triangles are clipped against the near plane (a ground plane runs behind the
//! camera), binned into square tiles, and the tiles are rasterized in parallel.
//!
//! Output per pixel: the front-most triangle and the barycentric coordinates of the sample *in
//! that triangle* (perspective-correct: interpolating 1/z and b/z linearly in screen space), so
//! any vertex attribute can be interpolated exactly as on the 3-D surface.

use crate::scene::camera::Camera;
use nalgebra::Vector3;
use rayon::prelude::*;

pub const TILE: usize = 32;
pub const NO_TRIANGLE: u32 = u32::MAX;

/// What the camera sees at one pixel.
#[derive(Clone, Copy, Debug)]
pub struct Fragment {
    pub triangle: u32,
    /// Barycentric weights of vertices 1 and 2 (vertex 0 gets 1 − b1 − b2).
    pub b1: f32,
    pub b2: f32,
    /// Camera-space depth along the view axis.
    pub depth: f32,
}

impl Fragment {
    const EMPTY: Fragment = Fragment {
        triangle: NO_TRIANGLE,
        b1: 0.0,
        b2: 0.0,
        depth: f32::INFINITY,
    };
}

/// Row-major fragments, row 0 at the top.
pub struct FragmentBuffer {
    pub width: usize,
    pub height: usize,
    pub fragments: Vec<Fragment>,
}

/// A triangle (or a near-clipped piece of one) in screen space.
struct ScreenTriangle {
    triangle: u32,
    x: [f64; 3],
    y: [f64; 3],
    /// 1/z at each corner.
    inv_z: [f64; 3],
    /// Barycentrics of each corner in the original triangle, divided by z.
    bary_over_z: [[f64; 3]; 3],
}

/// Rasterizes `triangles` over `positions` (world space). `near` is the near-plane distance.
/// `on_tile` is called once per finished tile (progress reporting).
pub fn rasterize(
    camera: &Camera,
    positions: &[Vector3<f64>],
    triangles: &[[u32; 3]],
    near: f64,
    on_tile: &(dyn Fn() + Sync),
) -> FragmentBuffer {
    let (width, height) = (camera.width as usize, camera.height as usize);
    let view: Vec<Vector3<f64>> = positions.par_iter().map(|p| camera.to_view(p)).collect();
    let screen: Vec<ScreenTriangle> = triangles
        .par_iter()
        .enumerate()
        .flat_map_iter(|(index, tri)| {
            clip_and_project(camera, index as u32, tri.map(|v| view[v as usize]), near)
        })
        .collect();

    let (tiles_x, tiles_y) = (width.div_ceil(TILE), height.div_ceil(TILE));
    let mut bins: Vec<Vec<u32>> = vec![Vec::new(); tiles_x * tiles_y];
    for (s, tri) in screen.iter().enumerate() {
        let Some((x0, x1, y0, y1)) = pixel_bounds(tri, width, height) else {
            continue;
        };
        for ty in y0 / TILE..=y1 / TILE {
            for tx in x0 / TILE..=x1 / TILE {
                bins[ty * tiles_x + tx].push(s as u32);
            }
        }
    }

    let tiles: Vec<Vec<Fragment>> = bins
        .par_iter()
        .enumerate()
        .map(|(t, bin)| {
            let (tx, ty) = (t % tiles_x, t / tiles_x);
            let tile = rasterize_tile(&screen, bin, tx * TILE, ty * TILE, width, height);
            on_tile();
            tile
        })
        .collect();

    let mut fragments = vec![Fragment::EMPTY; width * height];
    for (t, tile) in tiles.into_iter().enumerate() {
        let (x0, y0) = ((t % tiles_x) * TILE, (t / tiles_x) * TILE);
        let tile_w = TILE.min(width - x0);
        for (row, chunk) in tile.chunks(tile_w).enumerate() {
            let start = (y0 + row) * width + x0;
            fragments[start..start + tile_w].copy_from_slice(chunk);
        }
    }
    FragmentBuffer {
        width,
        height,
        fragments,
    }
}

/// Clips a camera-space triangle to z ≥ near and projects the 0, 1 or 2 resulting triangles.
fn clip_and_project(
    camera: &Camera,
    triangle: u32,
    corners: [Vector3<f64>; 3],
    near: f64,
) -> Vec<ScreenTriangle> {
    const IDENTITY: [[f64; 3]; 3] = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    let inside = corners.map(|c| c.z >= near);
    if !inside.iter().any(|&i| i) {
        return Vec::new();
    }
    // Sutherland–Hodgman against one plane; each polygon vertex keeps its original barycentrics.
    let mut polygon: Vec<(Vector3<f64>, [f64; 3])> = Vec::with_capacity(4);
    for i in 0..3 {
        let j = (i + 1) % 3;
        let (a, b) = (corners[i], corners[j]);
        if inside[i] {
            polygon.push((a, IDENTITY[i]));
        }
        if inside[i] != inside[j] {
            let t = (near - a.z) / (b.z - a.z);
            let bary = [0, 1, 2].map(|k| IDENTITY[i][k] + t * (IDENTITY[j][k] - IDENTITY[i][k]));
            polygon.push((a + (b - a) * t, bary));
        }
    }
    (1..polygon.len() - 1)
        .map(|k| {
            let picked = [polygon[0], polygon[k], polygon[k + 1]];
            let mut tri = ScreenTriangle {
                triangle,
                x: [0.0; 3],
                y: [0.0; 3],
                inv_z: [0.0; 3],
                bary_over_z: [[0.0; 3]; 3],
            };
            for (c, (p, bary)) in picked.iter().enumerate() {
                let (x, y) = camera.view_to_screen(p);
                tri.x[c] = x;
                tri.y[c] = y;
                tri.inv_z[c] = 1.0 / p.z;
                tri.bary_over_z[c] = bary.map(|b| b / p.z);
            }
            tri
        })
        .collect()
}

/// Inclusive pixel range whose centres may be covered, or None if off screen.
fn pixel_bounds(
    tri: &ScreenTriangle,
    width: usize,
    height: usize,
) -> Option<(usize, usize, usize, usize)> {
    let min = |v: &[f64; 3]| v[0].min(v[1]).min(v[2]);
    let max = |v: &[f64; 3]| v[0].max(v[1]).max(v[2]);
    // Pixel i has its centre at i + ½.
    let x0 = (min(&tri.x) - 0.5).ceil().max(0.0);
    let x1 = (max(&tri.x) - 0.5).floor().min(width as f64 - 1.0);
    let y0 = (min(&tri.y) - 0.5).ceil().max(0.0);
    let y1 = (max(&tri.y) - 0.5).floor().min(height as f64 - 1.0);
    if !(x0 <= x1 && y0 <= y1) {
        return None;
    }
    Some((x0 as usize, x1 as usize, y0 as usize, y1 as usize))
}

fn rasterize_tile(
    screen: &[ScreenTriangle],
    bin: &[u32],
    x_start: usize,
    y_start: usize,
    width: usize,
    height: usize,
) -> Vec<Fragment> {
    let tile_w = TILE.min(width - x_start);
    let tile_h = TILE.min(height - y_start);
    let mut out = vec![Fragment::EMPTY; tile_w * tile_h];
    for &s in bin {
        let tri = &screen[s as usize];
        let Some((x0, x1, y0, y1)) = pixel_bounds(tri, width, height) else {
            continue;
        };
        let (x0, x1) = (x0.max(x_start), x1.min(x_start + tile_w - 1));
        let (y0, y1) = (y0.max(y_start), y1.min(y_start + tile_h - 1));
        let area = edge(tri, 0, 1, tri.x[2], tri.y[2]);
        if area.abs() < 1e-12 {
            continue;
        }
        let inv_area = 1.0 / area;
        for py in y0..=y1 {
            let sy = py as f64 + 0.5;
            for px in x0..=x1 {
                let sx = px as f64 + 0.5;
                // Screen-space barycentrics; all ≥ 0 inside whatever the winding.
                let l0 = edge(tri, 1, 2, sx, sy) * inv_area;
                let l1 = edge(tri, 2, 0, sx, sy) * inv_area;
                let l2 = 1.0 - l0 - l1;
                if l0 < 0.0 || l1 < 0.0 || l2 < 0.0 {
                    continue;
                }
                let inv_z = l0 * tri.inv_z[0] + l1 * tri.inv_z[1] + l2 * tri.inv_z[2];
                let depth = (1.0 / inv_z) as f32;
                let slot = &mut out[(py - y_start) * tile_w + (px - x_start)];
                if depth < slot.depth {
                    let bary = |k: usize| {
                        (l0 * tri.bary_over_z[0][k]
                            + l1 * tri.bary_over_z[1][k]
                            + l2 * tri.bary_over_z[2][k])
                            / inv_z
                    };
                    *slot = Fragment {
                        triangle: tri.triangle,
                        b1: bary(1) as f32,
                        b2: bary(2) as f32,
                        depth,
                    };
                }
            }
        }
    }
    out
}

/// Twice the signed area of (corner a, corner b, point p).
#[inline]
fn edge(tri: &ScreenTriangle, a: usize, b: usize, px: f64, py: f64) -> f64 {
    (tri.x[b] - tri.x[a]) * (py - tri.y[a]) - (tri.y[b] - tri.y[a]) * (px - tri.x[a])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(width: u32, height: u32) -> Camera {
        Camera::new(
            Vector3::new(0.0, -5.0, 0.0),
            Vector3::zeros(),
            Vector3::z(),
            60.0,
            width,
            height,
        )
        .unwrap()
    }

    #[test]
    fn nearer_triangles_win_and_barycentrics_reconstruct_points() {
        let cam = camera(40, 30);
        let positions = vec![
            // Far square at y = 2 and a near triangle at y = 0 covering the centre.
            Vector3::new(-3.0, 2.0, -3.0),
            Vector3::new(3.0, 2.0, -3.0),
            Vector3::new(3.0, 2.0, 3.0),
            Vector3::new(-3.0, 2.0, 3.0),
            Vector3::new(-0.5, 0.0, -0.5),
            Vector3::new(0.5, 0.3, -0.5),
            Vector3::new(0.0, -0.2, 0.6),
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]];
        let buffer = rasterize(&cam, &positions, &triangles, 0.01, &|| ());
        let centre = buffer.fragments[15 * 40 + 20];
        assert_eq!(centre.triangle, 2);
        let mut covered = 0;
        for (i, f) in buffer.fragments.iter().enumerate() {
            if f.triangle == NO_TRIANGLE {
                continue;
            }
            covered += 1;
            let [a, b, c] = triangles[f.triangle as usize].map(|v| positions[v as usize]);
            let (b1, b2) = (f.b1 as f64, f.b2 as f64);
            let p = a * (1.0 - b1 - b2) + b * b1 + c * b2;
            // The interpolated point lies on the ray through the pixel centre.
            let (x, y) = ((i % 40) as f64 + 0.5, (i / 40) as f64 + 0.5);
            let ray = cam.ray_direction(x, y);
            let to_p = p - cam.position;
            assert!((to_p.normalize() - ray).norm() < 1e-5, "pixel {i}");
            assert!((to_p.dot(&cam.forward) - f.depth as f64).abs() < 1e-4);
        }
        // The far square covers ~41 % of the 40 × 30 image.
        assert!((450..520).contains(&covered), "{covered}");
    }

    #[test]
    fn triangles_behind_the_camera_are_clipped() {
        let cam = camera(32, 32);
        // A ground-like quad from behind the camera to far in front, below the eye.
        let positions = vec![
            Vector3::new(-10.0, -20.0, -1.0),
            Vector3::new(10.0, -20.0, -1.0),
            Vector3::new(10.0, 20.0, -1.0),
            Vector3::new(-10.0, 20.0, -1.0),
        ];
        let buffer = rasterize(&cam, &positions, &[[0, 1, 2], [0, 2, 3]], 0.01, &|| ());
        // Bottom rows see the ground, top rows the sky; no pixel is wrongly hit above the horizon.
        assert!(buffer.fragments[31 * 32 + 16].triangle != NO_TRIANGLE);
        assert!(buffer.fragments[16].triangle == NO_TRIANGLE);
        for (i, f) in buffer.fragments.iter().enumerate() {
            if f.triangle != NO_TRIANGLE {
                let [a, b, c] = [0, 1, 2]
                    .map(|k| positions[[[0, 1, 2], [0, 2, 3]][f.triangle as usize][k] as usize]);
                let p = a * (1.0 - f.b1 as f64 - f.b2 as f64) + b * f.b1 as f64 + c * f.b2 as f64;
                assert!((p.z + 1.0).abs() < 1e-4 && p.y > -5.0, "pixel {i}: {p:?}");
            }
        }
    }
}
