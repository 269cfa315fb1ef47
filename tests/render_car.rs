//! The shipped car scene: its mesh is what the generator writes, and it renders to plausible
//! LWIR polarimetric images.

mod common;

use irpol::render::render_scene;
use irpol::scene::car::sedan;
use irpol::scene::obj::parse_obj;
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

#[test]
fn car_renders_with_warm_hood_and_cool_glass() {
    let dir = tempfile::tempdir().unwrap();
    let scene = common::car_scene(dir.path(), 320, 240, "pixel");
    let out = dir.path().join("out");
    let summary = render_scene(&scene, &out, false).unwrap();
    if let Some(keep) = std::env::var_os("IRPOL_KEEP_RENDER") {
        let _ = std::fs::remove_dir_all(&keep);
        std::fs::rename(&out, keep).unwrap();
    }
    println!("{}", serde_json::to_string_pretty(&summary).unwrap());
    for file in [
        "S0.tif",
        "DoLP.tif",
        "stokes.exr",
        "S0.png",
        "AoP.png",
        "composite.png",
        "summary.json",
    ] {
        assert!(out.join(file).is_file(), "{file}");
    }
}
