//! A terrain object kept as the heightfield it is (docs/design.md §1.8, **Exposure**): its grid and
//! world heights, so that the thermal model can find the terrain's self-occlusion from horizon
//! maps (`transport::horizon`) instead of tracing rays against millions of its triangles.
//!
//! Only a terrain that stays a heightfield in world space is kept: uniform scale, any translation
//! and a rotation about z alone. Tilted about x or y, a vertical line can cross it twice and
//! "the height at (x, y)" no longer means anything.

use super::mesh::{RawMesh, Transform};
use nalgebra::Vector3;

/// A positional match to a grid point is within this (m): far above the rounding of world
/// positions, far below any cell.
const GRID_POINT_TOLERANCE_M: f64 = 1e-6;

/// The grid of one terrain object in world space. Grid point (i, j), 0 ≤ i ≤ nx, 0 ≤ j ≤ ny, is
/// `g = j (nx + 1) + i`, the raw mesh's vertex order (`procedural::terrain`), at world
/// xy = origin + i·axis\[0\] + j·axis\[1\] and world z = `heights_m[g]`.
#[derive(Clone, Debug)]
pub struct Heightfield {
    /// The scene surface (`Scene::surfaces`) of the terrain's single part, so that a thermal vertex
    /// can be recognised as lying on it.
    pub surface: u32,
    /// nx, ny cells: (nx + 1) × (ny + 1) grid points. The periodic tile's last row and column
    /// repeat the first (the tile is not repeated in the scene: its edge is its edge).
    pub divisions: [u32; 2],
    /// World cell size along the grid's i and j axes (m): size/divisions × scale.
    pub cell_m: [f64; 2],
    /// World z of each grid point (m), bit-identical to the shaded mesh's vertices.
    pub heights_m: Vec<f64>,
    /// World xy of grid point (0, 0).
    pub origin: [f64; 2],
    /// World xy step of one cell along i and along j (orthogonal, lengths `cell_m`).
    pub axis: [[f64; 2]; 2],
    /// The object's rotation about z (rad): the grid's i axis is at this angle from world x.
    pub rotation_z_rad: f64,
    /// The largest height (m), for early ends of horizon searches.
    pub max_height_m: f64,
}

impl Heightfield {
    /// The heightfield of a terrain tile's raw mesh (`procedural::terrain` of `size` and
    /// `divisions`) placed by `rotate_deg` and `transform`, or `None` when the rotation tilts it
    /// (an x or y component).
    pub fn of_terrain(
        raw: &RawMesh,
        size: [f64; 2],
        divisions: [u32; 2],
        rotate_deg: [f64; 3],
        transform: &Transform,
        surface: u32,
    ) -> Option<Heightfield> {
        if rotate_deg[0] != 0.0 || rotate_deg[1] != 0.0 {
            return None;
        }
        let [nx, ny] = divisions.map(|d| d.max(1));
        let points = (nx as usize + 1) * (ny as usize + 1);
        debug_assert_eq!(raw.positions.len(), points);
        // The mesh's own transform, so that the heights are those of the shaded vertices.
        let heights_m: Vec<f64> = raw.positions.iter().map(|p| transform.point(p).z).collect();
        let max_height_m = heights_m.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let world_xy = |v: Vector3<f64>| {
            let w = transform.rotation * (v * transform.scale);
            [w.x, w.y]
        };
        let corner = transform.point(&Vector3::new(-0.5 * size[0], -0.5 * size[1], 0.0));
        let cell = [size[0] / nx as f64, size[1] / ny as f64];
        Some(Heightfield {
            surface,
            divisions: [nx, ny],
            cell_m: cell.map(|c| c * transform.scale),
            heights_m,
            origin: [corner.x, corner.y],
            axis: [
                world_xy(Vector3::new(cell[0], 0.0, 0.0)),
                world_xy(Vector3::new(0.0, cell[1], 0.0)),
            ],
            rotation_z_rad: rotate_deg[2].to_radians(),
            max_height_m,
        })
    }

    /// Grid points along i and j: nx + 1, ny + 1.
    pub fn points(&self) -> [usize; 2] {
        self.divisions.map(|d| d as usize + 1)
    }

    /// The continuous grid coordinates (i, j) of world xy.
    pub fn grid_coordinates(&self, x: f64, y: f64) -> [f64; 2] {
        let (dx, dy) = (x - self.origin[0], y - self.origin[1]);
        // The axes are orthogonal, so each coordinate is a projection.
        self.axis
            .map(|[ax, ay]| (dx * ax + dy * ay) / (ax * ax + ay * ay))
    }

    /// The grid point a world position lies on (a vertex of this terrain), `None` if it is not
    /// within 1e-6 m of one.
    pub fn grid_point(&self, p: &Vector3<f64>) -> Option<usize> {
        let [u, v] = self.grid_coordinates(p.x, p.y);
        let [px, py] = self.points();
        let (i, j) = (u.round(), v.round());
        if !(i >= 0.0 && j >= 0.0 && i < px as f64 && j < py as f64) {
            return None;
        }
        let g = j as usize * px + i as usize;
        ((self.point(g) - p).norm() <= GRID_POINT_TOLERANCE_M).then_some(g)
    }

    /// The world position of grid point `g`.
    pub fn point(&self, g: usize) -> Vector3<f64> {
        let px = self.points()[0];
        let (i, j) = ((g % px) as f64, (g / px) as f64);
        Vector3::new(
            self.origin[0] + i * self.axis[0][0] + j * self.axis[1][0],
            self.origin[1] + i * self.axis[0][1] + j * self.axis[1][1],
            self.heights_m[g],
        )
    }

    /// The height of the terrain's triangulated surface (two triangles per cell split along
    /// (i, j)–(i + 1, j + 1), as `procedural` cuts them) at grid coordinates (u, v) inside the
    /// grid; `None` outside it.
    pub fn surface_height(&self, u: f64, v: f64) -> Option<f64> {
        let [nx, ny] = self.divisions.map(f64::from);
        if !(u >= 0.0 && v >= 0.0 && u <= nx && v <= ny) {
            return None;
        }
        // The last cell for a coordinate on the far edge.
        let (i, j) = (u.floor().min(nx - 1.0), v.floor().min(ny - 1.0));
        let (fx, fy) = (u - i, v - j);
        let px = self.points()[0];
        let g = j as usize * px + i as usize;
        let h = &self.heights_m;
        let (h00, h10, h01, h11) = (h[g], h[g + 1], h[g + px], h[g + px + 1]);
        Some(if fx >= fy {
            h00 + fx * (h10 - h00) + fy * (h11 - h10)
        } else {
            h00 + fy * (h01 - h00) + fx * (h11 - h01)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::procedural;
    use crate::scene::terrain::TerrainSpectrum;

    fn tile(size: [f64; 2], divisions: [u32; 2]) -> RawMesh {
        let spectrum = TerrainSpectrum {
            rms_height_m: 0.3,
            correlation_length_m: 2.0,
            hurst: None,
            seed: 4,
        };
        procedural::terrain(size, divisions, &spectrum)
    }

    #[test]
    fn grid_points_round_trip_through_world_positions() {
        let (size, divisions) = ([12.0, 5.0], [24, 8]);
        let raw = tile(size, divisions);
        for (scale, rotate, translate) in [
            (1.0, [0.0; 3], [0.0; 3]),
            (2.5, [0.0, 0.0, 37.0], [100.0, -40.0, 3.0]),
            (0.5, [0.0, 0.0, -120.0], [0.0, 7.0, -2.0]),
        ] {
            let transform = Transform::new(scale, rotate, translate);
            let field = Heightfield::of_terrain(&raw, size, divisions, rotate, &transform, 3)
                .expect("upright");
            assert_eq!(field.cell_m, [0.5 * scale, 0.625 * scale]);
            for (g, p) in raw.positions.iter().enumerate() {
                let world = transform.point(p);
                // The mesh's own vertex is the grid point, and the grid point is the vertex.
                assert!((field.point(g) - world).norm() < 1e-9, "{g}");
                assert_eq!(field.heights_m[g], world.z);
                assert_eq!(field.grid_point(&world), Some(g));
                assert_eq!(field.grid_point(&field.point(g)), Some(g));
            }
            // Half a cell away, a millimetre above, or beyond the edge: not on the grid.
            let p = field.point(30);
            let half = Vector3::new(field.axis[0][0], field.axis[0][1], 0.0) * 0.5;
            assert_eq!(field.grid_point(&(p + half)), None);
            assert_eq!(field.grid_point(&(p + Vector3::z() * 1e-3)), None);
            let beyond = field.point(0) - half * 2.0;
            assert_eq!(field.grid_point(&beyond), None);
        }
    }

    #[test]
    fn a_tilted_terrain_is_no_heightfield() {
        let raw = tile([4.0, 4.0], [8, 8]);
        let transform = Transform::new(1.0, [5.0, 0.0, 0.0], [0.0; 3]);
        let field = Heightfield::of_terrain(&raw, [4.0; 2], [8, 8], [5.0, 0.0, 0.0], &transform, 0);
        assert!(field.is_none());
    }

    #[test]
    fn the_surface_height_is_the_meshs_triangles() {
        let (size, divisions) = ([4.0, 3.0], [8, 6]);
        let raw = tile(size, divisions);
        let transform = Transform::new(1.0, [0.0; 3], [0.0; 3]);
        let field =
            Heightfield::of_terrain(&raw, size, divisions, [0.0; 3], &transform, 0).unwrap();
        // At grid points, the heights; on the diagonal of a cell, the mean of its ends; on the
        // far edge, the edge's points.
        let at = |i: usize, j: usize| field.heights_m[j * 9 + i];
        assert_eq!(field.surface_height(3.0, 2.0), Some(at(3, 2)));
        let diagonal = field.surface_height(3.5, 2.5).unwrap();
        assert!((diagonal - 0.5 * (at(3, 2) + at(4, 3))).abs() < 1e-12);
        assert_eq!(field.surface_height(8.0, 6.0), Some(at(8, 6)));
        assert_eq!(field.surface_height(8.01, 1.0), None);
        // Each triangle is a plane: the centroid of (3,2),(4,2),(4,3) has their mean height.
        let centroid = field
            .surface_height(3.0 + 2.0 / 3.0, 2.0 + 1.0 / 3.0)
            .unwrap();
        let mean = (at(3, 2) + at(4, 2) + at(4, 3)) / 3.0;
        assert!((centroid - mean).abs() < 1e-12);
    }
}
