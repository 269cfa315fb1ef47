//! Rendering benchmarks: the shipped car scene with the shipped material library (`fits/`),
//! per-pixel shading, at 640×480 and 1920×1080, with occlusion, inter-reflection and the sun (the
//! scene as shipped, its windows the spectral silicate glass band-integrated over 8–14 µm, docs/design.md
//! §1.9) and in the open world (`open_world = true`, the paper's model); and at 640×480 with
//! grey windows (`smooth_glass`, one wavelength), the cost of the spectral ones. Each iteration is
//! a whole render in memory: per-material tables, ray-tracing hierarchy, rasterization, shading,
//! noise (file writing excluded).

#[path = "../tests/it/common.rs"]
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

/// The 1080p car through the ideal camera and through a real one (f/1 optics with a 17 µm pixel,
/// FPN and 14-bit quantization, a DoFP array with ER 30, 1° orientation errors, 2 % crosstalk,
/// Newton demosaicking and calibration), measured in one run so their ratio is the camera's cost.
fn camera(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let mut group = c.benchmark_group("render_car_camera");
    group.sample_size(10);
    let path = common::car_scene_with_shipped_fits(dir.path(), 1920, 1080, "pixel");
    let ideal = std::fs::read_to_string(&path).unwrap();
    let camera = ideal.replace(
        "[environment]",
        "[sensor.optics]\nf_number = 1.0\npixel_pitch_um = 17.0\nfill_factor = 0.8\n\
         blur_sigma_px = 0.3\n\n[sensor.detector]\nfpn_gain_sigma = 0.01\nfpn_offset_mk = 20.0\n\
         bits = 14\n\n[sensor.dofp]\nextinction_ratio = 30.0\norientation_sigma_deg = 1.0\n\
         crosstalk = 0.02\ndemosaic = \"newton\"\n\n[environment]",
    );
    assert_ne!(camera, ideal, "the car scene changed");
    for (name, text) in [("ideal_1920x1080", ideal), ("camera_1920x1080", camera)] {
        let scene = irpol::scene::load_scene_text(&path, &text).unwrap();
        group.bench_function(name, |b| b.iter(|| render(&scene, &Silent).unwrap()));
    }
    group.finish();
}

criterion_group!(benches, car, camera);
criterion_main!(benches);
