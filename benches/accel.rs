//! Ray queries (`transport::accel`, docs/verification.md, Benchmarks; the hierarchy's build is
//! `benches/mesh.rs`'s `bvh_build`).
//!
//! The scene is the Mitsuba comparison's: an icosphere of 20 480 triangles (radius 1, centre at
//! z = 1.02) over a 12 × 12 m plane of two triangles. `closest_hit` and `occluded` are timed for
//! secondary rays as the path tracer casts them: leaving the sphere's surface outward and the
//! plane upward (cosine-distributed about the normal, origins offset by the accelerator's
//! offset), 4096 fixed rays per iteration, throughput in rays.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use irpol::scene::mesh::ShadedMesh;
use irpol::scene::procedural::{icosphere, plane};
use irpol::transport::accel::Accelerator;
use nalgebra::Vector3;
use rand::{Rng, SeedableRng};

const RAYS: usize = 4096;
const CENTRE: Vector3<f64> = Vector3::new(0.0, 0.0, 1.02);

/// The sphere over the plane, with flat attributes (only the geometry matters here).
fn sphere_over_plane() -> ShadedMesh {
    let (sphere, ground) = (icosphere(1.0, 5), plane([12.0, 12.0], [1, 1]));
    let mut positions: Vec<Vector3<f64>> = sphere.positions.iter().map(|p| p + CENTRE).collect();
    let offset = positions.len() as u32;
    positions.extend(ground.positions.iter().copied());
    let mut triangles: Vec<[u32; 3]> = sphere.faces.iter().map(|f| f.vertices).collect();
    triangles.extend(ground.faces.iter().map(|f| f.vertices.map(|v| v + offset)));
    assert_eq!(triangles.len(), 20_482);
    ShadedMesh {
        normals: vec![Vector3::z(); positions.len()],
        temperatures: vec![300.0; positions.len()],
        triangle_surface: vec![0; triangles.len()],
        positions,
        triangles,
    }
}

/// A cosine-distributed unit direction about unit `normal`.
fn cosine_about(normal: &Vector3<f64>, rng: &mut impl Rng) -> Vector3<f64> {
    let helper = if normal.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = normal.cross(&helper).normalize();
    let v = normal.cross(&u);
    let (r, phi) = (
        rng.random::<f64>().sqrt(),
        std::f64::consts::TAU * rng.random::<f64>(),
    );
    let z = (1.0 - r * r).max(0.0).sqrt();
    (u * (r * phi.cos()) + v * (r * phi.sin()) + normal * z).normalize()
}

type Rays = Vec<(Vector3<f64>, Vector3<f64>)>;

/// Rays leaving the sphere (random points on its triangles, outward) and the plane (upward).
fn secondary_rays(mesh: &ShadedMesh, offset: f64) -> (Rays, Rays) {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let sphere_triangles = mesh.triangles.len() - 2;
    let from_sphere = (0..RAYS)
        .map(|_| {
            let t = rng.random_range(0..sphere_triangles);
            let (b1, b2) = (rng.random::<f64>(), rng.random::<f64>());
            let (b1, b2) = if b1 + b2 > 1.0 {
                (1.0 - b1, 1.0 - b2)
            } else {
                (b1, b2)
            };
            let point = mesh.interpolate(t, b1, b2).point;
            let normal = (point - CENTRE).normalize();
            (point + normal * offset, cosine_about(&normal, &mut rng))
        })
        .collect();
    let from_plane = (0..RAYS)
        .map(|_| {
            let (x, y) = (rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0));
            let origin = Vector3::new(x, y, offset);
            (origin, cosine_about(&Vector3::z(), &mut rng))
        })
        .collect();
    (from_sphere, from_plane)
}

fn queries(c: &mut Criterion) {
    let mesh = sphere_over_plane();
    let accel = Accelerator::new(&mesh, 12.0);
    let (from_sphere, from_plane) = secondary_rays(&mesh, accel.offset);
    let mut group = c.benchmark_group("accel");
    group.throughput(Throughput::Elements(RAYS as u64));
    for (name, rays) in [("sphere", &from_sphere), ("plane", &from_plane)] {
        group.bench_function(format!("closest_hit_{name}"), |b| {
            b.iter(|| {
                rays.iter()
                    .filter_map(|(o, d)| accel.closest_hit(o, d))
                    .map(|hit| hit.triangle)
                    .sum::<usize>()
            })
        });
        group.bench_function(format!("occluded_{name}"), |b| {
            b.iter(|| rays.iter().filter(|(o, d)| accel.occluded(o, d)).count())
        });
    }
    group.finish();
}

criterion_group!(benches, queries);
criterion_main!(benches);
