//! Thermal benchmark: the shipped car of `scenes/car_day.toml` (9694 thermal vertices,
//! 15 parts with their own stacks, a clear midsummer day in Munich) over 24 h, weather and sun
//! sampled every 60 s, shadow rays every 10 min, no spin-up. Each iteration is the whole run in
//! memory: sky view factors, shadows, the grouping of identical vertices and every solve (the
//! CSV, PLY and plot writing excluded).
//!
//! `batch_asphalt_soil`: one day (1440 steps of 60 s) of diurnal forcing with a sudden shadow on
//! 50 mm asphalt over 0.5 m soil (61 nodes), 8 vertices marched together by the batched BDF2
//! solver, and one of them by the adaptive solver for the ratio (divide by 1440 × 8 resp. 1440
//! for the time per vertex-step). `cargo bench --bench thermal -- batch` runs only these.

use criterion::{criterion_group, criterion_main, Criterion};
use irpol::progress::Silent;
use irpol::scene::load_scene;
use irpol::thermal::{
    Back, BatchForcing, BatchSolver, BatchState, Forcing, FrontForcing, Layer, LayerMaterial,
    LayerStack, Resolution, Solver, SolverControl, ThermalState, BATCH_MAX_SUBSTEP_S, LANES,
};
use irpol::thermal_scene::solve_scene;
use std::f64::consts::PI;
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

/// Lane `l` at t (s): a 0…800 W/m² half-sine from 06:00 to 18:00 (scaled per lane), cut to 10 %
/// from 10:00 + 20 min × l for 90 min; long-wave 270 W/m²; h = 10; air 285–300 K.
fn diurnal(t: f64, l: usize) -> Forcing {
    let day = (t - 6.0 * 3600.0) / (12.0 * 3600.0);
    let sun = if (0.0..=1.0).contains(&day) {
        800.0 * (PI * day).sin()
    } else {
        0.0
    };
    let from = 36_000.0 + 1200.0 * l as f64;
    let shade = if t > from && t <= from + 5400.0 {
        0.1
    } else {
        1.0
    };
    Forcing {
        front: FrontForcing {
            absorbed_w_m2: sun * shade * (1.0 - 0.08 * l as f64),
            longwave_in_w_m2: 270.0,
            emissivity: 0.9,
            h_w_m2k: 10.0,
            air_k: 292.5 - 7.5 * (2.0 * PI * (t - 5.0 * 3600.0) / 86_400.0).cos(),
        },
        back: Back::Fixed(288.0),
        internal_w_m2: 0.0,
    }
}

fn batch(c: &mut Criterion) {
    let grid = LayerStack::new(vec![
        Layer::new(LayerMaterial::new("asphalt", 0.75, 2300.0, 920.0), 0.05),
        Layer::new(LayerMaterial::new("soil", 1.0, 1600.0, 1000.0), 0.5),
    ])
    .unwrap()
    .discretise(&Resolution::default())
    .unwrap();
    let samples: Vec<[Forcing; LANES]> = (0..=1440)
        .map(|i| std::array::from_fn(|l| diurnal(i as f64 * 60.0, l)))
        .collect();
    let packed: Vec<BatchForcing> = samples
        .iter()
        .map(|f| BatchForcing {
            absorbed_w_m2: std::array::from_fn(|l| f[l].front.absorbed_w_m2),
            longwave_in_w_m2: std::array::from_fn(|l| f[l].front.longwave_in_w_m2),
            emissivity: 0.9,
            h_w_m2k: 10.0,
            air_k: f[0].front.air_k,
            back: Back::Fixed(288.0),
            internal_w_m2: 0.0,
        })
        .collect();
    let mut group = c.benchmark_group("batch_asphalt_soil");
    group.sample_size(10);
    group.bench_function("1440_steps_8_lanes", |b| {
        b.iter(|| {
            let mut solver = BatchSolver::new(grid.clone(), BATCH_MAX_SUBSTEP_S, 1e-9).unwrap();
            let mut state = BatchState::uniform(&grid, [288.0; LANES]).unwrap();
            for w in packed.windows(2) {
                solver.step(&mut state, 60.0, &w[0], &w[1]).unwrap();
            }
            state.surface_k()
        })
    });
    group.bench_function("1440_steps_adaptive_1_vertex", |b| {
        b.iter(|| {
            let mut solver = Solver::new(grid.clone(), SolverControl::default()).unwrap();
            let mut state = ThermalState::uniform(&grid, 288.0).unwrap();
            for w in samples.windows(2) {
                solver.step(&mut state, 60.0, &w[0][0], &w[1][0]).unwrap();
            }
            state.surface_k()
        })
    });
    group.finish();
}

criterion_group!(benches, car_day, batch);
criterion_main!(benches);
