//! Procedural objects with exact normals: an icosphere, a subdivided plane and a terrain tile.
//! Each is one part named `surface`.

use super::mesh::{FaceOrigin, RawFace, RawMesh};
use super::terrain::{self, TerrainSpectrum};
use nalgebra::Vector3;
use std::collections::HashMap;

pub const SHAPE_PART: &str = "surface";

/// Unit icosahedron subdivided `subdivisions` times (20·4ⁿ faces) and scaled to `radius`, with
/// the exact radial normals, outward winding.
pub fn icosphere(radius: f64, subdivisions: u32) -> RawMesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut positions: Vec<Vector3<f64>> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .iter()
    .map(|p| Vector3::from(*p).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..subdivisions {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut middle = |a: u32, b: u32, positions: &mut Vec<Vector3<f64>>| {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let m = (positions[a as usize] + positions[b as usize]).normalize();
                positions.push(m);
                (positions.len() - 1) as u32
            })
        };
        let mut next = Vec::with_capacity(faces.len() * 4);
        for [a, b, c] in faces {
            let ab = middle(a, b, &mut positions);
            let bc = middle(b, c, &mut positions);
            let ca = middle(c, a, &mut positions);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    let normals = positions.clone();
    let mut mesh = RawMesh {
        positions: positions.iter().map(|p| p * radius).collect(),
        normals,
        ..RawMesh::default()
    };
    let part = mesh.part_index(SHAPE_PART);
    mesh.faces = faces
        .into_iter()
        .enumerate()
        .map(|(i, f)| RawFace {
            vertices: f,
            normals: Some(f),
            part,
            origin: FaceOrigin::Index(i + 1),
        })
        .collect();
    mesh
}

/// At least `divisions`, and enough that no cell of a `size` plane is longer than `cell_m`
/// (at most 4096 a side).
pub fn divisions_for_cell(size: [f64; 2], divisions: [u32; 2], cell_m: f64) -> [u32; 2] {
    [0, 1].map(|axis| {
        let needed = (size[axis] / cell_m).ceil().min(4096.0) as u32;
        divisions[axis].max(needed)
    })
}

/// A `size[0]` × `size[1]` plane in z = 0 centred at the origin, facing +z, cut into
/// `divisions[0]` × `divisions[1]` squares of two triangles each.
pub fn plane(size: [f64; 2], divisions: [u32; 2]) -> RawMesh {
    let [nx, ny] = divisions.map(|d| d.max(1));
    let mut mesh = RawMesh::default();
    push_grid_vertices(&mut mesh, size, [nx, ny], |_, _| 0.0);
    mesh.normals.push(Vector3::z());
    push_grid_faces(&mut mesh, [nx, ny], |_| 0);
    mesh
}

/// A terrain tile (see [`super::terrain`]): the `size` plane of [`plane`] displaced by a random
/// heightfield of the given spectrum, with the heightfield's exact normals at every vertex. The
/// tile is periodic, so its last row and column repeat the first.
pub fn terrain(size: [f64; 2], divisions: [u32; 2], spectrum: &TerrainSpectrum) -> RawMesh {
    let [nx, ny] = divisions.map(|d| d.max(1));
    let (gx, gy) = (nx as usize, ny as usize);
    let field = terrain::synthesize(size, [gx, gy], spectrum);
    let grid = |i: u32, j: u32| (j as usize % gy) * gx + i as usize % gx;
    let mut mesh = RawMesh::default();
    push_grid_vertices(&mut mesh, size, [nx, ny], |i, j| field.height[grid(i, j)]);
    for j in 0..=ny {
        for i in 0..=nx {
            let g = grid(i, j);
            mesh.normals
                .push(Vector3::new(-field.slope_x[g], -field.slope_y[g], 1.0).normalize());
        }
    }
    push_grid_faces(&mut mesh, [nx, ny], |vertex| vertex);
    mesh
}

/// The (nx + 1) × (ny + 1) corners of a `size` grid centred at the origin, row-major, at
/// height `height(i, j)`.
fn push_grid_vertices(
    mesh: &mut RawMesh,
    size: [f64; 2],
    [nx, ny]: [u32; 2],
    height: impl Fn(u32, u32) -> f64,
) {
    mesh.positions.reserve(((nx + 1) * (ny + 1)) as usize);
    for j in 0..=ny {
        for i in 0..=nx {
            mesh.positions.push(Vector3::new(
                size[0] * (i as f64 / nx as f64 - 0.5),
                size[1] * (j as f64 / ny as f64 - 0.5),
                height(i, j),
            ));
        }
    }
}

/// Two counter-clockwise (seen from +z) triangles per grid cell, one part; `normal(v)` is the
/// normal index of vertex v.
fn push_grid_faces(mesh: &mut RawMesh, [nx, ny]: [u32; 2], normal: impl Fn(u32) -> u32) {
    let part = mesh.part_index(SHAPE_PART);
    let index = |i: u32, j: u32| j * (nx + 1) + i;
    mesh.faces.reserve(2 * (nx * ny) as usize);
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (
                index(i, j),
                index(i + 1, j),
                index(i + 1, j + 1),
                index(i, j + 1),
            );
            for vertices in [[a, b, c], [a, c, d]] {
                mesh.faces.push(RawFace {
                    vertices,
                    normals: Some(vertices.map(&normal)),
                    part,
                    origin: FaceOrigin::Index(mesh.faces.len() + 1),
                });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_is_a_closed_outward_sphere() {
        let mesh = icosphere(2.0, 3);
        assert_eq!(mesh.faces.len(), 20 * 64);
        // Euler characteristic of a closed genus-0 surface: V − E + F = 2 with E = 3F/2.
        assert_eq!(mesh.positions.len() as i64 - 3 * 20 * 64 / 2 + 20 * 64, 2);
        let mut area = 0.0;
        for face in &mesh.faces {
            let [a, b, c] = face.vertices.map(|i| mesh.positions[i as usize]);
            let cross = (b - a).cross(&(c - a));
            assert!(cross.dot(&(a + b + c)) > 0.0, "inward face");
            area += 0.5 * cross.norm();
        }
        // Inscribed polyhedron: slightly below 4πr² = 50.27.
        assert!(area < 16.0 * std::f64::consts::PI && area > 0.98 * 16.0 * std::f64::consts::PI);
        assert!(mesh
            .positions
            .iter()
            .all(|p| (p.norm() - 2.0).abs() < 1e-12));
    }

    #[test]
    fn a_plane_cell_raises_divisions_but_never_lowers_them() {
        assert_eq!(divisions_for_cell([20.0, 0.5], [1, 1], 0.25), [80, 2]);
        assert_eq!(divisions_for_cell([20.0, 0.5], [200, 1], 0.25), [200, 2]);
        // An exact multiple needs no extra cell; a sliver more needs one.
        assert_eq!(divisions_for_cell([1.0, 1.0 + 1e-9], [1, 1], 0.25), [4, 5]);
        assert_eq!(divisions_for_cell([1e6, 1.0], [1, 1], 0.25), [4096, 4]);
    }

    #[test]
    fn plane_faces_up_and_covers_its_size() {
        let mesh = plane([4.0, 2.0], [4, 2]);
        assert_eq!(mesh.faces.len(), 16);
        let mut area = 0.0;
        for face in &mesh.faces {
            let [a, b, c] = face.vertices.map(|i| mesh.positions[i as usize]);
            let cross = (b - a).cross(&(c - a));
            assert!(cross.z > 0.0);
            area += 0.5 * cross.norm();
        }
        assert!((area - 8.0).abs() < 1e-12);
    }

    #[test]
    fn a_terrain_tile_is_periodic_and_its_normals_face_up() {
        let spectrum = TerrainSpectrum {
            rms_height_m: 0.5,
            correlation_length_m: 2.0,
            hurst: Some(0.5),
            seed: 9,
        };
        let mesh = terrain([20.0, 10.0], [40, 20], &spectrum);
        assert_eq!(
            (mesh.positions.len(), mesh.faces.len()),
            (41 * 21, 2 * 40 * 20)
        );
        let at = |i: usize, j: usize| j * 41 + i;
        for j in 0..=20 {
            assert_eq!(mesh.positions[at(0, j)].z, mesh.positions[at(40, j)].z);
            assert_eq!(mesh.normals[at(0, j)], mesh.normals[at(40, j)]);
        }
        for i in 0..=40 {
            assert_eq!(mesh.positions[at(i, 0)].z, mesh.positions[at(i, 20)].z);
        }
        assert!(mesh
            .normals
            .iter()
            .all(|n| n.z > 0.0 && (n.norm() - 1.0).abs() < 1e-12));
        // Every face winds up (+z), so its geometric normal agrees with the shading normals.
        for face in &mesh.faces {
            let [a, b, c] = face.vertices.map(|i| mesh.positions[i as usize]);
            assert!((b - a).cross(&(c - a)).z > 0.0);
        }
    }
}
