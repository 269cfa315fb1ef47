//! What `irpol render` writes and how the sensor side behaves: float TIFFs and the EXR hold the
//! rendered values, the channels are consistent, previews and summary are complete; per-vertex
//! PLY temperatures are interpolated perspective-correctly; the atmosphere and the NETD noise
//! follow docs/design.md §1.5 and are reproducible.

use crate::common;

use common::*;
use irpol::app::render::render_scene;
use irpol::optics::{Band, RefractiveIndex};
use irpol::output::Channel;
use irpol::pbrdf::{HemisphereQuadrature, Pbrdf, Shadowing, SlopeDistribution};
use irpol::progress::Silent;
use irpol::render::{render, BACKGROUND};
use irpol::scene::load_scene;
use std::io::Cursor;

fn read_tiff(path: &std::path::Path) -> (u32, u32, Vec<f32>) {
    let mut decoder =
        tiff::decoder::Decoder::new(Cursor::new(std::fs::read(path).unwrap())).unwrap();
    let (w, h) = decoder.dimensions().unwrap();
    match decoder.read_image().unwrap() {
        tiff::decoder::DecodingResult::F32(data) => (w, h, data),
        _ => panic!("{} is not a 32-bit float TIFF", path.display()),
    }
}

#[test]
fn files_hold_the_rendered_channels() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{}{}{}{}",
        camera_toml(48).replace("[48, 48]", "[64, 48]"),
        AUTUMN_ENVIRONMENT,
        material_toml(0.1, 1.8, 1.2, 0.2, 0.0),
        sphere_toml(3, 300.0),
    );
    let path = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    let summary = render_scene(&path, &out, &Silent).unwrap();
    let image = render(&load_scene(&path).unwrap(), &Silent).unwrap().image;

    let mut stacks = Vec::new();
    for channel in Channel::ALL {
        let (w, h, data) = read_tiff(&out.join(format!("{}.tif", channel.name())));
        assert_eq!((w, h), (64, 48));
        assert_eq!(data, image.channel(channel), "{}", channel.name());
        stacks.push(data);
    }
    // Channel identities (docs/design.md §1.6): I0 + I90 = I45 + I135 = S0, I0 − I90 = S1, DoLP, AoP.
    for i in 0..64 * 48 {
        let pixel: Vec<f64> = stacks.iter().map(|channel| channel[i] as f64).collect();
        let [s0, s1, s2, s3, dolp, aop, i0, i45, i90, i135] = pixel[..] else {
            unreachable!("ten channels")
        };
        // A lone convex sphere in an unpolarized environment: no circular polarization.
        assert!(s3.abs() < 1e-9 * s0);
        assert!((i0 + i90 - s0).abs() < 1e-5 * s0 && (i45 + i135 - s0).abs() < 1e-5 * s0);
        assert!((i0 - i90 - s1).abs() < 1e-4 && (i45 - i135 - s2).abs() < 1e-4);
        assert!((dolp - s1.hypot(s2) / s0).abs() < 1e-6);
        assert!(
            aop > -std::f64::consts::FRAC_PI_2 - 1e-6 && aop <= std::f64::consts::FRAC_PI_2 + 1e-6
        );
    }

    use exr::prelude::{ReadChannels, ReadLayers};
    let exr = exr::prelude::read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(out.join("stokes.exr"))
        .unwrap();
    let mut names: Vec<String> = exr
        .layer_data
        .channel_data
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    names.sort();
    let mut expected: Vec<String> = Channel::ALL.iter().map(|c| c.name().to_string()).collect();
    expected.sort();
    assert_eq!(names, expected);
    let s0 = exr
        .layer_data
        .channel_data
        .list
        .iter()
        .find(|c| c.name.to_string() == "S0")
        .unwrap();
    assert_eq!(
        s0.sample_data.values_as_f32().collect::<Vec<_>>(),
        stacks[0]
    );

    for png in [
        "S0.png",
        "S1.png",
        "S2.png",
        "DoLP.png",
        "AoP.png",
        "S3.png",
        "composite.png",
    ] {
        let decoded = image::load_from_memory(&std::fs::read(out.join(png)).unwrap()).unwrap();
        assert!(decoded.width() > 64 && decoded.height() > 48, "{png}");
    }
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(json["width"], 64);
    assert_eq!(json["pixels"]["total"], 64 * 48);
    let object = json["pixels"]["object"].as_u64().unwrap();
    assert_eq!(
        object as usize,
        image.surface.iter().filter(|&&s| s != BACKGROUND).count()
    );
    assert_eq!(json["pixels"]["per_part"]["ball/surface"], object);
    assert_eq!(json["channels"].as_array().unwrap().len(), 10);
    // A lone convex sphere: nothing occludes it, so the path integrator adds nothing and
    // reports no Monte Carlo error.
    assert_eq!(json["transport"]["open_world"], false);
    assert_eq!(json["transport"]["bounces"], 3);
    let s0_error = &json["channels"][0]["relative_standard_error"];
    assert_eq!(s0_error["mean"].as_f64(), Some(0.0));
    let (_, _, stderr) = read_tiff(&out.join("stderr_S0.tif"));
    assert!(stderr.iter().all(|&e| e == 0.0));
    let t = &json["apparent_temperature_k"];
    assert!(t["min"].as_f64().unwrap() < t["mean"].as_f64().unwrap());
    assert!(t["max"].as_f64().unwrap() < 300.0 && t["min"].as_f64().unwrap() > 270.0);
    // 10 channel TIFFs, stderr_S0.tif, 6 ground-truth TIFFs, the EXR, 6 previews (S3 with
    // transport), the composite and the summary.
    assert_eq!(summary.files.len(), 26);
    assert!(json["timings_s"]["total"].as_f64().unwrap() > 0.0);
}

#[test]
fn ply_vertex_temperatures_are_interpolated_in_perspective() {
    // A 2 m square facing the camera at y = 0, 280 K on its left edge and 320 K on its right,
    // in a 0 K environment: S0 = ε0(θ) L_bb(T(x)) with T linear in world x.
    let dir = tempfile::tempdir().unwrap();
    let ply = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n\
        property float z\nproperty float temperature\nelement face 1\n\
        property list uchar int vertex_indices\nend_header\n\
        -1 0 -1 280\n1 0 -1 320\n1 0 1 320\n-1 0 1 280\n4 0 3 2 1\n";
    std::fs::write(dir.path().join("square.ply"), ply).unwrap();
    let text = format!(
        "{}{}{}[[objects]]\nmesh = \"square.ply\"\nmaterial = \"m\"\nrotate_deg = [0.0, 0.0, 25.0]\n",
        camera_toml(96),
        uniform_environment_toml(0.0),
        material_toml(0.2, 2.5, 1.5, 0.1, 0.0),
    );
    let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
    let image = render(&scene, &Silent).unwrap().image;
    let pbrdf = Pbrdf::new(
        SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
        Shadowing::Smith,
        RefractiveIndex::new(1.5, 0.1),
        0.0,
    )
    .unwrap();
    let band = Band::lwir();
    let angle = 25f64.to_radians();
    let (axis, normal) = (
        nalgebra::Vector3::new(angle.cos(), angle.sin(), 0.0),
        nalgebra::Vector3::new(-angle.sin(), angle.cos(), 0.0),
    );
    let mut checked = 0;
    for (i, &s) in image.surface.iter().enumerate() {
        if s == BACKGROUND {
            continue;
        }
        let d = scene
            .camera
            .ray_direction((i % 96) as f64 + 0.5, (i / 96) as f64 + 0.5);
        let o = scene.camera.position;
        let p = o + d * (-o.dot(&normal) / d.dot(&normal));
        let temperature = 300.0 + 20.0 * p.dot(&axis);
        let cos_theta = normal.dot(&-d).abs();
        let e = pbrdf.emissivity(cos_theta.acos(), &HemisphereQuadrature::default());
        let expected = e[0] * band.radiance(temperature);
        let got = image.stokes[i][0];
        assert!(
            (got - expected).abs() < 1e-3 * expected,
            "pixel {i}: {got} vs {expected}"
        );
        checked += 1;
    }
    assert!(checked > 1500, "{checked}");
}

#[test]
fn atmosphere_blends_toward_path_radiance_with_range() {
    // Black, cold plate in a 0 K world seen through a 300 K atmosphere: S0 = (1 − τ) L_bb(300 K).
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{}{}[atmosphere]\nextinction_per_km = 100.0\ntemperature_k = 300.0\n{}\
         [[objects]]\nshape = {{ kind = \"plane\", size = [6.0, 6.0], divisions = [3, 3] }}\n\
         material = \"m\"\ntemperature_k = 0.0\nrotate_deg = [-70.0, 0.0, 0.0]\n",
        camera_toml(64),
        uniform_environment_toml(0.0),
        material_toml(0.2, 2.5, 1.5, 0.1, 0.0),
    );
    let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
    let image = render(&scene, &Silent).unwrap().image;
    let path = Band::lwir().radiance(300.0);
    // The plate's +z normal turned −70° about x.
    let normal = nalgebra::Vector3::new(0.0, 70f64.to_radians().sin(), 70f64.to_radians().cos());
    let mut ranges = Vec::new();
    for (i, &s) in image.surface.iter().enumerate() {
        if s == BACKGROUND {
            continue;
        }
        let d = scene
            .camera
            .ray_direction((i % 64) as f64 + 0.5, (i / 64) as f64 + 0.5);
        let o = scene.camera.position;
        let range = -o.dot(&normal) / d.dot(&normal);
        let expected = (1.0 - (-0.1 * range).exp()) * path;
        assert!(
            (image.stokes[i][0] - expected).abs() < 1e-5 * expected,
            "pixel {i}"
        );
        assert!(image.stokes[i][1].abs() < 1e-9 && image.stokes[i][2].abs() < 1e-9);
        ranges.push(range);
    }
    let spread = ranges.iter().cloned().fold(0.0, f64::max)
        - ranges.iter().cloned().fold(f64::MAX, f64::min);
    assert!(
        spread > 1.0,
        "the plate should span a range of distances: {spread}"
    );
}

#[test]
fn netd_noise_has_its_stated_size_and_is_seeded() {
    let make = |seed: u64| {
        format!(
            "{}[sensor]\nnetd_mk = 100.0\nseed = {seed}\nnetd_reference_k = 300.0\n{}{}{}",
            camera_toml(96),
            uniform_environment_toml(300.0),
            material_toml(0.2, 2.5, 1.5, 0.1, 0.0),
            sphere_toml(2, 300.0),
        )
    };
    let dir = tempfile::tempdir().unwrap();
    let run = |seed: u64| {
        render(
            &load_scene(&write_scene(dir.path(), &make(seed))).unwrap(),
            &Silent,
        )
        .unwrap()
        .image
    };
    let (a, b, c) = (run(7), run(7), run(8));
    assert_eq!(a.stokes, b.stokes);
    assert_ne!(a.stokes, c.stokes);
    // Isothermal: every pixel is L_bb(300 K) plus noise; σ(S0) = σ_I = ½ NETD dL/dT.
    let band = Band::lwir();
    let (l, sigma) = (
        band.radiance(300.0),
        0.5 * 0.1 * band.radiance_derivative(300.0),
    );
    let n = a.stokes.len() as f64;
    let mean = a.stokes.iter().map(|s| s[0]).sum::<f64>() / n;
    let std = (a.stokes.iter().map(|s| (s[0] - mean).powi(2)).sum::<f64>() / n).sqrt();
    let std1 = (a.stokes.iter().map(|s| s[1] * s[1]).sum::<f64>() / n).sqrt();
    assert!((mean - l).abs() < 4.0 * sigma / n.sqrt());
    assert!((std / sigma - 1.0).abs() < 0.05, "{std} vs {sigma}");
    assert!((std1 / (sigma * 2f64.sqrt()) - 1.0).abs() < 0.05);
}

fn read_tiff_with_description(path: &std::path::Path) -> (tiff::decoder::DecodingResult, String) {
    let mut decoder =
        tiff::decoder::Decoder::new(Cursor::new(std::fs::read(path).unwrap())).unwrap();
    let description = decoder
        .get_tag_ascii_string(tiff::tags::Tag::ImageDescription)
        .unwrap();
    (decoder.read_image().unwrap(), description)
}

/// Ground truth: a unit sphere 4 m in front of the camera. The centre pixel
/// sees the sphere's nearest point: depth 3 m, normal toward the camera, the typed temperature,
/// IDs 1; the apparent temperature is the exact brightness temperature of S0; the background has
/// zeros and IDs 0; every TIFF names the camera's intrinsics in its ImageDescription.
#[test]
fn ground_truth_channels_describe_the_visible_point() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{}{}{}{}",
        camera_toml(49),
        AUTUMN_ENVIRONMENT,
        material_toml(0.1, 1.8, 1.2, 0.2, 0.0),
        sphere_toml(4, 305.0),
    );
    let path = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    render_scene(&path, &out, &Silent).unwrap();
    let centre = 24 * 49 + 24;
    let float = |name: &str| match read_tiff_with_description(&out.join(name)) {
        (tiff::decoder::DecodingResult::F32(data), description) => (data, description),
        _ => panic!("{name} is not float"),
    };
    let id = |name: &str| match read_tiff_with_description(&out.join(name)).0 {
        tiff::decoder::DecodingResult::U32(data) => data,
        _ => panic!("{name} is not u32"),
    };
    let (depth, description) = float("depth.tif");
    // The tessellated sphere's nearest point is within its chord sag of 3 m.
    assert!((depth[centre] - 3.0).abs() < 2e-3, "{}", depth[centre]);
    assert_eq!(depth[0], 0.0);
    let (normal, _) = float("normal.tif");
    let n = &normal[3 * centre..3 * centre + 3];
    assert!(
        n[1] < -0.999 && n[0].abs() < 0.03 && n[2].abs() < 0.03,
        "{n:?}"
    );
    let (temperature, _) = float("surface_temperature.tif");
    assert!((temperature[centre] - 305.0).abs() < 1e-4 && temperature[0] == 0.0);
    assert_eq!(
        (id("object_id.tif")[centre], id("part_id.tif")[centre]),
        (1, 1)
    );
    assert_eq!((id("object_id.tif")[0], id("part_id.tif")[0]), (0, 0));
    let (apparent, _) = float("apparent_temperature.tif");
    let (_, _, s0) = read_tiff(&out.join("S0.tif"));
    let band = Band::lwir();
    for i in [centre, 0, 10 * 49 + 30] {
        let exact = band.brightness_temperature(s0[i] as f64).unwrap();
        assert!(
            (apparent[i] as f64 - exact).abs() < 1e-3,
            "{} vs {exact}",
            apparent[i]
        );
    }
    let metadata: serde_json::Value = serde_json::from_str(&description).unwrap();
    let fy = metadata["camera"]["fy_px"].as_f64().unwrap();
    assert!((fy - 24.5 / 18f64.to_radians().tan()).abs() < 1e-9, "{fy}");
    assert_eq!(
        metadata["unit"],
        "m along the optical axis (0 = background)"
    );
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["ids"]["parts"]["1"], "ball/surface");
    assert_eq!(summary["camera"]["forward"][1], 1.0);
}

/// With noise, I0…I135 are the recorded polarizer images (S0…S2 are re-estimated
/// from them, so the identities hold to f32 rounding), and with `dofp = true` the raw mosaic holds
/// each pixel's own orientation (pattern 90/45 over 135/0) and the demosaicked S0 follows the
/// full-resolution S0 inside smooth regions.
#[test]
fn polarizer_images_are_the_recorded_ones_and_the_dofp_mosaic_samples_them() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        "{}{}{}{}",
        camera_toml(40),
        AUTUMN_ENVIRONMENT,
        material_toml(0.1, 1.8, 1.2, 0.2, 0.0),
        sphere_toml(4, 305.0),
    )
    .replace(
        "[environment]",
        "[sensor]\nnetd_mk = 50.0\nseed = 3\ndofp = true\n\n[environment]",
    );
    let path = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    render_scene(&path, &out, &Silent).unwrap();
    let read = |name: &str| read_tiff(&out.join(name)).2;
    let (s0, s1, s2) = (read("S0.tif"), read("S1.tif"), read("S2.tif"));
    let i: Vec<Vec<f32>> = ["I0.tif", "I45.tif", "I90.tif", "I135.tif"]
        .iter()
        .map(|n| read(n))
        .collect();
    let mut redundancy = 0.0f64;
    for p in 0..40 * 40 {
        let sum = 0.5 * (i[0][p] + i[1][p] + i[2][p] + i[3][p]);
        assert!((s0[p] - sum).abs() < 1e-4 * s0[p].abs().max(1.0));
        assert!((s1[p] - (i[0][p] - i[2][p])).abs() < 1e-4);
        assert!((s2[p] - (i[1][p] - i[3][p])).abs() < 1e-4);
        // I0 + I90 − I45 − I135 is pure noise in recorded images (zero if re-derived from S).
        redundancy += f64::from(i[0][p] + i[2][p] - i[1][p] - i[3][p]).powi(2);
    }
    assert!(
        redundancy > 0.0,
        "the polarizer images were re-derived from the Stokes images"
    );
    let raw = read("dofp_mosaic.tif");
    let expected = [[2, 1], [3, 0]];
    for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1), (17, 22), (20, 20)] {
        let k = expected[y % 2][x % 2];
        assert_eq!(raw[y * 40 + x], i[k][y * 40 + x], "({x},{y})");
    }
    let dofp_s0 = read("dofp_S0.tif");
    let centre = 20 * 40 + 20;
    assert!((dofp_s0[centre] / s0[centre] - 1.0).abs() < 0.01);
    assert_eq!(read("dofp_DoLP.tif").len(), 1600);
}
