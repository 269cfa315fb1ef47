//! Rendering benchmarks: the shipped car scene with the shipped material library (`fits/`),
//! per-pixel shading, at 640×480 and 1920×1080, with occlusion, inter-reflection and the sun (the
//! scene as shipped) and in the open world (`open_world = true`, the paper's model); and at
//! 640×480 with the windows (windshield, rear and side windows) made of the spectral silicate
//! glass of measurements/README.md, band-integrated over 8–14 µm (DESIGN §1.9). Each iteration is
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
                let text = text.replace("samples = 16 ", "open_world = true\nsamples = 16 ");
                std::fs::write(&path, text).unwrap();
            }
            let scene = load_scene(&path).unwrap();
            group.bench_function(format!("{name}_{w}x{h}"), |b| {
                b.iter(|| render(&scene, &Silent).unwrap())
            });
        }
    }
    let scene_dir = dir.path().join("640x480_silicate_windows");
    let path = common::car_scene_with_shipped_fits(&scene_dir, 640, 480, "pixel");
    std::fs::write(scene_dir.join("fits/silicate_glass.toml"), SILICATE_GLASS).unwrap();
    let text = std::fs::read_to_string(&path).unwrap();
    // The windows are the smooth_glass parts at 284 K (the headlights, at 292 K, stay).
    let windows = "material = \"smooth_glass\"\ntemperature_k = 284.0";
    assert_eq!(text.matches(windows).count(), 3);
    let text = text.replace(
        windows,
        "material = \"silicate_glass\"\ntemperature_k = 284.0",
    );
    std::fs::write(&path, text).unwrap();
    let scene = load_scene(&path).unwrap();
    group.bench_function("sun_occlusion_silicate_windows_640x480", |b| {
        b.iter(|| render(&scene, &Silent).unwrap())
    });
    group.finish();
}

/// The silicate glass of measurements/README.md: Cauchy σ = 0.06, q = 2.8, Smith, ρ_d = 0, N
/// from one Lorentz oscillator at 9.3 µm at nine wavelengths across its reststrahlen band.
const SILICATE_GLASS: &str = "name = \"silicate_glass\"\ntool_version = \"bench\"\n\n[model]\n\
    distribution = \"cauchy\"\nsigma = 0.06\nq = 2.8\nshadowing = \"smith\"\n\
    wavelength_um = [8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0]\n\
    n = [0.517774, 0.588464, 1.36346, 2.87319, 2.62133, 2.30722, 2.08423, 1.96574, 1.87624]\n\
    k = [0.543731, 1.2793, 2.12223, 1.38554, 0.477271, 0.210027, 0.100204, 0.0596999, 0.0359674]\n\
    rho_d = 0.0\n";

criterion_group!(benches, car);
criterion_main!(benches);
