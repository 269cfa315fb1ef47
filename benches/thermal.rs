//! Thermal benchmark: the shipped car of `scenes/car_day.toml` (9694 thermal vertices,
//! 15 parts with their own stacks, a clear midsummer day in Munich) over 24 h, weather and sun
//! sampled every 60 s, shadow rays every 10 min, no spin-up. Each iteration is the whole run in
//! memory: sky view factors, shadows, the grouping of identical vertices and every solve (the
//! CSV, PLY and plot writing excluded).

use criterion::{criterion_group, criterion_main, Criterion};
use irpol::progress::Silent;
use irpol::scene::load_scene;
use irpol::thermal_scene::solve_scene;
use std::path::Path;

fn car_day(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(root.join("scenes/car.obj"), dir.path().join("car.obj")).unwrap();
    let text = std::fs::read_to_string(root.join("scenes/car_day.toml")).unwrap();
    let fits = root.join("fits");
    let text = text
        .replace(
            "material_library = \"../fits\"",
            &format!("material_library = {:?}", fits.display().to_string()),
        )
        .replace("spinup_days = 1", "spinup_days = 0");
    assert!(text.contains("spinup_days = 0") && text.contains("duration_h = 24"));
    let path = dir.path().join("car_day.toml");
    std::fs::write(&path, text).unwrap();
    let scene = load_scene(&path).unwrap();
    let mut group = c.benchmark_group("thermal_car_day");
    group.sample_size(10);
    group.bench_function("24h_60s_steps_10min_shadows", |b| {
        b.iter(|| solve_scene(&scene, &[], &Silent).unwrap())
    });
    group.finish();
}

criterion_group!(benches, car_day);
criterion_main!(benches);
