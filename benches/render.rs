//! Rendering benchmarks: the shipped car scene with the shipped material library (`fits/`),
//! per-pixel shading, at 640×480 and 1920×1080, with occlusion, inter-reflection and the sun (the
//! scene as shipped, its windows the spectral silicate glass band-integrated over 8–14 µm, docs/design.md
//! §1.9) and in the open world (`open_world = true`, the paper's model); and at 640×480 with
//! grey windows (`smooth_glass`, one wavelength), the cost of the spectral ones. Each iteration is
//! a whole render in memory: per-material tables, ray-tracing hierarchy, rasterization, shading,
//! noise (file writing excluded).

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
        for open_world in [false, true] {
            let name = if open_world {
                "open_world"
            } else {
                "sun_occlusion"
            };
            let scene_dir = dir.path().join(format!("{w}x{h}_{name}"));
            let path = common::car_scene_with_shipped_fits(&scene_dir, w, h, "pixel");
            if open_world {
                let text = std::fs::read_to_string(&path).unwrap();
                let text = text.replace("samples = 12 ", "open_world = true\nsamples = 12 ");
                assert!(text.contains("open_world = true"), "the car scene changed");
                std::fs::write(&path, text).unwrap();
            }
            let scene = load_scene(&path).unwrap();
            group.bench_function(format!("{name}_{w}x{h}"), |b| {
                b.iter(|| render(&scene, &Silent).unwrap())
            });
        }
    }
    let scene_dir = dir.path().join("640x480_grey_windows");
    let path = common::car_scene_with_shipped_fits(&scene_dir, 640, 480, "pixel");
    let text = std::fs::read_to_string(&path).unwrap();
    // The windows (windshield, rear and side windows) at 284 K; the headlights are smooth_glass.
    let windows = "material = \"silicate_glass\"\ntemperature_k = 284.0";
    assert_eq!(text.matches(windows).count(), 3);
    let text = text.replace(
        windows,
        "material = \"smooth_glass\"\ntemperature_k = 284.0",
    );
    std::fs::write(&path, text).unwrap();
    let scene = load_scene(&path).unwrap();
    group.bench_function("sun_occlusion_grey_windows_640x480", |b| {
        b.iter(|| render(&scene, &Silent).unwrap())
    });
    group.finish();
}

criterion_group!(benches, car);
criterion_main!(benches);
