//! Helpers shared by the render integration tests.
#![allow(dead_code)]

use irpol::material::{Material, MaterialModel, ModelSpec};
use irpol::pbrdf::{Shadowing, SlopeDistribution};
use std::path::Path;

/// The generating "truth" of each shipped synthetic measurement (measurements/README.md):
/// (name, distribution, n, k, ρ_d, wavelength µm), all with Smith shadowing.
pub fn shipped_truths() -> [(&'static str, SlopeDistribution, f64, f64, f64, f64); 4] {
    [
        (
            "paper_paint",
            SlopeDistribution::Cauchy {
                sigma: 0.10,
                q: 1.8,
            },
            1.2,
            0.2,
            0.0,
            9.925,
        ),
        (
            "rough_paint",
            SlopeDistribution::Cauchy {
                sigma: 0.30,
                q: 2.5,
            },
            1.55,
            0.05,
            0.03,
            9.925,
        ),
        (
            "smooth_glass",
            SlopeDistribution::Cauchy {
                sigma: 0.03,
                q: 3.0,
            },
            2.2,
            0.1,
            0.0,
            10.6,
        ),
        (
            "anodized_panel",
            SlopeDistribution::Gaussian { sigma: 0.15 },
            3.0,
            1.0,
            0.01,
            9.925,
        ),
    ]
}

/// Writes the [`shipped_truths`] as a material library, standing in for `fits/`.
pub fn write_truth_library(dir: &Path) {
    for (name, distribution, n, k, rho_d, wavelength_um) in shipped_truths() {
        let material = Material {
            name: name.into(),
            tool_version: "test".into(),
            model: MaterialModel::Grey(ModelSpec {
                distribution,
                shadowing: Shadowing::Smith,
                n,
                k,
                rho_d,
                facet: Default::default(),
                lobe_keys: Default::default(),
                wavelength_um,
            }),
            fit: None,
        };
        material.save(&dir.join(format!("{name}.toml"))).unwrap();
    }
    silicate_truth()
        .save(&dir.join("silicate_glass.toml"))
        .unwrap();
}

/// The spectral truth of measurements/silicate_glass.csv (scripts/make_measurements.py: one
/// Lorentz oscillator, n and k at its nine wavelengths to 6 digits), the car's windows.
pub fn silicate_truth() -> Material {
    let wavelength_um = vec![8.0, 8.5, 9.0, 9.5, 10.0, 10.6, 11.5, 12.5, 14.0];
    let n = vec![
        0.517774, 0.588464, 1.36346, 2.87319, 2.62133, 2.30722, 2.08423, 1.96574, 1.87624,
    ];
    let k = vec![
        0.543731, 1.2793, 2.12223, 1.38554, 0.477271, 0.210027, 0.100204, 0.0596999, 0.0359674,
    ];
    Material {
        name: "silicate_glass".into(),
        tool_version: "test".into(),
        model: MaterialModel::Spectral(irpol::material::SpectralModel {
            distribution: SlopeDistribution::Cauchy {
                sigma: 0.06,
                q: 2.8,
            },
            shadowing: Shadowing::Smith,
            rho_d: vec![0.0; wavelength_um.len()],
            volume: Default::default(),
            wavelength_um,
            n,
            k,
            dispersion: None,
        }),
        fit: None,
    }
}

/// A copy of the shipped car scene in `dir/scenes`, with the truth library in `dir/fits`, at the
/// given resolution and shading.
pub fn car_scene(dir: &Path, width: u32, height: u32, shading: &str) -> std::path::PathBuf {
    write_truth_library(&dir.join("fits"));
    car_scene_files(dir, width, height, shading)
}

/// As [`car_scene`] but with the shipped fitted library (`fits/`).
pub fn car_scene_with_shipped_fits(
    dir: &Path,
    width: u32,
    height: u32,
    shading: &str,
) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::create_dir_all(dir.join("fits")).unwrap();
    for name in [
        "paper_paint",
        "rough_paint",
        "smooth_glass",
        "silicate_glass",
        "anodized_panel",
    ] {
        let file = format!("{name}.toml");
        std::fs::copy(root.join("fits").join(&file), dir.join("fits").join(&file)).unwrap();
    }
    car_scene_files(dir, width, height, shading)
}

fn car_scene_files(dir: &Path, width: u32, height: u32, shading: &str) -> std::path::PathBuf {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::create_dir_all(dir.join("scenes")).unwrap();
    std::fs::copy(root.join("scenes/car.obj"), dir.join("scenes/car.obj")).unwrap();
    let text = std::fs::read_to_string(root.join("scenes/car.toml"))
        .unwrap()
        .replace(
            "resolution = [640, 480]",
            &format!("resolution = [{width}, {height}]"),
        )
        .replace("shading = \"pixel\"", &format!("shading = \"{shading}\""));
    let path = dir.join("scenes/car.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Writes `text` as `dir/scene.toml` and returns its path.
pub fn write_scene(dir: &Path, text: &str) -> std::path::PathBuf {
    let path = dir.join("scene.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// Writes `text` as `dir/scene.toml`, loads and renders it in memory.
pub fn render_scene_text(
    dir: &Path,
    text: &str,
) -> (irpol::scene::Scene, irpol::render::StokesImage) {
    let scene = irpol::scene::load_scene(&write_scene(dir, text)).unwrap();
    let image = irpol::render::render(&scene, &irpol::progress::Silent)
        .unwrap()
        .image;
    (scene, image)
}

/// The pixels of `image` that see a surface.
pub fn object_pixels(image: &irpol::render::StokesImage) -> Vec<usize> {
    (0..image.stokes.len())
        .filter(|&i| image.surface[i] != irpol::render::BACKGROUND)
        .collect()
}

/// A closed isothermal cavity: the camera inside a sphere of paper_paint's generating parameters
/// (`shipped_truths`) at 350 K, a 283 K environment outside, 24 × 24 pixels; `render` is the
/// `[render]` table's keys.
pub fn closed_cavity_toml(render: &str) -> String {
    format!(
        "[camera]\nposition = [0.0, 0.0, 0.0]\nlook_at = [0.0, 1.0, 0.2]\nup = [0.0, 0.0, 1.0]\n\
         fov_deg = 50.0\nresolution = [24, 24]\n\
         [environment]\nair_temperature_k = 283.0\n\
         sky = {{ model = \"table\", elevation_deg = [0.0, 90.0], brightness_temperature_k = [283.0, 283.0] }}\n\
         ground = {{ temperature_k = 283.0, emissivity = 1.0 }}\n\
         {}\n[render]\n{render}\n\
         [[objects]]\nname = \"cavity\"\nshape = {{ kind = \"sphere\", radius = 2.0, subdivisions = 5 }}\n\
         material = \"m\"\ntemperature_k = 350.0\n",
        material_toml(0.10, 1.8, 1.2, 0.2, 0.0)
    )
}

/// A camera 4 m from the origin along −y looking at it, square image.
pub fn camera_toml(size: u32) -> String {
    format!(
        "[camera]\nposition = [0.0, -4.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\n\
         fov_deg = 36.0\nresolution = [{size}, {size}]\n"
    )
}

/// An environment of uniform brightness temperature `t` (sky and a black-body ground).
pub fn uniform_environment_toml(t: f64) -> String {
    format!(
        "[environment]\nair_temperature_k = {t}\n\
         sky = {{ model = \"table\", elevation_deg = [0.0, 90.0], brightness_temperature_k = [{t}, {t}] }}\n\
         ground = {{ temperature_k = {t}, emissivity = 1.0 }}\n"
    )
}

/// The clear autumn sky of the car scene.
pub const AUTUMN_ENVIRONMENT: &str = "[environment]\nair_temperature_k = 283.15\n\
    sky = { model = \"window\", zenith_emissivity = 0.75 }\n\
    ground = { temperature_k = 288.0, emissivity = 0.95 }\n";

/// Unit sphere at the origin with an inline material `m`.
pub fn sphere_toml(subdivisions: u32, temperature: f64) -> String {
    format!(
        "[[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = {subdivisions} }}\n\
         material = \"m\"\ntemperature_k = {temperature}\n"
    )
}

/// Inline material `m`: Cauchy σ, q, N = n + ik, ρ_d, Smith shadowing.
pub fn material_toml(sigma: f64, q: f64, n: f64, k: f64, rho_d: f64) -> String {
    format!(
        "[materials.m]\ndistribution = \"cauchy\"\nsigma = {sigma}\nq = {q}\nn = {n}\nk = {k}\n\
         rho_d = {rho_d}\nshadowing = \"smith\"\n"
    )
}

/// Runs the `irpol` binary with `args`: (success, stdout, stderr).
pub fn irpol(args: &[&str]) -> (bool, String, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .args(args)
        .output()
        .expect("run irpol");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// `irpol fit INPUTS… EXTRA… --out DIR/fits --reports DIR/reports`: success, stdout, stderr.
pub fn fit_into(dir: &Path, inputs: &[&Path], extra: &[&str]) -> (bool, String, String) {
    let (fits, reports) = (dir.join("fits"), dir.join("reports"));
    let mut args = vec!["fit"];
    args.extend(inputs.iter().map(|p| p.to_str().unwrap()));
    args.extend_from_slice(extra);
    args.extend(["--out", fits.to_str().unwrap()]);
    args.extend(["--reports", reports.to_str().unwrap()]);
    irpol(&args)
}

/// A scene of one steel plate with `[thermal]` on a clear day for two hours (the thermal limit
/// and input tests): `edit` changes the text before it is written.
pub fn thermal_plate_scene(edit: impl Fn(String) -> String) -> String {
    edit(
        r#"[camera]
position = [6.0, -6.0, 3.0]
look_at = [0.0, 0.0, 0.5]
fov_deg = 40.0
resolution = [16, 12]

[environment]
air_temperature_k = 290.0
sky = { model = "window", zenith_emissivity = 0.75 }
ground = { temperature_k = 290.0, emissivity = 0.95 }

[materials.paint]
distribution = "cauchy"
sigma = 0.2
q = 2.0
n = 1.5
k = 0.2
shadowing = "smith"

[thermal]
weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }
start_utc = "2026-06-21T00:00:00Z"
latitude_deg = 48.14
longitude_deg = 11.58
output_step_s = 3600
duration_h = 2

[thermal.layers.steel]
conductivity_w_mk = 45.0
density_kg_m3 = 7850.0
heat_capacity_j_kgk = 470.0

[[objects]]
name = "plate"
shape = { kind = "plane", size = [0.5, 0.5], divisions = [1, 1] }
material = "paint"
[objects.thermal]
stack = [["steel", 0.001]]
solar_absorptance = 0.6
"#
        .to_owned(),
    )
}

/// Vertices of object `name` of a scene.
pub fn vertices_of(scene: &irpol::scene::Scene, name: &str) -> Vec<usize> {
    let object = scene.object_names.iter().position(|n| n == name).unwrap();
    irpol::thermal_scene::vertex_surfaces(scene)
        .iter()
        .enumerate()
        .filter(|(_, &s)| scene.surfaces[s as usize].object == object)
        .map(|(v, _)| v)
        .collect()
}

/// The index of the recorded instant `time_s` of a thermal run.
pub fn record(solution: &irpol::thermal_scene::ThermalSolution, time_s: f64) -> usize {
    solution.times_s.iter().position(|&t| t == time_s).unwrap()
}
