use super::*;
use crate::scene::procedural::{icosphere, plane};
use rand::{Rng, SeedableRng};

fn mesh_of(positions: Vec<Vector3<f64>>, triangles: Vec<[u32; 3]>) -> ShadedMesh {
    ShadedMesh {
        normals: vec![Vector3::z(); positions.len()],
        temperatures: vec![300.0; positions.len()],
        triangle_surface: vec![0; triangles.len()],
        positions,
        triangles,
    }
}

fn square() -> ShadedMesh {
    ShadedMesh {
        temperatures: vec![300.0, 310.0, 320.0, 330.0],
        ..mesh_of(
            vec![
                Vector3::new(-1.0, -1.0, 0.0),
                Vector3::new(1.0, -1.0, 0.0),
                Vector3::new(1.0, 1.0, 0.0),
                Vector3::new(-1.0, 1.0, 0.0),
            ],
            vec![[0, 1, 2], [0, 2, 3]],
        )
    }
}

#[test]
fn hits_either_side_at_the_right_point_with_interpolated_attributes() {
    let mesh = square();
    let accel = Accelerator::new(&mesh, 3.0);
    let down = Vector3::new(0.0, 0.0, -1.0);
    let hit = accel
        .closest_hit(&Vector3::new(0.5, -0.25, 2.0), &down)
        .unwrap();
    assert!((hit.point - Vector3::new(0.5, -0.25, 0.0)).norm() < 1e-12);
    // Bilinear data on a linear split: T = 315 + 5x + 10y... on triangle 0 (x ≥ y).
    let b = hit.barycentric;
    let expected = 300.0 * b[0] + 310.0 * b[1] + 320.0 * b[2];
    assert!((hit.temperature - expected).abs() < 1e-9);
    assert_eq!(hit.triangle, 0);
    // From below (back face).
    let up = Vector3::new(0.0, 0.0, 1.0);
    let hit = accel
        .closest_hit(&Vector3::new(-0.5, 0.25, -1.0), &up)
        .unwrap();
    assert_eq!(hit.triangle, 1);
    assert!(accel.occluded(&Vector3::new(-0.5, 0.25, -1.0), &up));
    assert!(!accel.occluded(&Vector3::new(3.0, 0.0, -1.0), &up));
    assert!(accel
        .closest_hit(&Vector3::new(0.0, 0.0, 1.0), &up)
        .is_none());
}

/// The reference: every triangle of the mesh in order, without the hierarchy.
fn brute_force(
    mesh: &ShadedMesh,
    origin: &Vector3<f64>,
    direction: &Vector3<f64>,
) -> Option<SurfaceHit> {
    let ray = Ray::new(origin, direction);
    let mut best = (f64::INFINITY, None);
    for t in 0..mesh.triangles.len() {
        if let Some((distance, b1, b2)) = Triangle::new(mesh, t).intersect(&ray, best.0) {
            best = (distance, Some((t, b1, b2)));
        }
    }
    let (t, b1, b2) = best.1?;
    Some(mesh.interpolate(t, b1, b2))
}

/// Checks `closest_hit` and `occluded` against the brute-force reference on `rays`; returns the
/// numbers of hits and misses.
fn agree_with_brute_force(
    mesh: &ShadedMesh,
    rays: impl Iterator<Item = (Vector3<f64>, Vector3<f64>)>,
) -> (usize, usize) {
    let accel = Accelerator::new(mesh, 10.0);
    let (mut hits, mut misses) = (0, 0);
    for (i, (origin, direction)) in rays.enumerate() {
        let expected = brute_force(mesh, &origin, &direction);
        match (&expected, accel.closest_hit(&origin, &direction)) {
            (Some(expected), Some(hit)) => {
                hits += 1;
                assert!(
                    hit.triangle == expected.triangle || (hit.point - expected.point).norm() < 1e-9,
                    "ray {i} {origin:?} {direction:?}: {hit:?}, expected {expected:?}"
                );
            }
            (None, None) => misses += 1,
            (expected, ours) => {
                panic!("ray {i} {origin:?} {direction:?}: {ours:?}, expected {expected:?}")
            }
        }
        let occluded = accel.occluded(&origin, &direction);
        assert_eq!(occluded, expected.is_some(), "ray {i}");
    }
    (hits, misses)
}

/// A direction with random components, some set to zero (rays parallel to axes and planes).
fn random_direction(rng: &mut impl Rng, i: usize) -> Vector3<f64> {
    let mut d = Vector3::from_fn(|_, _| rng.random_range(-1.0..1.0));
    if i.is_multiple_of(5) {
        d.z = 0.0;
    }
    if i.is_multiple_of(7) {
        (d.x, d.y) = (0.0, 0.0);
    }
    if i.is_multiple_of(11) {
        d.x = 0.0;
    }
    d.normalize()
}

/// The icosphere (at z = 1.02) over a plane, as in the Mitsuba comparison scene.
fn sphere_over_plane() -> ShadedMesh {
    let (sphere, ground) = (icosphere(1.0, 3), plane([8.0, 8.0], [2, 2]));
    let mut positions: Vec<Vector3<f64>> = (sphere.positions.iter())
        .map(|p| p + Vector3::new(0.0, 0.0, 1.02))
        .collect();
    let offset = positions.len() as u32;
    positions.extend(ground.positions.iter().copied());
    let mut triangles: Vec<[u32; 3]> = sphere.faces.iter().map(|f| f.vertices).collect();
    triangles.extend(ground.faces.iter().map(|f| f.vertices.map(|v| v + offset)));
    mesh_of(positions, triangles)
}

/// The hierarchy finds the same first triangle as the brute-force loop, and the any-hit shadow
/// query agrees with it, on random rays from inside, outside and on the surface of an icosphere
/// over a plane (origins on the plane and on sphere triangles, rays grazing the plane and
/// parallel to axes included).
#[test]
fn queries_agree_with_brute_force_on_a_sphere_over_a_plane() {
    let mesh = sphere_over_plane();
    let sphere_triangles = mesh.triangles.len() - 8;
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let rays = (0..21_000).map(|i| {
        let origin = match i % 3 {
            0 => Vector3::new(
                rng.random_range(-3.0..3.0),
                rng.random_range(-3.0..3.0),
                0.0,
            ),
            1 => {
                let t = rng.random_range(0..sphere_triangles);
                let (b1, b2) = (rng.random_range(0.0..0.5), rng.random_range(0.0..0.5));
                mesh.interpolate(t, b1, b2).point
            }
            _ => Vector3::from_fn(|r, _| {
                rng.random_range(if r == 2 { -0.5..3.0 } else { -3.0..3.0 })
            }),
        };
        (origin, random_direction(&mut rng, i))
    });
    let (hits, misses) = agree_with_brute_force(&mesh, rays.collect::<Vec<_>>().into_iter());
    assert!(hits > 5000 && misses > 5000, "{hits} hits, {misses} misses");
}

/// Random triangles of every size in a 10 m box, overlapping, with slivers, zero-area ones
/// (coincident and collinear vertices) and exact duplicates: leaves hold several triangles,
/// boxes overlap, and the hierarchy still finds the reference's first hit.
fn triangle_soup(rng: &mut impl Rng, count: usize) -> ShadedMesh {
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    for i in 0..count {
        let centre = Vector3::from_fn(|_, _| rng.random_range(-5.0..5.0));
        let size = 10f64.powf(rng.random_range(-3.0..0.5));
        let mut corner = || centre + Vector3::from_fn(|_, _| rng.random_range(-size..size));
        let (p0, p1) = (corner(), corner());
        let p2 = match i % 10 {
            0 => p0,                         // coincident vertices
            1 => p0 + (p1 - p0) * 0.375,     // collinear
            2 => p1 + Vector3::repeat(1e-7), // a sliver
            _ => corner(),
        };
        let n = positions.len() as u32;
        positions.extend([p0, p1, p2]);
        triangles.push([n, n + 1, n + 2]);
        if i % 50 == 0 {
            triangles.push([n, n + 1, n + 2]); // an exact duplicate
        }
    }
    mesh_of(positions, triangles)
}

#[test]
fn queries_agree_with_brute_force_on_a_triangle_soup() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
    let mesh = triangle_soup(&mut rng, 3000);
    let accel = Accelerator::new(&mesh, 10.0);
    let leaves: Vec<usize> = (accel.nodes.iter())
        .map(Node::count)
        .filter(|&c| c > 0)
        .collect();
    assert_eq!(leaves.iter().sum::<usize>(), mesh.triangles.len());
    assert!(leaves.iter().all(|&c| c <= 4));
    let several = leaves.iter().filter(|&&c| c >= 2).count();
    assert!(
        several * 4 > leaves.len(),
        "{several} of {} leaves hold ≥ 2",
        leaves.len()
    );
    let rays: Vec<_> = (0..20_000)
        .map(|i| {
            let origin = if i % 4 == 0 {
                // On a triangle's vertex or inside a triangle.
                let t = mesh.triangles[rng.random_range(0..mesh.triangles.len())];
                mesh.positions[t[0] as usize]
            } else {
                Vector3::from_fn(|_, _| rng.random_range(-7.0..7.0))
            };
            (origin, random_direction(&mut rng, i))
        })
        .collect();
    let (hits, misses) = agree_with_brute_force(&mesh, rays.into_iter());
    assert!(hits > 5000 && misses > 1000, "{hits} hits, {misses} misses");
}

/// Every node's box holds the f64 vertices of every triangle below it (bounds rounded outward),
/// and the leaves cover each triangle once.
#[test]
fn boxes_hold_their_triangles() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    let mesh = triangle_soup(&mut rng, 2000);
    let accel = Accelerator::new(&mesh, 10.0);
    let mut seen = vec![0; mesh.triangles.len()];
    fn check(accel: &Accelerator, at: usize, seen: &mut [u32]) -> (usize, usize) {
        let node = &accel.nodes[at];
        let (first, end) = if node.count() > 0 {
            (node.link as usize, node.link as usize + node.count())
        } else {
            let (first, _) = check(accel, at + 1, seen);
            let (_, end) = check(accel, at + node.link as usize, seen);
            (first, end)
        };
        for slot in first..end {
            let t = accel.order[slot] as usize;
            for v in accel.mesh.triangles[t] {
                let p = accel.mesh.positions[v as usize];
                for a in 0..3 {
                    assert!(f64::from(node.lo[a]) < p[a] && p[a] < f64::from(node.hi[a]));
                }
            }
            if node.count() > 0 {
                seen[t] += 1;
            }
        }
        (first, end)
    }
    assert_eq!(check(&accel, 0, &mut seen), (0, mesh.triangles.len()));
    assert!(seen.iter().all(|&s| s == 1));
}

/// Degenerate meshes build without panicking and answer: no triangles; many triangles on one
/// point or one centroid (the heuristic cannot split them: median splits keep leaves ≤ 4).
#[test]
fn degenerate_meshes_build_and_answer() {
    let empty = mesh_of(Vec::new(), Vec::new());
    let accel = Accelerator::new(&empty, 1.0);
    assert!(accel
        .closest_hit(&Vector3::zeros(), &Vector3::z())
        .is_none());
    assert!(!accel.occluded(&Vector3::zeros(), &Vector3::z()));
    assert!(accel.bounding_sphere().is_none());

    let point = mesh_of(vec![Vector3::new(1.0, 2.0, 3.0)], vec![[0, 0, 0]; 1000]);
    let accel = Accelerator::new(&point, 1.0);
    assert!(accel.nodes.iter().all(|n| n.count() <= 4));
    let towards = Vector3::new(1.0, 2.0, 3.0).normalize();
    assert!(accel.closest_hit(&Vector3::zeros(), &towards).is_none());

    // 1000 copies of one triangle: same centroid, all hit at the same point.
    let square = square();
    let copies = mesh_of(square.positions.clone(), vec![[0, 1, 2]; 1000]);
    let accel = Accelerator::new(&copies, 1.0);
    assert!(accel.nodes.iter().all(|n| n.count() <= 4));
    let down = -Vector3::z();
    let hit = accel
        .closest_hit(&Vector3::new(0.5, -0.5, 1.0), &down)
        .unwrap();
    assert!((hit.point - Vector3::new(0.5, -0.5, 0.0)).norm() < 1e-15);
    assert!(accel.occluded(&Vector3::new(0.5, -0.5, 1.0), &down));
    // On the triangle itself, along and off its plane.
    let on = Vector3::new(0.5, -0.5, 0.0);
    assert!(accel.closest_hit(&on, &Vector3::x()).is_none());
    assert_eq!(accel.closest_hit(&on, &down).unwrap().point, on);
}
