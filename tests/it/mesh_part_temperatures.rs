//! A mesh part's typed temperature is the temperature it is drawn at, up to its edges: vertices
//! a part shares with other parts are split per part, each copy at its own part's temperature
//! (the paper's §4 averaged them, so a box's top at 315 K beside 300 K sides rendered at ~310 K
//! near its edges, with no word of it).

use crate::common;

use common::{material_toml, uniform_environment_toml, write_scene};
use irpol::progress::Silent;
use irpol::render::render;
use irpol::scene::load_scene;

/// A unit cube whose faces share their corner vertices across three groups: top, bottom, sides.
const BOX_OBJ: &str = "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n\
v -0.5 -0.5 1\nv 0.5 -0.5 1\nv 0.5 0.5 1\nv -0.5 0.5 1\n\
g top\nf 5 6 7\nf 5 7 8\n\
g bottom\nf 1 3 2\nf 1 4 3\n\
g sides\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

#[test]
fn a_box_top_keeps_its_typed_temperature_at_shared_vertices() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("box.obj"), BOX_OBJ).unwrap();
    let text = format!(
        "[camera]\nposition = [2.5, -2.5, 3.0]\nlook_at = [0.0, 0.0, 0.5]\nup = [0.0, 0.0, 1.0]\n\
         fov_deg = 40.0\nresolution = [48, 48]\n\n{}\n{}\n\
         [[objects]]\nname = \"box\"\nmesh = \"box.obj\"\nmaterial = \"m\"\ntemperature_k = 300.0\n\
         [objects.parts.top]\ntemperature_k = 315.0\n",
        uniform_environment_toml(290.0),
        material_toml(0.2, 2.0, 1.5, 0.1, 0.0),
    );
    let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
    let part_of = |s: u32| scene.surfaces[s as usize].part.as_str();
    // Every shading vertex of the top is at 315 K, every one of the sides at 300 K.
    for (triangle, &surface) in scene
        .mesh
        .triangles
        .iter()
        .zip(&scene.mesh.triangle_surface)
    {
        let expected = if part_of(surface) == "top" {
            315.0
        } else {
            300.0
        };
        for &v in triangle {
            assert_eq!(
                scene.mesh.temperatures[v as usize],
                expected,
                "{}",
                part_of(surface)
            );
        }
    }
    // And the render's ground truth draws the top at 315 K in every pixel it covers.
    let image = render(&scene, &Silent).unwrap().image;
    let top: Vec<f32> = image
        .surface
        .iter()
        .zip(&image.truth)
        .filter(|(&s, _)| s != irpol::render::BACKGROUND && part_of(s) == "top")
        .map(|(_, t)| t.temperature_k)
        .collect();
    assert!(top.len() > 100, "the top covers {} pixels", top.len());
    assert!(
        top.iter().all(|&t| t == 315.0),
        "{:?}",
        top.iter().fold(f32::INFINITY, |a, &b| a.min(b))
    );
}
