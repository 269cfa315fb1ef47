use super::collapse::LANES;
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
        .flat_map(|n| n.count)
        .filter(|&c| c > 0)
        .map(|c| c as usize)
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

/// What a walk of the wide tree saw: how many times each node and each triangle was reached,
/// and the most nodes on a path.
struct Seen {
    nodes: Vec<u32>,
    triangles: Vec<u32>,
    depth: usize,
}

/// Walks the wide tree from node `at` (at `level`, the root at 1): checks that every used
/// lane's box holds the f64 vertices of every triangle below it (bounds rounded outward),
/// counts what it reaches in `seen`, and returns the leaf-order slots below (first, end), which
/// must be contiguous.
fn check_subtree(accel: &Accelerator, at: usize, level: usize, seen: &mut Seen) -> (usize, usize) {
    seen.nodes[at] += 1;
    seen.depth = seen.depth.max(level);
    let node = &accel.nodes[at];
    let used = (0..LANES).filter(|&l| node.used(l));
    let mut ranges = Vec::new();
    for lane in used {
        let (child, count) = (node.child[lane] as usize, node.count[lane] as usize);
        let (first, end) = if count > 0 {
            for slot in child..child + count {
                seen.triangles[accel.order[slot] as usize] += 1;
            }
            (child, child + count)
        } else {
            check_subtree(accel, child, level + 1, seen)
        };
        for slot in first..end {
            let t = accel.order[slot] as usize;
            for v in accel.mesh.triangles[t] {
                let p = accel.mesh.positions[v as usize];
                for a in 0..3 {
                    let (lo, hi) = (node.bounds[0][a][lane], node.bounds[1][a][lane]);
                    assert!(
                        f64::from(lo) < p[a] && p[a] < f64::from(hi),
                        "node {at} lane {lane}"
                    );
                }
            }
        }
        ranges.push((first, end));
    }
    // In slot order by construction; sorted here so that the check does not depend on it.
    ranges.sort_unstable();
    for pair in ranges.windows(2) {
        assert_eq!(
            pair[0].1, pair[1].0,
            "node {at}: slots {ranges:?} not contiguous"
        );
    }
    let (first, last) = (ranges.first(), ranges.last());
    (first.expect("a node with no lane").0, last.unwrap().1)
}

/// The collapsed tree is a tree over every triangle: every lane's box holds the f64 vertices of
/// every triangle below it, each node is reached once from the root, each triangle lies in
/// exactly one leaf, leaves hold at most four, and a node has four lanes unless all its lanes
/// are leaves (nothing left to open).
#[test]
fn the_wide_tree_holds_every_triangle_once_inside_its_boxes() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
    for mesh in [triangle_soup(&mut rng, 2000), sphere_over_plane()] {
        let accel = Accelerator::new(&mesh, 10.0);
        let mut seen = Seen {
            nodes: vec![0; accel.nodes.len()],
            triangles: vec![0; mesh.triangles.len()],
            depth: 0,
        };
        let range = check_subtree(&accel, 0, 1, &mut seen);
        assert_eq!(range, (0, mesh.triangles.len()));
        assert!(seen.nodes.iter().all(|&n| n == 1));
        assert!(seen.triangles.iter().all(|&n| n == 1));
        // The traversal's stack is sized from the depth.
        assert_eq!(seen.depth, accel.depth);
        assert!(3 * accel.depth <= SHORT_STACK);
        assert!(accel.nodes.iter().all(|n| n.count.iter().all(|&c| c <= 4)));
        // A lane left unused means no interior lane was left to open.
        for node in &accel.nodes {
            let used = (0..LANES).filter(|&l| node.used(l));
            if used.clone().count() < LANES {
                assert!(used.clone().all(|l| node.count[l] > 0), "{node:?}");
            }
        }
    }
    // A single triangle: a binary tree of one leaf, a root with one lane.
    let mesh = square();
    let one = mesh_of(mesh.positions.clone(), vec![[0, 1, 2]]);
    let accel = Accelerator::new(&one, 1.0);
    assert_eq!(accel.nodes.len(), 1);
    assert_eq!(accel.nodes[0].count, [1, 0, 0, 0]);
    let (nodes, triangles) = (vec![0], vec![0]);
    let mut seen = Seen {
        nodes,
        triangles,
        depth: 0,
    };
    assert_eq!(check_subtree(&accel, 0, 1, &mut seen), (0, 1));
    assert_eq!((seen.nodes[0], seen.triangles[0], accel.depth), (1, 1, 1));
}

/// 5 000 random triangles (sizes from 1 mm to 3 m, crossing one another) and 20 000 rays from
/// inside and around them: `closest_hit` finds the brute-force loop's triangle at the same
/// distance, and `occluded` agrees, on every ray (random triangles make ties improbable).
#[test]
fn queries_agree_with_brute_force_on_a_large_random_mesh() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(23);
    let mut positions = Vec::new();
    for _ in 0..5000 {
        let centre = Vector3::from_fn(|_, _| rng.random_range(-5.0..5.0));
        let size = 10f64.powf(rng.random_range(-3.0..0.5));
        for _ in 0..3 {
            positions.push(centre + Vector3::from_fn(|_, _| rng.random_range(-size..size)));
        }
    }
    let triangles = (0..5000u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let mesh = mesh_of(positions, triangles);
    let accel = Accelerator::new(&mesh, 10.0);
    let (mut hits, mut misses) = (0, 0);
    for i in 0..20_000 {
        let origin = Vector3::from_fn(|_, _| rng.random_range(-7.0..7.0));
        let ray = Ray::new(&origin, &random_direction(&mut rng, i));
        let mut expected = None;
        for t in 0..mesh.triangles.len() {
            let t_max = expected.map_or(f64::INFINITY, |(_, distance)| distance);
            if let Some((distance, _, _)) = Triangle::new(&mesh, t).intersect(&ray, t_max) {
                expected = Some((t, distance));
            }
        }
        let ours = accel.closest(&ray);
        match (expected, ours) {
            (Some((t, distance)), Some((slot, ours, _, _))) => {
                hits += 1;
                assert_eq!(accel.order[slot] as usize, t, "ray {i}");
                assert!(
                    (ours - distance).abs() <= 1e-12,
                    "ray {i}: {ours} {distance}"
                );
            }
            (None, None) => misses += 1,
            _ => panic!("ray {i}: {ours:?}, expected {expected:?}"),
        }
        let occluded = accel.occluded(&ray.origin, &ray.direction);
        assert_eq!(occluded, expected.is_some(), "ray {i}");
    }
    assert!(hits > 5000 && misses > 1000, "{hits} hits, {misses} misses");
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
    assert!(accel.nodes.iter().all(|n| n.count.iter().all(|&c| c <= 4)));
    let towards = Vector3::new(1.0, 2.0, 3.0).normalize();
    assert!(accel.closest_hit(&Vector3::zeros(), &towards).is_none());

    // 1000 copies of one triangle: same centroid, all hit at the same point.
    let square = square();
    let copies = mesh_of(square.positions.clone(), vec![[0, 1, 2]; 1000]);
    let accel = Accelerator::new(&copies, 1.0);
    assert!(accel.nodes.iter().all(|n| n.count.iter().all(|&c| c <= 4)));
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
