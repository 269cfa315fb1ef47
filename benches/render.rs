//! Rendering benchmarks: the shipped car scene with the shipped material library (`fits/`),
//! per-pixel shading, at 640×480 and 1920×1080. Each iteration is a whole render in
//! memory: per-material tables, rasterization, shading, noise (file writing excluded).

#[path = "../tests/common/mod.rs"]
mod common;

use criterion::{criterion_group, criterion_main, Criterion};
use irpol::progress::Silent;
use irpol::render::render;
use irpol::scene::load_scene;

fn car(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let mut group = c.benchmark_group("render_car_pixel");
    group.sample_size(10);
    for (w, h) in [(640, 480), (1920, 1080)] {
        let scene_dir = dir.path().join(format!("{w}x{h}"));
        let path = common::car_scene_with_shipped_fits(&scene_dir, w, h, "pixel");
        let scene = load_scene(&path).unwrap();
        group.bench_function(format!("{w}x{h}"), |b| {
            b.iter(|| render(&scene, &Silent).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, car);
criterion_main!(benches);
