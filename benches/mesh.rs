//! Mesh scale: reading binary PLY files and building the ray-tracing hierarchy over millions of
//! triangles (docs/verification.md, Benchmarks).
//!
//! `ply_read`: `parse_ply` (what the scene loader calls on a `.ply` file) on grids written in
//! memory (`mesh_support::GridPly`: float x y z, nx ny nz and `temperature`, faces as
//! `property list uchar int vertex_indices`), little and big endian, of about 1 and 5 million
//! triangles, with the throughput in bytes of file; and, for comparison in the same run,
//! `parse_ply_through_parser`, the item-by-item parser path every file took before the direct
//! binary reader (at 1 million triangles only: at 5 million its per-item maps take several GB).
//! Required: ≥ 100 MB/s.
//!
//! `bvh_build`: `Accelerator::new` on a shaded procedural plane of about 1 and 5 million
//! triangles (the shading is done once, outside the timing). Peak memory of reading plus the
//! hierarchy is measured by `examples/mesh_memory.rs` under `/usr/bin/time -v`.

#[path = "../tests/it/mesh_support.rs"]
mod mesh_support;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use irpol::scene::mesh::{shade_mesh, ObjectShading, Transform};
use irpol::scene::ply::{parse_ply, parse_ply_through_parser};
use irpol::scene::procedural::plane;
use irpol::transport::accel::Accelerator;
use mesh_support::GridPly;
use std::time::Duration;

const MILLIONS: [usize; 2] = [1, 5];

fn ply_read(c: &mut Criterion) {
    let mut group = c.benchmark_group("ply_read");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(10));
    for millions in MILLIONS {
        for big_endian in [false, true] {
            let bytes = GridPly::with_triangles(millions * 1_000_000, big_endian).bytes();
            let order = if big_endian { "big" } else { "little" };
            group.throughput(Throughput::Bytes(bytes.len() as u64));
            group.bench_function(format!("direct_{order}_{millions}M"), |b| {
                b.iter(|| parse_ply(&bytes).unwrap())
            });
            if millions == 1 {
                group.bench_function(format!("parser_{order}_{millions}M"), |b| {
                    b.iter(|| parse_ply_through_parser(&bytes).unwrap())
                });
            }
        }
    }
    group.finish();
}

fn bvh_build(c: &mut Criterion) {
    let mut group = c.benchmark_group("bvh_build");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(20));
    for millions in MILLIONS {
        // 2·n² triangles.
        let cells = ((millions as f64 * 5e5).sqrt().ceil()) as u32;
        let raw = plane([100.0, 100.0], [cells, cells]);
        let setup = ObjectShading {
            transform: Transform::new(1.0, [0.0; 3], [0.0; 3]),
            crease_angle_deg: 30.0,
            part_temperature: &[Some(300.0)],
            part_surface: &[0],
        };
        let (shaded, _) = shade_mesh(&raw, &setup).unwrap();
        drop(raw);
        group.throughput(Throughput::Elements(shaded.triangles.len() as u64));
        group.bench_function(format!("plane_{millions}M"), |b| {
            b.iter(|| Accelerator::new(&shaded, 141.0))
        });
    }
    group.finish();
}

criterion_group!(benches, ply_read, bvh_build);
criterion_main!(benches);
