//! Horizon maps of a terrain (docs/design.md §1.8, **Exposure**; `transport::horizon`).
//!
//! `horizon_build`: `HorizonMap::new` on the heightfield of a 1600 × 1600-cell terrain tile
//! (1601² = 2.56 M grid points, 16 directions; the map holds 164 MB). The tile is synthesized
//! once, outside the timing.
//!
//! `horizon_query`: the sky rule of a vertex (288 directions) against the map, `horizon_tan` and
//! `blocks` per direction, over 1000 grid points; and `horizon_tan_from` (the march of points off
//! the grid) for the same directions from 1 m above 100 grid points.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use irpol::pbrdf::cosine_hemisphere_rule;
use irpol::scene::heightfield::Heightfield;
use irpol::scene::mesh::Transform;
use irpol::scene::procedural::terrain;
use irpol::scene::terrain::TerrainSpectrum;
use irpol::transport::horizon::HorizonMap;
use nalgebra::Vector3;
use std::hint::black_box;
use std::time::Duration;

/// The heightfield of a 400 m, 1600² cell tile with rms slopes ~0.2.
fn field() -> Heightfield {
    let (size, divisions) = ([400.0, 400.0], [1600, 1600]);
    let spectrum = TerrainSpectrum {
        rms_height_m: 1.5,
        correlation_length_m: 10.0,
        hurst: Some(0.5),
        seed: 1,
    };
    let raw = terrain(size, divisions, &spectrum);
    let transform = Transform::new(1.0, [0.0; 3], [0.0; 3]);
    Heightfield::of_terrain(&raw, size, divisions, [0.0; 3], &transform, 0).unwrap()
}

fn horizon(c: &mut Criterion) {
    let field = field();
    let mut group = c.benchmark_group("horizon_build");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(30));
    group.throughput(Throughput::Elements(field.heights_m.len() as u64));
    group.bench_function("terrain_1601x1601", |b| b.iter(|| HorizonMap::new(&field)));
    group.finish();

    let map = HorizonMap::new(&field);
    let rule: Vec<Vector3<f64>> = cosine_hemisphere_rule(12, 24)
        .into_iter()
        .map(|(d, _)| d)
        .collect();
    let points: Vec<usize> = (0..1000).map(|k| k * 2563 + 1700).collect();
    let mut group = c.benchmark_group("horizon_query");
    group.throughput(Throughput::Elements((points.len() * rule.len()) as u64));
    group.bench_function("blocks_288_directions", |b| {
        b.iter(|| {
            let mut blocked = 0usize;
            for &g in &points {
                blocked += rule.iter().filter(|d| map.blocks(g, d)).count();
            }
            black_box(blocked)
        })
    });
    group.throughput(Throughput::Elements((100 * rule.len()) as u64));
    group.bench_function("horizon_tan_from_288_directions", |b| {
        b.iter(|| {
            let mut sum = 0.0;
            for &g in &points[..100] {
                let p = field.point(g) + Vector3::z();
                sum += rule
                    .iter()
                    .map(|d| map.horizon_tan_from(&p, d))
                    .sum::<f64>();
            }
            black_box(sum)
        })
    });
    group.finish();
}

criterion_group!(benches, horizon);
criterion_main!(benches);
