//! Physics acceptance tests of the renderer on small procedural scenes (docs/design.md §1.5–1.6):
//! an isothermal enclosure shows no contrast and no polarization; emission alone is polarized
//! along the projected normal with DoLP = |ε1|/ε0; reflection alone across it; Gouraud and
//! per-pixel shading agree on a finely tessellated sphere.

use crate::common;

use common::*;
use irpol::optics::{Band, RefractiveIndex};
use irpol::pbrdf::{HemisphereQuadrature, Pbrdf, Shadowing, SlopeDistribution};
use irpol::progress::Silent;
use irpol::render::{render, StokesImage, BACKGROUND};
use irpol::scene::{load_scene, Scene};
use nalgebra::Vector3;
use std::f64::consts::{FRAC_PI_2, PI};

fn render_text(text: &str) -> (Scene, StokesImage) {
    let dir = tempfile::tempdir().unwrap();
    let scene = load_scene(&write_scene(dir.path(), text)).unwrap();
    let image = render(&scene, &Silent).unwrap().image;
    (scene, image)
}

/// For each object pixel of the unit sphere: (pixel index, exact unit normal, unit ω_r) from the
/// ray through the pixel centre (the icosphere is inscribed, so its pixels hit the sphere too).
fn sphere_pixels(scene: &Scene, image: &StokesImage) -> Vec<(usize, Vector3<f64>, Vector3<f64>)> {
    let camera = &scene.camera;
    let mut out = Vec::new();
    for (i, &s) in image.surface.iter().enumerate() {
        if s == BACKGROUND {
            continue;
        }
        let (x, y) = (
            (i % image.width) as f64 + 0.5,
            (i / image.width) as f64 + 0.5,
        );
        let d = camera.ray_direction(x, y);
        let o = camera.position;
        let b = o.dot(&d);
        let disc = b * b - (o.norm_squared() - 1.0);
        assert!(disc >= 0.0, "pixel {i} hits the mesh but not the sphere");
        let p = o + d * (-b - disc.sqrt());
        out.push((i, p.normalize(), -d));
    }
    out
}

/// Angle (radians, in [0, π/2]) between two orientations given mod π.
fn orientation_gap(a: f64, b: f64) -> f64 {
    let d = (a - b).rem_euclid(PI);
    d.min(PI - d)
}

/// Orientation of a world vector projected on the image plane at ray ω_r: angle from image
/// right, counter-clockwise (docs/design.md §1.6 pixel frame).
fn projected_angle(scene: &Scene, v: &Vector3<f64>, w_r: &Vector3<f64>) -> f64 {
    let right = scene.camera.right;
    let x_pix = (right - w_r * right.dot(w_r)).normalize();
    let y_pix = w_r.cross(&x_pix);
    v.dot(&y_pix).atan2(v.dot(&x_pix))
}

fn dolp_aop(s: [f64; 4]) -> (f64, f64) {
    (s[1].hypot(s[2]) / s[0], 0.5 * s[2].atan2(s[1]))
}

#[test]
fn isothermal_enclosure_has_no_contrast_and_no_polarization() {
    let band = Band::lwir();
    let l = band.radiance(300.0);
    for shading in ["pixel", "gouraud"] {
        // A rough sphere, a glossy tilted plate and a volume scatterer (internal facets and the
        // polarized subsurface term of §1.10) in a 300 K enclosure, through a 300 K atmosphere:
        // everything must read L_bb(300 K), unpolarized (docs/design.md §1.5).
        let text = format!(
            "{}{}[render]\nshading = \"{shading}\"\n[atmosphere]\nextinction_per_km = 50.0\n\
             temperature_k = 300.0\n{}{}\
             [materials.glass]\ndistribution = \"gaussian\"\nsigma = 0.03\nn = 2.2\nk = 0.1\nshadowing = \"smith\"\n\
             [[objects]]\nname = \"plate\"\nshape = {{ kind = \"plane\", size = [3.0, 3.0], divisions = [4, 4] }}\n\
             material = \"glass\"\ntemperature_k = 300.0\ntranslate = [0.0, 1.5, -0.5]\nrotate_deg = [-60.0, 20.0, 0.0]\n\
             [materials.ptfe]\ndistribution = \"cauchy\"\nsigma = 0.87\nq = 2.42\nn = 1.23\nk = 0.075\n\
             shadowing = \"smith\"\nfacet = \"internal\"\nrho_s = 0.9\nd = 0.3\nd_c = -0.2\n\
             [[objects]]\nname = \"volume\"\nshape = {{ kind = \"plane\", size = [2.0, 2.0], divisions = [4, 4] }}\n\
             material = \"ptfe\"\ntemperature_k = 300.0\ntranslate = [-1.5, -1.0, 0.0]\nrotate_deg = [50.0, -30.0, 0.0]\n",
            camera_toml(96),
            uniform_environment_toml(300.0),
            material_toml(0.3, 2.5, 1.5, 0.2, 0.05),
            sphere_toml(3, 300.0),
        );
        let (scene, image) = render_text(&text);
        let mut count = 0;
        for (s, &surface) in image.stokes.iter().zip(&image.surface) {
            if surface == BACKGROUND {
                continue;
            }
            count += 1;
            assert!((s[0] - l).abs() < 1e-4 * l, "{shading}: S0 {} vs {l}", s[0]);
            assert!(s[1].hypot(s[2]) / s[0] < 1e-4, "{shading}: DoLP of {s:?}");
        }
        println!("isothermal {shading}: {count} object pixels");
        assert!(count > 2000, "{count}");
        // The volume scatterer (the third object) is in view.
        let volume_pixels = image
            .surface
            .iter()
            .filter(|&&s| s != BACKGROUND && scene.surfaces[s as usize].object == 2)
            .count();
        assert!(volume_pixels > 500, "{volume_pixels}");
    }
}

#[test]
fn emission_alone_is_polarized_along_the_projected_normal() {
    let (sigma, q, n, k) = (0.2, 2.5, 1.5, 0.1);
    let text = format!(
        "{}{}{}{}",
        camera_toml(128),
        uniform_environment_toml(0.0),
        material_toml(sigma, q, n, k, 0.0),
        sphere_toml(5, 300.0),
    );
    let (scene, image) = render_text(&text);
    let pbrdf = Pbrdf::new(
        SlopeDistribution::Cauchy { sigma, q },
        Shadowing::Smith,
        RefractiveIndex::new(n, k),
        0.0,
    )
    .unwrap();
    let quadrature = HemisphereQuadrature::default();
    let (mut checked, mut worst_dolp, mut worst_aop) = (0, 0.0f64, 0.0f64);
    for (i, normal, w_r) in sphere_pixels(&scene, &image) {
        let theta = normal.dot(&w_r).clamp(-1.0, 1.0).acos();
        if theta > 80f64.to_radians() {
            continue; // silhouette pixels: the tessellation's normal error dominates
        }
        let e = pbrdf.emissivity(theta, &quadrature);
        let (dolp, aop) = dolp_aop(image.stokes[i]);
        worst_dolp = worst_dolp.max((dolp - e[1].abs() / e[0]).abs());
        if dolp > 2e-3 {
            worst_aop = worst_aop.max(orientation_gap(aop, projected_angle(&scene, &normal, &w_r)));
        }
        checked += 1;
    }
    println!(
        "emission: {checked} pixels, worst ΔDoLP {worst_dolp:.2e}, worst ΔAoP {:.3}°",
        worst_aop.to_degrees()
    );
    assert!(checked > 5000, "{checked}");
    assert!(worst_dolp < 1e-3, "DoLP off by {worst_dolp}");
    assert!(
        worst_aop < 1f64.to_radians(),
        "AoP off by {}°",
        worst_aop.to_degrees()
    );
}

#[test]
fn reflection_alone_is_polarized_across_the_projected_normal() {
    // Object at 0 K in a uniform 300 K enclosure: what leaves is reflected light, s-polarized.
    let text = format!(
        "{}{}{}{}",
        camera_toml(128),
        uniform_environment_toml(300.0),
        material_toml(0.1, 2.0, 1.5, 0.1, 0.0),
        sphere_toml(5, 0.0),
    );
    let (scene, image) = render_text(&text);
    let (mut checked, mut worst) = (0, 0.0f64);
    for (i, normal, w_r) in sphere_pixels(&scene, &image) {
        let (dolp, aop) = dolp_aop(image.stokes[i]);
        if dolp < 2e-3 || normal.dot(&w_r) < 0.2 {
            continue;
        }
        let across = projected_angle(&scene, &normal, &w_r) + FRAC_PI_2;
        let gap = orientation_gap(aop, across);
        worst = worst.max(gap);
        assert!(gap < 1f64.to_radians(), "pixel {i}: AoP {aop} vs {across}");
        checked += 1;
    }
    println!(
        "reflection: {checked} pixels, worst ΔAoP {:.3}°",
        worst.to_degrees()
    );
    assert!(checked > 3000, "{checked}");
}

#[test]
fn gouraud_and_per_pixel_shading_agree_on_a_fine_sphere() {
    let make = |shading: &str| {
        format!(
            "{}{}[render]\nshading = \"{shading}\"\n{}{}",
            camera_toml(128),
            AUTUMN_ENVIRONMENT,
            material_toml(0.1, 1.8, 1.2, 0.2, 0.0),
            sphere_toml(5, 300.0),
        )
    };
    let (_, pixel) = render_text(&make("pixel"));
    let (_, gouraud) = render_text(&make("gouraud"));
    let mut worst = 0.0f64;
    let mut count = 0;
    for ((p, g), &surface) in pixel.stokes.iter().zip(&gouraud.stokes).zip(&pixel.surface) {
        if surface == BACKGROUND {
            continue;
        }
        worst = worst.max((p[0] - g[0]).abs() / p[0]);
        count += 1;
    }
    println!("gouraud vs pixel: {count} pixels, worst relative ΔS0 {worst:.2e}");
    assert!(count > 5000);
    assert!(worst < 5e-3, "S0 differs by {worst}");
}

#[test]
fn a_flat_terrain_renders_as_the_plane_and_a_rough_one_as_a_rough_surface() {
    // rms height 0: the terrain is the plane, vertex for vertex, with the plane's normal, so
    // its render is bit for bit the plane's. With relief its image differs, and only where
    // the ground is (the sky pixels stay the sky's).
    let scene = |shape: &str| {
        format!(
            "{}{}{}[[objects]]\nname = \"ground\"\nshape = {{ {shape} }}\nmaterial = \"m\"\n\
             temperature_k = 295.0\ntranslate = [0.0, 0.0, -1.0]\n",
            camera_toml(48),
            AUTUMN_ENVIRONMENT,
            material_toml(0.3, 2.0, 1.5, 0.1, 0.05),
        )
    };
    let grid = "size = [12.0, 12.0], divisions = [24, 24]";
    let (_, plane) = render_text(&scene(&format!("kind = \"plane\", {grid}")));
    let terrain = |rms: f64| {
        render_text(&scene(&format!(
            "kind = \"terrain\", {grid}, rms_height_m = {rms}, correlation_length_m = 2.0, seed = 4"
        )))
        .1
    };
    let flat = terrain(0.0);
    assert_eq!(flat.stokes, plane.stokes);
    assert!(plane.surface.iter().filter(|&&s| s != BACKGROUND).count() > 200);
    let rough = terrain(0.3);
    let changed = (0..plane.stokes.len())
        .filter(|&p| rough.stokes[p] != plane.stokes[p])
        .count();
    assert!(changed > 200, "{changed} pixels changed");
}
