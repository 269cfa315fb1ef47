//! The shipped car scene: its mesh is what the generator writes, and it renders to plausible
//! LWIR polarimetric images.

use crate::common;

use irpol::app::render::render_scene;
use irpol::optics::Band;
use irpol::progress::Silent;
use irpol::render::{render, BACKGROUND};
use irpol::scene::car::sedan;
use irpol::scene::load_scene;
use irpol::scene::obj::parse_obj;
use irpol::thermal_scene::{scene_at, solve_scene};
use std::path::Path;

/// `scenes/car.obj` must be the generator's output (regenerate with IRPOL_WRITE_CAR=1).
#[test]
fn shipped_car_mesh_is_the_generated_one() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/car.obj");
    if std::env::var_os("IRPOL_WRITE_CAR").is_some() {
        irpol::scene::car::write_car_obj(&path).unwrap();
    }
    let shipped = parse_obj(&std::fs::read_to_string(&path).unwrap()).unwrap();
    let generated = sedan();
    assert_eq!(shipped.parts, generated.parts);
    assert_eq!(shipped.faces.len(), generated.faces.len());
    assert_eq!(shipped.positions.len(), generated.positions.len());
    for (a, b) in shipped.positions.iter().zip(&generated.positions) {
        assert!((a - b).norm() < 1e-5);
    }
}

/// Mean S0 of the pixels that see `part` of the car.
fn part_mean(scene: &irpol::scene::Scene, image: &irpol::render::StokesImage, part: &str) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (s, &surface) in image.stokes.iter().zip(&image.surface) {
        if surface != BACKGROUND && scene.surfaces[surface as usize].part == part {
            sum += s[0];
            n += 1;
        }
    }
    assert!(n > 20, "{part}: {n} pixels");
    sum / n as f64
}

#[test]
fn car_renders_with_warm_hood_and_cool_glass() {
    let dir = tempfile::tempdir().unwrap();
    let path = common::car_scene(dir.path(), 320, 240, "pixel");
    let out = dir.path().join("out");
    let summary = render_scene(&path, &out, &Silent).unwrap();
    for file in &summary.files {
        assert!(out.join(file).is_file(), "{file}");
    }
    if let Some(keep) = std::env::var_os("IRPOL_KEEP_RENDER") {
        let _ = std::fs::remove_dir_all(&keep);
        std::fs::rename(&out, keep).unwrap();
    }
    let scene = load_scene(&path).unwrap();
    let image = render(&scene, &Silent).unwrap().image;
    let band = Band::lwir();
    let t = |part: &str| {
        band.brightness_temperature(part_mean(&scene, &image, part))
            .unwrap()
    };
    let (hood, body, glass, ground) = (t("hood"), t("body"), t("side_windows"), t("ground"));
    // Apparent temperatures sit below the true ones (ε < 1, cold sky reflected) but keep order.
    assert!(hood > 310.0 && hood < 320.0, "hood {hood}");
    // Body pixels next to the hood share its seam vertices (averaged to 305 K).
    assert!(body > 283.0 && body < 295.0, "body {body}");
    assert!(glass < body, "glass {glass} vs body {body}");
    assert!(ground > 283.0 && ground < 288.0, "ground {ground}");
    assert!(summary.pixels.per_part["car/hood"] > 500);
}

#[test]
fn gouraud_car_is_close_to_per_pixel() {
    let dir = tempfile::tempdir().unwrap();
    let mean_s0 = |shading: &str| {
        let path = common::car_scene(&dir.path().join(shading), 160, 120, shading);
        let scene = load_scene(&path).unwrap();
        let image = render(&scene, &Silent).unwrap().image;
        ["hood", "body", "windshield", "ground"].map(|p| part_mean(&scene, &image, p))
    };
    let (pixel, gouraud) = (mean_s0("pixel"), mean_s0("gouraud"));
    for (p, g) in pixel.iter().zip(&gouraud) {
        assert!((p - g).abs() < 0.01 * p, "{p} vs {g}");
    }
}

#[test]
fn shipped_scene_renders_with_the_shipped_library() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load_scene(&root.join("scenes/car.toml")).unwrap();
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(
        names,
        vec![
            "paper_paint",
            "rough_paint",
            "silicate_glass",
            "anodized_panel",
            "smooth_glass",
            "asphalt"
        ]
    );
    assert_eq!((scene.camera.width, scene.camera.height), (640, 480));
}

/// Median DoLP of the pixels that see any of `parts`.
fn median_dolp(
    scene: &irpol::scene::Scene,
    image: &irpol::render::StokesImage,
    parts: &[&str],
) -> f64 {
    let mut dolp: Vec<f64> = image
        .stokes
        .iter()
        .zip(&image.surface)
        .filter(|(_, &s)| {
            s != BACKGROUND && parts.contains(&scene.surfaces[s as usize].part.as_str())
        })
        .map(|(s, _)| s[1].hypot(s[2]) / s[0])
        .collect();
    assert!(dolp.len() > 100, "{parts:?}: {} pixels", dolp.len());
    dolp.sort_by(f64::total_cmp);
    dolp[dolp.len() / 2]
}

/// The day scene's LWIR materials polarize as field measurements of painted cars (2–7 %) and
/// roads (above 1 %) report: median DoLP at 11:30 UTC, the sun 65° high (docs/materials.md).
#[test]
fn the_day_cars_paint_and_asphalt_polarize_as_measured_in_the_field() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load_scene(&root.join("scenes/car_day.toml")).unwrap();
    let noon_s = 41400.0;
    let solution = solve_scene(&scene, &[noon_s], &Silent).unwrap();
    let i = solution.times_s.iter().position(|&t| t == noon_s).unwrap();
    let at_noon = scene_at(&scene, &solution, i).unwrap();
    let image = render(&at_noon, &Silent).unwrap().image;
    let painted = ["body", "hood", "roof", "trunk", "pillars", "mirrors"];
    let (paint, asphalt) = (
        median_dolp(&at_noon, &image, &painted),
        median_dolp(&at_noon, &image, &["ground"]),
    );
    println!(
        "noon DoLP: painted panels {:.2} %, asphalt {:.2} %",
        100.0 * paint,
        100.0 * asphalt
    );
    assert!((0.02..0.07).contains(&paint), "painted panels {paint}");
    assert!(asphalt > 0.01, "asphalt {asphalt}");
}

#[test]
fn the_shipped_terrain_scene_is_the_car_in_a_five_million_triangle_field() {
    // scenes/car_terrain.toml is the scale benchmark (docs/verification.md, "Large scenes"):
    // the car's 15 942 faces plus a 1600 × 1600-cell terrain tile, its relief the asked rms.
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene = load_scene(&root.join("scenes/car_terrain.toml")).unwrap();
    assert_eq!(scene.mesh.triangles.len(), 15_942 + 2 * 1600 * 1600);
    assert_eq!((scene.camera.width, scene.camera.height), (1920, 1080));
    let field = scene
        .object_names
        .iter()
        .position(|n| n == "field")
        .unwrap();
    let heights: Vec<f64> = scene
        .mesh
        .triangles
        .iter()
        .zip(&scene.mesh.triangle_surface)
        .filter(|(_, &s)| scene.surfaces[s as usize].object == field)
        .map(|(t, _)| scene.mesh.positions[t[0] as usize].z + 0.6)
        .collect();
    let rms = (heights.iter().map(|h| h * h).sum::<f64>() / heights.len() as f64).sqrt();
    assert!((rms - 0.15).abs() < 0.002, "terrain rms {rms}");
}
