//! The split first bounce (`[render] first_bounce_samples`, docs/design.md §1.7): the visible
//! point's correction from k lobe samples per path, one continuing, the others ending at their
//! hit's open-world value. Its weights (1 and −1 on the continuing sample's full and open-world
//! parts, 1/k on each open-world part) must add up to the unsplit estimator's expectation.

use crate::common;

use common::*;
use irpol::render::StokesImage;

/// Mean and standard error (from the pixels' own errors) of Stokes component `j` over `pixels`.
fn mean_and_error(image: &StokesImage, pixels: &[usize], j: usize) -> (f64, f64) {
    let n = pixels.len() as f64;
    let mean = pixels.iter().map(|&i| image.stokes[i][j]).sum::<f64>() / n;
    let variance: f64 = pixels
        .iter()
        .map(|&i| image.standard_error[i][j].powi(2))
        .sum();
    (mean, variance.sqrt() / n)
}

/// Inside a closed isothermal cavity the camera reads the wall's blackbody radiance exactly; the
/// correction there is all hits, and its open-world and deeper parts are both large (a wrong
/// weight on either moves S0 by ≥ 0.4 %: the deeper part is the wall's reflectance squared
/// times L_bb(350 K) − L_env). Sobol' points (64 paths, split 4) and multi-jittered ones
/// (12 paths, split 3).
#[test]
fn a_split_first_bounce_keeps_a_closed_cavity_at_its_blackbody_radiance() {
    let dir = tempfile::tempdir().unwrap();
    for (samples, split) in [(64, 4), (12, 3)] {
        let text = closed_cavity_toml(&format!(
            "bounces = 8\nsamples = {samples}\nfirst_bounce_samples = {split}"
        ));
        let (scene, image) = render_scene_text(dir.path(), &text);
        let l350 = scene.sensor.band.radiance(350.0);
        let pixels: Vec<usize> = (0..image.stokes.len()).collect();
        let (s0, _) = mean_and_error(&image, &pixels, 0);
        assert!(
            (s0 / l350 - 1.0).abs() < 1e-3,
            "{samples} paths, split {split}: S0 {s0} vs {l350}"
        );
        for j in 1..4 {
            let (mean, error) = mean_and_error(&image, &pixels, j);
            assert!(
                mean.abs() < 4.0 * error + 1e-12 * l350,
                "S{j} {mean} ± {error}"
            );
        }
    }
}

/// A glossy metal sphere over a glossy ground (the Mitsuba comparison's materials, 32 × 24):
/// split 4 and no split agree on the sphere's and the ground's means within their standard
/// errors in every Stokes component (same expectation), and the split lowers the sphere's noise,
/// whose first bounce crosses the ground's far edge.
#[test]
fn a_split_first_bounce_has_the_unsplit_mean_and_less_noise() {
    let dir = tempfile::tempdir().unwrap();
    let text = |split: u32, seed: u32| {
        format!(
            "[camera]\nposition = [4.4, -5.2, 2.3]\nlook_at = [0.0, 0.0, 0.75]\nup = [0.0, 0.0, 1.0]\n\
             fov_deg = 30.0\nresolution = [32, 24]\n\
             [environment]\nair_temperature_k = 1.0\n\
             sky = {{ model = \"table\", elevation_deg = [0.0, 15.0, 90.0], radiance = [31.0, 21.0, 11.0] }}\n\
             ground = {{ temperature_k = 1.0, emissivity = 0.2 }}\n\
             [render]\nbounces = 4\nsamples = 64\nfirst_bounce_samples = {split}\nseed = {seed}\n\
             [materials.metal]\ndistribution = \"gaussian\"\nsigma = 0.15\nn = 3.0\nk = 20.0\n\
             rho_d = 0.0\nshadowing = \"smith\"\n\
             [materials.ground]\ndistribution = \"gaussian\"\nsigma = 0.2\nn = 1.5\nk = 0.1\n\
             rho_d = 0.0\nshadowing = \"smith\"\n\
             [[objects]]\nname = \"sphere\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 4 }}\n\
             material = \"metal\"\ntemperature_k = 1.0\ntranslate = [0.0, 0.0, 1.02]\n\
             [[objects]]\nname = \"ground\"\nshape = {{ kind = \"plane\", size = [12.0, 12.0], divisions = [1, 1] }}\n\
             material = \"ground\"\ntemperature_k = 1.0\n"
        )
    };
    let (scene, plain) = render_scene_text(dir.path(), &text(1, 1));
    let (_, split) = render_scene_text(dir.path(), &text(4, 2));
    let object_of = |i: usize| scene.surfaces[plain.surface[i] as usize].object;
    let visible = object_pixels(&plain);
    let sphere: Vec<usize> = visible
        .iter()
        .copied()
        .filter(|&i| object_of(i) == 0)
        .collect();
    let ground: Vec<usize> = visible
        .iter()
        .copied()
        .filter(|&i| object_of(i) == 1)
        .collect();
    assert!(sphere.len() > 50 && ground.len() > 50);
    for pixels in [&sphere, &ground] {
        for j in 0..4 {
            let (a, ea) = mean_and_error(&plain, pixels, j);
            let (b, eb) = mean_and_error(&split, pixels, j);
            let reference = mean_and_error(&plain, pixels, 0).0;
            assert!(
                (a - b).abs() < 4.0 * ea.hypot(eb) + 1e-9 * reference,
                "S{j}: {a} ± {ea} unsplit, {b} ± {eb} split"
            );
        }
    }
    let (_, noise_plain) = mean_and_error(&plain, &sphere, 0);
    let (_, noise_split) = mean_and_error(&split, &sphere, 0);
    assert!(
        noise_split < noise_plain / 1.3,
        "sphere S0 error {noise_split} split, {noise_plain} unsplit"
    );
}
