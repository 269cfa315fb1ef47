//! Band rendering of spectral materials (docs/design.md §1.9): a material whose n, k, ρ_d are
//! tables over wavelength is integrated over the sensor band, S_j = ∫ R(λ) [∫ F_j0(λ) L_env,λ
//! cosθ_i dΩ_i + ε_j(λ) B_λ(T)] dλ, against grey materials, a dense wavelength integral and a
//! wavelength-by-wavelength render.

use crate::common;

use common::*;
use irpol::material::{Material, MaterialModel};
use irpol::pbrdf::HemisphereQuadrature;
use irpol::progress::Silent;
use irpol::render::{render, StokesImage, BACKGROUND};
use irpol::scene::{load_scene, Scene};
use irpol::transport::kernel::KernelQuadrature;
use irpol::transport::tables::{theta_coordinate, theta_grid, theta_of_coordinate, THETA_MAX};
use std::path::Path;

/// The silicate glass of measurements/README.md (one Lorentz oscillator at 9.3 µm, SCATMECH
/// truth): n, k at nine wavelengths across its reststrahlen band.
const SILICATE_UM: [f64; 9] = [8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0];
const SILICATE_N: [f64; 9] = [
    0.517774, 0.588464, 1.36346, 2.87319, 2.62133, 2.30722, 2.08423, 1.96574, 1.87624,
];
const SILICATE_K: [f64; 9] = [
    0.543731, 1.2793, 2.12223, 1.38554, 0.477271, 0.210027, 0.100204, 0.0596999, 0.0359674,
];

fn list(values: &[f64]) -> String {
    let items: Vec<String> = values.iter().map(|v| format!("{v:?}")).collect();
    format!("[{}]", items.join(", "))
}

/// A Cauchy (σ, q) Smith material file `dir/<name>.toml`: spectral when `wavelengths` has
/// several entries (n, k, ρ_d per wavelength), grey when it has one.
fn write_material(dir: &Path, name: &str, sigma: f64, q: f64, table: [&[f64]; 4]) {
    let [wavelengths, n, k, rho] = table;
    let value = |v: &[f64]| {
        if wavelengths.len() == 1 {
            format!("{:?}", v[0])
        } else {
            list(v)
        }
    };
    let text = format!(
        "name = \"{name}\"\ntool_version = \"test\"\n\n[model]\ndistribution = \"cauchy\"\n\
         sigma = {sigma:?}\nq = {q:?}\nshadowing = \"smith\"\nwavelength_um = {}\nn = {}\nk = {}\n\
         rho_d = {}\n",
        value(wavelengths),
        value(n),
        value(k),
        value(rho)
    );
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join(format!("{name}.toml")), text).unwrap();
}

fn write_silicate(dir: &Path, name: &str) {
    write_material(
        dir,
        name,
        0.06,
        2.8,
        [&SILICATE_UM, &SILICATE_N, &SILICATE_K, &[0.0; 9]],
    );
}

fn render_scene(dir: &Path, text: &str) -> (Scene, StokesImage) {
    let scene = load_scene(&write_scene(dir, text)).unwrap();
    let image = render(&scene, &Silent).unwrap().image;
    (scene, image)
}

/// A sphere resting on a plate, both of library material `material`, in the autumn sky with a
/// sun: occlusion, inter-reflection between the two and a glint.
fn sphere_on_plate(material: &str, render: &str) -> String {
    format!(
        "material_library = \"lib\"\n\
         [camera]\nposition = [3.5, -3.5, 2.2]\nlook_at = [0.0, 0.0, 0.6]\nup = [0.0, 0.0, 1.0]\n\
         fov_deg = 45.0\nresolution = [40, 40]\n\
         {AUTUMN_ENVIRONMENT}\
         [render]\nshading = \"pixel\"\n{render}\n\
         [sun]\nelevation_deg = 35.0\nazimuth_deg = 200.0\n\
         [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 4 }}\n\
         translate = [0.0, 0.0, 1.0]\nmaterial = \"{material}\"\ntemperature_k = 310.0\n\
         [[objects]]\nname = \"plate\"\nshape = {{ kind = \"plane\", size = [6.0, 6.0], divisions = [6, 6] }}\n\
         material = \"{material}\"\ntemperature_k = 295.0\n"
    )
}

/// Acceptance A: a spectral material whose n, k, ρ_d do not change with λ is band-integrated to
/// its grey image, in the open world and with occlusion, inter-reflection and the sun.
#[test]
fn a_constant_spectral_material_renders_as_its_grey_self() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    write_material(&lib, "grey", 0.12, 2.5, [&[10.0], &[1.7], &[0.3], &[0.04]]);
    let table = [7.0, 8.2, 9.5, 11.0, 12.5, 15.0];
    write_material(
        &lib,
        "flat",
        0.12,
        2.5,
        [&table, &[1.7; 6], &[0.3; 6], &[0.04; 6]],
    );
    for settings in ["open_world = true", "bounces = 2\nsamples = 8\nseed = 3"] {
        let (_, grey) = render_scene(dir.path(), &sphere_on_plate("grey", settings));
        let (scene, flat) = render_scene(dir.path(), &sphere_on_plate("flat", settings));
        assert!(scene.materials[0].optics.band().is_some());
        let mut corrected = 0;
        for (i, (a, b)) in grey.stokes.iter().zip(&flat.stokes).enumerate() {
            let scale = a[0].abs();
            for j in 0..4 {
                assert!(
                    (a[j] - b[j]).abs() <= 1e-12 * scale,
                    "{settings}: pixel {i} S{j}: grey {} vs spectral {}",
                    a[j],
                    b[j]
                );
            }
            corrected += (grey.standard_error[i][0] > 0.0) as usize;
        }
        if !settings.contains("open_world") {
            assert!(
                corrected > 100,
                "only {corrected} pixels see the other object"
            );
        }
    }
}

/// Sky and ground of zero radiance (the ground a blackbody at 1 K, 0 in 8–14 µm): only emission
/// is seen.
const BLACK_ENVIRONMENT: &str = "[environment]\nair_temperature_k = 1.0\n\
    sky = { model = \"table\", elevation_deg = [0.0, 90.0], radiance = [0.0, 0.0] }\n\
    ground = { temperature_k = 1.0, emissivity = 1.0 }\n";

/// B_λ(T), W·m⁻²·sr⁻¹·m⁻¹ at λ in µm, written out here independently of the library.
fn planck(lambda_um: f64, t: f64) -> f64 {
    let (h, c, k) = (6.626_070_15e-34, 299_792_458.0, 1.380_649e-23);
    let lambda = lambda_um * 1e-6;
    2.0 * h * c * c / lambda.powi(5) / (h * c / (lambda * k * t)).exp_m1()
}

/// Acceptance B: the emission of a silicate sphere at 300 K in a black environment against
/// ∫ R(λ) ε_j(λ, θ) B_λ(T) dλ on 2000 wavelength nodes (R = 1 over 8–14 µm), ε_j from the
/// `Pbrdf` of `SpectralModel::at(λ)` at each node. The reference takes ε on the renderer's
/// emission-angle grid, linear between its nodes (the angular interpolation is the grey
/// renderer's own and is not what is checked here), with the renderer's quadrature.
#[test]
fn silicate_emission_matches_a_dense_wavelength_integral() {
    let dir = tempfile::tempdir().unwrap();
    write_silicate(&dir.path().join("lib"), "silicate");
    let text = format!(
        "material_library = \"lib\"\n{}{BLACK_ENVIRONMENT}[render]\nshading = \"pixel\"\nopen_world = true\n\
         [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 5 }}\n\
         material = \"silicate\"\ntemperature_k = 300.0\n",
        camera_toml(48)
    );
    let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
    let rendered = render(&scene, &Silent).unwrap();
    let image = &rendered.image;
    let grid = theta_grid(&rendered.table_resolutions[0]);

    // Each object pixel's emission angle, as the renderer sees it: the shading normal (ground
    // truth) against the ray back to the camera.
    let mut pixels = Vec::new();
    for (i, truth) in image.truth.iter().enumerate() {
        if image.surface[i] == BACKGROUND {
            continue;
        }
        let (x, y) = ((i % 48) as f64 + 0.5, (i / 48) as f64 + 0.5);
        let toward_camera = -scene.camera.ray_direction(x, y);
        let normal = nalgebra::Vector3::from(truth.normal.map(f64::from)).normalize();
        let cos_theta = normal.dot(&toward_camera).max(THETA_MAX.cos());
        let (node, f) = grid.locate(theta_coordinate(cos_theta));
        pixels.push((i, node, f));
    }
    // Pixels between a few pairs of angle nodes (normal, ~35°, ~65°, ~80°, beyond 89°) keep the
    // reference to a few thousand emissivity integrals per wavelength.
    let last = grid.len() - 2;
    let chosen = [0, 15, 30, 45, last];
    pixels.retain(|&(_, node, _)| chosen.contains(&node));
    assert!(pixels.len() > 40, "{} pixels", pixels.len());
    let mut thetas: Vec<usize> = chosen.iter().flat_map(|&n| [n, n + 1]).collect();
    thetas.dedup();

    let material = Material::load(&dir.path().join("lib/silicate.toml")).unwrap();
    let MaterialModel::Spectral(model) = &material.model else {
        panic!("a spectral material")
    };
    let quadrature: HemisphereQuadrature = KernelQuadrature::default().hemisphere();
    let angles: Vec<f64> = thetas
        .iter()
        .map(|&i| theta_of_coordinate(grid.value(i)))
        .collect();
    // 2000 nodes: 250 Gauss–Legendre points on each of the table's eight pieces.
    let rule = gauss_legendre(250);
    let t = 300.0;
    let mut reference = vec![[0.0f64; 2]; thetas.len()];
    for pair in SILICATE_UM.windows(2) {
        let (a, b) = (pair[0], pair[1]);
        for &(x, w) in &rule {
            let lambda = a + 0.5 * (b - a) * (x + 1.0);
            let weight = 0.5 * (b - a) * 1e-6 * w * planck(lambda, t);
            let pbrdf = model.at(lambda).unwrap().pbrdf().unwrap();
            let e = pbrdf.emissivity_table(&angles, &quadrature);
            for (r, e) in reference.iter_mut().zip(&e) {
                r[0] += weight * e[0];
                r[1] += weight * e[1];
            }
        }
    }
    let mut worst: f64 = 0.0;
    for &(i, node, f) in &pixels {
        let at = |n: usize| reference[thetas.iter().position(|&m| m == n).unwrap()];
        let (a, b) = (at(node), at(node + 1));
        let expected = [a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])];
        let s = image.stokes[i];
        // S1 in the pixel frame: emission is polarized along the projected normal, so |S1, S2|
        // is the linear part |ε1| L.
        let linear = s[1].hypot(s[2]);
        let errors = [
            (s[0] - expected[0]).abs(),
            (linear - expected[1].abs()).abs(),
        ];
        worst = worst.max(errors[0].max(errors[1]) / expected[0]);
        assert!(
            errors[0] <= 1e-5 * expected[0] && errors[1] <= 1e-5 * expected[0],
            "pixel {i}: S0 {} vs {}, |S1,S2| {linear} vs {}",
            s[0],
            expected[0],
            expected[1].abs()
        );
    }
    eprintln!("silicate emission vs 2000 wavelength nodes: {worst:.2e} of S0 at worst");
}

/// Gauss–Legendre nodes and weights on [−1, 1] (Newton on the Legendre recurrence).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
            let mut derivative = 0.0;
            for _ in 0..100 {
                let (mut p0, mut p1) = (1.0, x);
                for k in 2..=n {
                    let k = k as f64;
                    (p0, p1) = (p1, ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k);
                }
                derivative = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / derivative;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * derivative * derivative))
        })
        .collect()
}

/// Acceptance C: a sensor band the material's table does not cover is refused when the scene
/// loads, in one line naming the scene file, the material and both ranges; nothing is written.
#[test]
fn a_band_beyond_the_table_is_refused_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    write_silicate(&dir.path().join("lib"), "silicate");
    let text = format!(
        "material_library = \"lib\"\n{}[sensor]\nband_um = [7.5, 14.0]\n{AUTUMN_ENVIRONMENT}\
         [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 2 }}\n\
         material = \"silicate\"\ntemperature_k = 300.0\n",
        camera_toml(16)
    );
    let scene = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    let (ok, stdout, stderr) = irpol(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok, "{stdout}");
    let message = stderr.trim();
    assert_eq!(message.lines().count(), 1, "{message}");
    for part in [
        scene.to_str().unwrap(),
        "'silicate'",
        "8–14 µm",
        "7.5–14 µm",
    ] {
        assert!(message.contains(part), "{part} missing from: {message}");
    }
    assert!(!out.exists());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(leftovers.len(), 2, "{leftovers:?}"); // scene.toml and lib
}

/// `summary.json` says which materials were band-integrated and on how many wavelength nodes.
#[test]
fn the_summary_names_band_integrated_materials() {
    let dir = tempfile::tempdir().unwrap();
    write_silicate(&dir.path().join("lib"), "silicate");
    let text = format!(
        "material_library = \"lib\"\n{}{AUTUMN_ENVIRONMENT}{}\
         [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 2 }}\n\
         material = \"silicate\"\ntemperature_k = 300.0\n\
         [[objects]]\nname = \"pebble\"\nshape = {{ kind = \"sphere\", radius = 0.2, subdivisions = 1 }}\n\
         translate = [1.2, 0.0, 0.0]\nmaterial = \"m\"\ntemperature_k = 300.0\n",
        camera_toml(16),
        material_toml(0.2, 2.0, 1.5, 0.1, 0.0)
    );
    let scene = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    let materials = summary["materials"].as_array().unwrap();
    let band_nodes = |name: &str| {
        materials
            .iter()
            .find(|m| m["name"] == name)
            .map(|m| m["band_nodes"].clone())
            .unwrap()
    };
    // Nine table nodes, eight pieces (12.5–14 µm in two): 9 × 4 Gauss–Legendre nodes.
    assert_eq!(band_nodes("silicate"), 36);
    assert!(band_nodes("m").is_null());
}

/// The Monte Carlo parts' spectral approximation (docs/design.md §1.7, §1.9; docs/spectral.md "Band rendering").
/// The correction at a band material takes the light of a surface hit as its emission, exact
/// node by node, plus what it reflects, modelled as a uniform grey source reflected by the hit;
/// the environment grey at its brightness temperature; the sun a 5772 K blackbody. Checked
/// against a render wavelength by wavelength: the same scene once per wavelength node λ_m, with
/// the material grey at its N(λ_m) and a sensor band 2 nm wide around λ_m, weighted by the node
/// weights. The sky is a table of brightness temperatures and the ground black, so that both see
/// the same environment spectrum, and the paths are the same (same seed, same sampling density),
/// so the difference is the approximation, not noise. The scene is the hard case: a hot silicate
/// sphere on a silicate plate, inter-reflecting across the reststrahlen band, in the sun.
#[test]
fn the_monte_carlo_spectral_approximation_is_small() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    write_silicate(&lib, "silicate");
    let scene_text = |material: &str, band: (f64, f64), render: &str| {
        format!(
            "material_library = \"lib\"\n\
             [camera]\nposition = [3.0, -3.0, 1.6]\nlook_at = [0.0, 0.0, 0.5]\nup = [0.0, 0.0, 1.0]\n\
             fov_deg = 50.0\nresolution = [24, 24]\n\
             [sensor]\nband_um = [{:?}, {:?}]\n\
             [environment]\nair_temperature_k = 283.15\n\
             sky = {{ model = \"table\", elevation_deg = [0.0, 30.0, 90.0], brightness_temperature_k = [280.0, 255.0, 235.0] }}\n\
             ground = {{ temperature_k = 288.0, emissivity = 1.0 }}\n\
             [render]\nshading = \"pixel\"\n{render}\n\
             [sun]\nelevation_deg = 30.0\nazimuth_deg = 200.0\n\
             [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 4 }}\n\
             translate = [0.0, 0.0, 1.0]\nmaterial = \"{material}\"\ntemperature_k = 330.0\n\
             [[objects]]\nname = \"plate\"\nshape = {{ kind = \"plane\", size = [6.0, 6.0], divisions = [6, 6] }}\n\
             material = \"{material}\"\ntemperature_k = 295.0\n",
            band.0, band.1
        )
    };
    let path = "bounces = 2\nsamples = 4\nseed = 5";
    let lwir = (8.0, 14.0);
    let (_, band) = render_scene(dir.path(), &scene_text("silicate", lwir, path));
    let (_, open) = render_scene(
        dir.path(),
        &scene_text("silicate", lwir, "open_world = true"),
    );

    let nodes =
        irpol::optics::WavelengthNodes::for_table(&irpol::optics::Band::lwir(), &SILICATE_UM)
            .unwrap();
    let material = Material::load(&lib.join("silicate.toml")).unwrap();
    let MaterialModel::Spectral(model) = &material.model else {
        panic!("a spectral material")
    };
    let half_width = 1e-3; // µm
    let mut reference = vec![[0.0f64; 4]; band.stokes.len()];
    let wavelengths = nodes.wavelengths_um().iter().zip(nodes.weights_m());
    for (m, (&lambda, &weight)) in wavelengths.enumerate() {
        let at = model.at(lambda).unwrap();
        let name = format!("node{m}");
        write_material(
            &lib,
            &name,
            0.06,
            2.8,
            [&[lambda], &[at.n], &[at.k], &[0.0]],
        );
        let narrow = (lambda - half_width, lambda + half_width);
        let (_, image) = render_scene(dir.path(), &scene_text(&name, narrow, path));
        // Radiance in the narrow band over its width: the spectral radiance at λ_m.
        let scale = weight / (2.0 * half_width * 1e-6);
        for (r, s) in reference.iter_mut().zip(&image.stokes) {
            for j in 0..4 {
                r[j] += scale * s[j];
            }
        }
    }
    let (mut worst, mut largest_correction) = (0.0f64, 0.0f64);
    for i in (0..band.stokes.len()).filter(|&i| band.surface[i] != BACKGROUND) {
        let largest = |a: &[f64; 4], b: &[f64; 4]| {
            (0..4).map(|j| (a[j] - b[j]).abs()).fold(0.0, f64::max) / reference[i][0]
        };
        worst = worst.max(largest(&band.stokes[i], &reference[i]));
        largest_correction = largest_correction.max(largest(&band.stokes[i], &open.stokes[i]));
    }
    eprintln!(
        "band render vs wavelength by wavelength: {worst:.2e} of S0 at worst (corrections for \
         occlusion, inter-reflection and the sun up to {largest_correction:.2e} of S0)"
    );
    assert!(largest_correction > 0.1, "{largest_correction}");
    assert!(worst < 5e-3, "{worst}");
}

/// The thermal model (docs/design.md §1.8) takes a spectral material's default emissivity as its
/// hemispherical emissivity Planck-weighted at 300 K over its table (docs/spectral.md "Band rendering").
#[test]
fn a_spectral_material_has_a_planck_weighted_thermal_emissivity() {
    let dir = tempfile::tempdir().unwrap();
    write_silicate(&dir.path().join("lib"), "silicate");
    let text = format!(
        "material_library = \"lib\"\n{}{AUTUMN_ENVIRONMENT}\
         [thermal]\nweather = {{ clear_day = {{ air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 }} }}\n\
         start_utc = \"2026-06-21T00:00:00Z\"\nlatitude_deg = 48.14\nlongitude_deg = 11.58\n\
         [thermal.layers.glass]\nconductivity_w_mk = 1.0\ndensity_kg_m3 = 2500.0\nheat_capacity_j_kgk = 800.0\n\
         [[objects]]\nname = \"pane\"\nshape = {{ kind = \"plane\", size = [1.0, 1.0], divisions = [1, 1] }}\n\
         material = \"silicate\"\n[objects.thermal]\nstack = [[\"glass\", 0.004]]\nsolar_absorptance = 0.1\n",
        camera_toml(8)
    );
    let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
    let thermal = scene.thermal.as_ref().unwrap();
    let emissivity = thermal.surfaces[0].as_ref().unwrap().emissivity;
    // Σ f_m(300 K) ε_h(λ_m) over the table's own range, 8–14 µm.
    let material = Material::load(&dir.path().join("lib/silicate.toml")).unwrap();
    let MaterialModel::Spectral(model) = &material.model else {
        panic!("a spectral material")
    };
    let nodes =
        irpol::optics::WavelengthNodes::for_table(&irpol::optics::Band::lwir(), &SILICATE_UM)
            .unwrap();
    let expected: f64 = nodes
        .wavelengths_um()
        .iter()
        .zip(nodes.planck_fractions(300.0))
        .map(|(&l, f)| {
            f * model
                .at(l)
                .unwrap()
                .pbrdf()
                .unwrap()
                .hemispherical_emissivity()
        })
        .sum();
    assert!(
        (emissivity - expected).abs() < 1e-12,
        "{emissivity} vs {expected}"
    );
    // Between the reststrahlen band's 0.51 and the window's 0.86.
    assert!((0.74..0.76).contains(&emissivity), "{emissivity}");
}

/// Spectral materials of one scene share one set of wavelength nodes: the band split at the
/// table wavelengths of all of them, so that light passed between them keeps its spectrum.
#[test]
fn spectral_materials_of_a_scene_share_their_wavelength_nodes() {
    let dir = tempfile::tempdir().unwrap();
    let lib = dir.path().join("lib");
    write_silicate(&lib, "silicate");
    let table = [7.5, 9.25, 14.5];
    write_material(
        &lib,
        "paint",
        0.2,
        2.0,
        [
            &table,
            &[1.5, 1.7, 1.6],
            &[0.1, 0.3, 0.2],
            &[0.02, 0.03, 0.02],
        ],
    );
    let text = format!(
        "material_library = \"lib\"\n{}{AUTUMN_ENVIRONMENT}\
         [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 2 }}\n\
         material = \"silicate\"\ntemperature_k = 300.0\n\
         [[objects]]\nname = \"pebble\"\nshape = {{ kind = \"sphere\", radius = 0.2, subdivisions = 1 }}\n\
         translate = [1.2, 0.0, 0.0]\nmaterial = \"paint\"\ntemperature_k = 300.0\n",
        camera_toml(16)
    );
    let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
    let nodes: Vec<_> = scene
        .materials
        .iter()
        .map(|m| m.optics.band().unwrap().nodes().clone())
        .collect();
    assert_eq!(nodes[0], nodes[1]);
    // Breaks at the silicate's seven inner wavelengths and 9.25 µm: nine pieces, the last
    // (12.5–14 µm) in two.
    assert_eq!(nodes[0].len(), 10 * 4);
    let image = render(&scene, &Silent).unwrap().image;
    assert!(image.stokes.iter().all(|s| s.iter().all(|v| v.is_finite())));
}
