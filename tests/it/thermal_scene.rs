//! The thermal model over a scene (docs/design.md §1.8: shade, convergence, energy closure, instants, bad input): a
//! ball over a ground plane and a thin plate high above it, on a clear midsummer day in Munich.

use crate::common;

use common::{irpol, record, vertices_of, write_scene};
use irpol::progress::Silent;
use irpol::scene::{load_scene, Scene};
use irpol::thermal_scene::{scene_at, solve_scene, vertex_surfaces, ThermalSolution};
use nalgebra::Vector3;

/// Ball centre (m): radius 0.5, 0.8 m above the ground.
const BALL: [f64; 3] = [0.0, 0.0, 0.8];

/// The scene, with `thermal_extra` appended to `[thermal]`.
fn scene_text(thermal_extra: &str) -> String {
    format!(
        r#"[camera]
position = [6.0, -6.0, 3.0]
look_at = [0.0, 0.0, 0.5]
fov_deg = 40.0
resolution = [64, 48]

[environment]
air_temperature_k = 290.0
sky = {{ model = "window", zenith_emissivity = 0.75 }}
ground = {{ temperature_k = 290.0, emissivity = 0.95 }}

[render]
samples = 2

[materials.paint]
distribution = "cauchy"
sigma = 0.2
q = 2.0
n = 1.5
k = 0.2
rho_d = 0.02
shadowing = "smith"

[thermal]
weather = {{ clear_day = {{ air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 }} }}
start_utc = "2026-06-21T00:00:00Z"
latitude_deg = 48.14
longitude_deg = 11.58
output_step_s = 3600
{thermal_extra}

[thermal.layers.paint]
conductivity_w_mk = 0.2
density_kg_m3 = 1200.0
heat_capacity_j_kgk = 1500.0

[thermal.layers.steel]
conductivity_w_mk = 45.0
density_kg_m3 = 7850.0
heat_capacity_j_kgk = 470.0

[thermal.layers.asphalt]
conductivity_w_mk = 0.75
density_kg_m3 = 2300.0
heat_capacity_j_kgk = 920.0

[[objects]]
name = "ball"
shape = {{ kind = "sphere", radius = 0.5, subdivisions = 2 }}
translate = {BALL:?}
material = "paint"
[objects.thermal]
stack = [["paint", 0.0001], ["steel", 0.001]]
back = {{ convection_w_m2k = 3.0 }}
solar_absorptance = 0.6

[[objects]]
name = "ground"
shape = {{ kind = "plane", size = [8.0, 8.0], divisions = [16, 16] }}
material = "paint"
[objects.thermal]
stack = [["asphalt", 0.2]]
back = {{ temperature_k = 290.0 }}
solar_absorptance = 0.9

[[objects]]
name = "plate"
shape = {{ kind = "plane", size = [0.5, 0.5], divisions = [1, 1] }}
translate = [20.0, 20.0, 5.0]
material = "paint"
[objects.thermal]
stack = [["steel", 0.001]]
solar_absorptance = 0.6
"#
    )
}

/// `irpol thermal SCENE --out OUT`: (success, stdout, stderr).
fn thermal_cli(scene: &std::path::Path, out: &std::path::Path) -> (bool, String, String) {
    irpol(&[
        "thermal",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ])
}

fn solved(dir: &std::path::Path, extra: &str, times: &[f64]) -> (Scene, ThermalSolution) {
    let path = write_scene(dir, &scene_text(extra));
    let scene = load_scene(&path).unwrap();
    let solution = solve_scene(&scene, times, &Silent).unwrap();
    (scene, solution)
}

/// Acceptance 4: the ground in the ball's afternoon shadow is cooler than the ground in sun, and
/// a thin plate under the clear night sky is colder than the air.
#[test]
fn shadowed_ground_is_cooler_and_a_plate_cools_below_the_air_at_night() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, solution) = solved(dir.path(), "", &[]);
    // 13:00 UTC is 15:00 local summer time.
    let afternoon = record(&solution, 13.0 * 3600.0);
    let sun = solution.weather[afternoon].sun_direction;
    assert!(sun.z > 0.3, "the sun is up: {sun:?}");
    let centre = Vector3::from(BALL);
    let shadow = centre - sun * (centre.z / sun.z);
    let ground = vertices_of(&scene, "ground");
    let nearest = |p: Vector3<f64>| {
        *ground
            .iter()
            .min_by(|&&a, &&b| {
                let d = |v: usize| (scene.mesh.positions[v] - p).norm();
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    let in_shadow = nearest(shadow);
    let in_sun = nearest(shadow + Vector3::new(-sun.y, sun.x, 0.0).normalize() * 3.0);
    let t = &solution.surface_k[afternoon];
    println!(
        "ground at 15:00 local: {:.2} K in the ball's shadow, {:.2} K in sun",
        t[in_shadow], t[in_sun]
    );
    assert!(t[in_shadow] < t[in_sun] - 3.0);

    let night = record(&solution, 3600.0);
    let plate = vertices_of(&scene, "plate");
    let air = solution.weather[night].air_k;
    for &v in &plate {
        let plate_k = solution.surface_k[night][v];
        assert!(plate_k < air - 1.0, "plate {plate_k} K, air {air} K");
    }
}

/// The ground's afternoon temperature at each of its vertices `inside_m` or more inside the ball's
/// shadow, for the ground typed with `divisions`.
fn ground_in_shadow(
    dir: &std::path::Path,
    divisions: &str,
    inside_m: f64,
) -> Vec<(Vector3<f64>, f64)> {
    let path = write_scene(
        dir,
        &scene_text("").replace("divisions = [16, 16]", divisions),
    );
    let scene = load_scene(&path).unwrap();
    let solution = solve_scene(&scene, &[], &Silent).unwrap();
    let afternoon = record(&solution, 13.0 * 3600.0);
    let sun = solution.weather[afternoon].sun_direction;
    let centre = Vector3::from(BALL);
    vertices_of(&scene, "ground")
        .into_iter()
        .filter_map(|v| {
            let p = scene.mesh.positions[v];
            // In the shadow: the ray toward the sun passes `inside_m` inside the ball's rim.
            let to_centre = centre - p;
            let miss = (to_centre - sun * to_centre.dot(&sun)).norm();
            (miss < 0.5 - inside_m).then_some((p, solution.surface_k[afternoon][v]))
        })
        .collect()
}

/// A ground plane typed with `divisions = [1, 1]` (what `scene init` writes) is solved on
/// `thermal.plane_cell_m` cells, so the ball's shadow appears in it as in a [200, 200] plane.
#[test]
fn a_plane_of_one_cell_shows_the_shadow_of_a_fine_plane() {
    let dir = tempfile::tempdir().unwrap();
    let coarse = ground_in_shadow(dir.path(), "divisions = [1, 1]", 0.1);
    let fine = ground_in_shadow(dir.path(), "divisions = [200, 200]", 0.0);
    assert!(
        coarse.len() >= 4,
        "{} coarse vertices in shadow",
        coarse.len()
    );
    // The fine plane's vertices lie on a 0.04 m grid from −4 m: interpolate it bilinearly.
    let cell = 8.0 / 200.0;
    let grid = |x: f64| (x + 4.0) / cell;
    let fine_at: std::collections::HashMap<(i64, i64), f64> = fine
        .iter()
        .map(|(q, t)| ((grid(q.x).round() as i64, grid(q.y).round() as i64), *t))
        .collect();
    let mut worst: f64 = 0.0;
    for (p, t) in &coarse {
        let (gx, gy) = (grid(p.x), grid(p.y));
        let (i, j) = (gx.floor() as i64, gy.floor() as i64);
        let (fx, fy) = (gx - i as f64, gy - j as f64);
        let corner = |di: i64, dj: i64| fine_at[&(i + di, j + dj)];
        let t_fine = (1.0 - fy) * ((1.0 - fx) * corner(0, 0) + fx * corner(1, 0))
            + fy * ((1.0 - fx) * corner(0, 1) + fx * corner(1, 1));
        worst = worst.max((t - t_fine).abs());
    }
    println!(
        "{} vertices in the shadow: [1, 1] vs [200, 200] worst {worst:.3} K",
        coarse.len()
    );
    assert!(worst < 0.5, "{worst} K");
}

/// Acceptance 5 at scene level: halving the forcing step changes no surface temperature of the
/// day by 0.01 K or more.
#[test]
fn halving_the_time_step_changes_surface_temperatures_by_less_than_10_mk() {
    let dir = tempfile::tempdir().unwrap();
    let (_, coarse) = solved(dir.path(), "time_step_s = 60", &[]);
    let (_, fine) = solved(dir.path(), "time_step_s = 30", &[]);
    assert_eq!(coarse.times_s, fine.times_s);
    let worst = coarse
        .surface_k
        .iter()
        .zip(&fine.surface_k)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max);
    println!("time step 60 s vs 30 s: worst surface difference {worst:.2e} K");
    assert!(worst < 0.01, "{worst} K");
}

/// Acceptance 3 at scene level: over 48 h of clear-day forcing (after a spin-up day) every
/// vertex's stored heat equals its integrated net flux to 1e-6 of the flux through it.
#[test]
fn energy_closes_over_48_hours_of_weather() {
    let dir = tempfile::tempdir().unwrap();
    let (_, solution) = solved(dir.path(), "duration_h = 48\nspinup_days = 1", &[]);
    println!(
        "energy closure: {:.2e}",
        solution.stats.worst_energy_closure
    );
    assert!(solution.stats.worst_energy_closure < 1e-6);
    assert!(solution.stats.distinct_solves < solution.stats.thermal_vertices);
}

/// Identical vertices share one solve: the four corners of the plate high above everything have
/// one normal, the whole sky and the same sun, so one history; the ground does not collapse into
/// one (its vertices see the ball and its shadow differently).
#[test]
fn identical_vertices_are_solved_once() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, solution) = solved(dir.path(), "", &[]);
    let plate = vertices_of(&scene, "plate");
    // The 0.5 m plate of divisions [1, 1] is solved on 0.25 m cells: 3 × 3 vertices.
    assert_eq!(plate.len(), 9);
    for row in &solution.surface_k {
        assert!(plate.iter().all(|&v| row[v] == row[plate[0]]));
    }
    let ground = vertices_of(&scene, "ground");
    let noon = &solution.surface_k[record(&solution, 11.0 * 3600.0)];
    let lo = ground
        .iter()
        .map(|&v| noon[v])
        .fold(f64::INFINITY, f64::min);
    let hi = ground.iter().map(|&v| noon[v]).fold(0.0, f64::max);
    assert!(hi - lo > 3.0, "ground at noon {lo}…{hi} K");
    let stats = solution.stats;
    assert!(stats.distinct_solves < stats.thermal_vertices, "{stats:?}");
}

/// An instant renders with the solved temperatures, the weather's air and the sun where it is.
#[test]
fn a_scene_at_an_instant_carries_the_solution() {
    let dir = tempfile::tempdir().unwrap();
    let (scene, solution) = solved(dir.path(), "", &[5000.0]);
    let i = record(&solution, 5000.0);
    let at = scene_at(&scene, &solution, i).unwrap();
    assert_eq!(at.mesh.temperatures, solution.surface_k[i]);
    assert_eq!(at.air_temperature_k, solution.weather[i].air_k);
    let instant = at.thermal_instant.as_ref().unwrap();
    assert_eq!(instant.time_utc, "2026-06-21T01:23:20Z");
    assert!(
        at.sun.is_none(),
        "the sun is below the horizon at 03:23 local time"
    );
    let noon = scene_at(&scene, &solution, record(&solution, 43200.0)).unwrap();
    let sun = noon.sun.unwrap();
    assert_eq!(
        sun.direction,
        solution.weather[record(&solution, 43200.0)].sun_direction
    );
}

#[test]
fn thermal_command_writes_the_table_meshes_and_plot() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), &scene_text("duration_h = 6"));
    let out = dir.path().join("thermal");
    let (ok, stdout, stderr) = thermal_cli(&scene, &out);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("thermal run of"), "{stdout}");
    let csv = std::fs::read_to_string(out.join("temperatures.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("time_s,part,t_surface_min_k,t_surface_mean_k,t_surface_max_k")
    );
    // 7 instants (0…6 h) × 3 parts.
    assert_eq!(lines.clone().count(), 21);
    assert!(lines
        .clone()
        .any(|l| l.starts_with("21600,ground/surface,")));
    for line in lines {
        let v: Vec<f64> = line
            .split(',')
            .skip(2)
            .map(|x| x.parse().unwrap())
            .collect();
        assert!(
            v[0] <= v[1] && v[1] <= v[2] && v[0] > 250.0 && v[2] < 350.0,
            "{line}"
        );
    }
    assert!(out.join("temperatures.png").is_file());
    assert!(out.join("surface_0006_21600s.ply").is_file());
    // The PLY is a mesh irpol reads back, with the temperature property: the shading mesh and
    // the solution's temperatures at that instant (as f32), read by irpol's reader and by
    // ply-rs-bw's parser alike (the file is written by hand, so a second reader checks it).
    let ply = std::fs::read(out.join("surface_0003_10800s.ply")).unwrap();
    let header = String::from_utf8_lossy(&ply[..300]);
    assert!(header.contains("property float temperature"), "{header}");
    let loaded = load_scene(&scene).unwrap();
    let solution = solve_scene(&loaded, &[], &Silent).unwrap();
    let direct = irpol::scene::ply::parse_ply(&ply).unwrap();
    let parsed = irpol::scene::ply::parse_ply_through_parser(&ply).unwrap();
    for raw in [&direct, &parsed] {
        assert_eq!(raw.positions.len(), loaded.mesh.positions.len());
        let faces: Vec<[u32; 3]> = raw.faces.iter().map(|f| f.vertices).collect();
        assert_eq!(faces, loaded.mesh.triangles);
        let temperatures = raw.vertex_temperatures.as_ref().unwrap();
        for (v, (&t, p)) in temperatures.iter().zip(&raw.positions).enumerate() {
            assert_eq!(t, solution.surface_k[3][v] as f32 as f64);
            assert_eq!(p.x, loaded.mesh.positions[v].x as f32 as f64);
        }
    }
}

#[test]
fn render_at_times_writes_numbered_folders_and_an_animation() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), &scene_text("duration_h = 12"));
    let out = dir.path().join("series");
    let (ok, _, stderr) = irpol(&[
        "render",
        scene.to_str().unwrap(),
        "--times",
        "0:43200:21600",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    for folder in ["000_0s", "001_21600s", "002_43200s"] {
        assert!(out.join(folder).join("S0.tif").is_file(), "{folder}");
    }
    let summary = std::fs::read_to_string(out.join("001_21600s/summary.json")).unwrap();
    assert!(
        summary.contains("\"time_utc\": \"2026-06-21T06:00:00Z\""),
        "{summary}"
    );
    let gif = std::fs::read(out.join("preview.gif")).unwrap();
    assert_eq!(&gif[..6], b"GIF89a");
}

/// Frame folders in `out`, sorted.
fn frame_folders(out: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(out)
        .unwrap()
        .flatten()
        .filter(|e| e.path().is_dir())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A series replaces the folder's earlier series as a whole: a shorter or differently stepped
/// series leaves no frame of the earlier one. A single instant rendered into the folder is an
/// output set of its own: a series keeps it and it keeps the series (before, `--times` deleted the
/// `--time-utc` render the docs had just made). The user's own files stay.
#[test]
fn a_series_replaces_the_earlier_series_and_keeps_the_users_files() {
    let dir = tempfile::tempdir().unwrap();
    let scene = write_scene(dir.path(), &scene_text("duration_h = 6"));
    let out = dir.path().join("series");
    let render = |when: &[&str]| {
        let mut args = vec!["render", scene.to_str().unwrap(), "--out"];
        args.push(out.to_str().unwrap());
        args.extend_from_slice(when);
        let (ok, _, stderr) = irpol(&args);
        assert!(ok, "{stderr}");
    };
    render(&["--times", "0:21600:10800"]);
    assert_eq!(frame_folders(&out), ["000_0s", "001_10800s", "002_21600s"]);
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    render(&["--times", "0:21600:7200"]);
    assert_eq!(
        frame_folders(&out),
        ["000_0s", "001_7200s", "002_14400s", "003_21600s"]
    );
    let manifest: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("series.json")).unwrap()).unwrap();
    assert_eq!(manifest["frames"][1]["folder"], "001_7200s");
    assert_eq!(manifest["frames"][1]["time_utc"], "2026-06-21T02:00:00Z");
    render(&["--time", "3600"]);
    assert_eq!(frame_folders(&out).len(), 4, "the series stays");
    assert!(out.join("preview.gif").exists() && out.join("series.json").exists());
    assert!(out.join("S0.tif").is_file());
    let single = std::fs::read(out.join("summary.json")).unwrap();
    render(&["--times", "0:3600:3600"]);
    assert_eq!(frame_folders(&out), ["000_0s", "001_3600s"]);
    assert!(out.join("S0.tif").is_file(), "the single render stays");
    assert_eq!(std::fs::read(out.join("summary.json")).unwrap(), single);
    assert_eq!(
        std::fs::read_to_string(out.join("notes.txt")).unwrap(),
        "mine"
    );
    let hidden: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(hidden.is_empty(), "no staging folder left: {hidden:?}");
}

/// Bad thermal input: one-line errors naming the key, and nothing written.
#[test]
fn bad_thermal_input_is_refused_by_name_and_writes_nothing() {
    let cases: [(&str, &str, &str); 8] = [
        (
            "[[\"paint\", 0.0001], [\"stel\", 0.001]]",
            "",
            "layer 'stel' is not defined in [thermal.layers] (defined: asphalt, paint, steel)",
        ),
        (
            "[[\"paint\", -0.0001]]",
            "",
            "layer 1 ('paint'): thickness = -0.0001 m is outside 1e-6…100 m",
        ),
        (
            "[[\"asphalt\", 0.1]]",
            "",
            "layer 1 ('asphalt'): conductivity = -0.75 W/m/K is outside 0.001…10000 W/m/K",
        ),
        (
            "[[\"paint\"]]",
            "",
            "a stack entry is [layer name, thickness_m]",
        ),
        ("[]", "", "stack is empty"),
        (
            "[[\"paint\", 0.001]]",
            "shadow_step_s = 0",
            "thermal.shadow_step_s = 0 must be positive",
        ),
        (
            "[[\"paint\", 0.001]]",
            "plane_cell_m = -0.5",
            "thermal.plane_cell_m = -0.5 must be positive",
        ),
        (
            "[[\"paint\", 0.001]]",
            "latitude = 3",
            "unknown field `latitude`",
        ),
    ];
    for (stack, extra, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        let text = scene_text(extra)
            .replace(
                "stack = [[\"paint\", 0.0001], [\"steel\", 0.001]]",
                &format!("stack = {stack}"),
            )
            // The asphalt case: a negative conductivity (its stack names the asphalt).
            .replace("conductivity_w_mk = 0.75", "conductivity_w_mk = -0.75");
        let scene = write_scene(dir.path(), &text);
        let out = dir.path().join("out");
        let (ok, _, stderr) = thermal_cli(&scene, &out);
        assert!(!ok);
        assert!(stderr.contains(expected), "{expected}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(!out.exists());
    }
}

#[test]
fn render_needs_an_instant_for_thermal_scenes_and_a_thermal_scene_for_instants() {
    let dir = tempfile::tempdir().unwrap();
    let thermal = write_scene(dir.path(), &scene_text(""));
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "render",
        thermal.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("has a [thermal] section: say when"),
        "{stderr}"
    );
    let (ok, _, stderr) = irpol(&[
        "render",
        thermal.to_str().unwrap(),
        "--time",
        "90000",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("outside the run 0…86400 s"),
        "{stderr}"
    );
    assert!(!out.exists());

    let plain = dir.path().join("plain.toml");
    let text = scene_text("");
    let cut = text.find("[thermal]").unwrap();
    let objects = text.find("[[objects]]").unwrap();
    let no_thermal = format!("{}{}", &text[..cut], &text[objects..])
        .lines()
        .filter(|l| {
            !l.starts_with("[objects.thermal]")
                && !l.starts_with("stack")
                && !l.starts_with("back")
                && !l.starts_with("solar_absorptance")
        })
        .map(|l| format!("{l}\n"))
        .collect::<String>()
        .replace(
            "material = \"paint\"\n",
            "material = \"paint\"\ntemperature_k = 290.0\n",
        );
    std::fs::write(&plain, no_thermal).unwrap();
    let (ok, _, stderr) = irpol(&[
        "render",
        plain.to_str().unwrap(),
        "--time",
        "0",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok && stderr.contains("no [thermal] section"), "{stderr}");
    assert!(!out.exists());
}

/// A weather file that is too short, or broken, is refused naming the file (and its line).
#[test]
fn bad_weather_files_are_refused_by_file_and_line() {
    let cases = [
        (
            "time_s,air_temperature_k\n0,290\n43200,295\n",
            "duration_h = 24",
            "the weather covers 0…43200 s but the run needs 0…86400 s",
        ),
        (
            "time_s,air_temperature_k\n0,290\n600,291\n300,292\n",
            "",
            "weather.csv:4:1: column 'time_s': 300 s is not after 600 s",
        ),
        ("air_temperature_k\n290\n291\n", "", "weather.csv"),
    ];
    for (csv, extra, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("weather.csv"), csv).unwrap();
        let text = scene_text(extra).replace(
            "weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }",
            "weather = \"weather.csv\"",
        );
        let scene = write_scene(dir.path(), &text);
        let out = dir.path().join("out");
        let (ok, _, stderr) = thermal_cli(&scene, &out);
        assert!(!ok && stderr.contains(expected), "{expected}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(!out.exists());
    }
}

/// Acceptance 4 on the shipped car (`scenes/car_day.toml`, 14 h without spin-up): at 15:00 local
/// time the ground in the car's shadow is cooler than the same ground (one part, one stack) in sun.
#[test]
fn the_ground_in_the_cars_shadow_is_cooler_in_the_afternoon() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(root.join("scenes/car.obj"), dir.path().join("car.obj")).unwrap();
    let text = std::fs::read_to_string(root.join("scenes/car_day.toml"))
        .unwrap()
        .replace(
            "material_library = \"../fits\"",
            &format!(
                "material_library = {:?}",
                root.join("fits").display().to_string()
            ),
        )
        .replace("spinup_days = 1", "spinup_days = 0")
        .replace("duration_h = 24", "duration_h = 14");
    let path = dir.path().join("car_day.toml");
    std::fs::write(&path, text).unwrap();
    let scene = load_scene(&path).unwrap();
    let solution = solve_scene(&scene, &[], &Silent).unwrap();
    let afternoon = record(&solution, 13.0 * 3600.0);
    let sun = solution.weather[afternoon].sun_direction;
    let roof = Vector3::new(0.0, 0.0, 1.0);
    let shadow = roof - sun * (roof.z / sun.z);
    let ground: Vec<usize> = vertex_surfaces(&scene)
        .iter()
        .enumerate()
        .filter(|(_, &s)| scene.surfaces[s as usize].part == "ground")
        .map(|(v, _)| v)
        .collect();
    let nearest = |p: Vector3<f64>| {
        *ground
            .iter()
            .min_by(|&&a, &&b| {
                let d = |v: usize| (scene.mesh.positions[v] - p).norm();
                d(a).total_cmp(&d(b))
            })
            .unwrap()
    };
    let side = Vector3::new(-sun.y, sun.x, 0.0).normalize();
    let (in_shadow, in_sun) = (nearest(shadow), nearest(shadow + side * 6.0));
    let t = &solution.surface_k[afternoon];
    println!(
        "car_day ground at 15:00 local: {:.2} K in the car's shadow, {:.2} K in sun",
        t[in_shadow], t[in_sun]
    );
    assert!(t[in_shadow] < t[in_sun] - 5.0);
    // The cabin's coupled solve: its fixed point settles to its tolerance and node and walls
    // close their energy.
    let noon = record(&solution, 43200.0);
    let (cabin, air) = (
        solution.enclosure_air_k[0][noon],
        solution.weather[noon].air_k,
    );
    println!(
        "car_day cabin at noon UTC: {cabin:.2} K, air {air:.2} K; fixed-point residual {:.1e} K, \
         energy closure {:.1e}",
        solution.enclosure_residual_k[0], solution.stats.worst_energy_closure
    );
    assert!(cabin > air + 10.0);
    assert!(solution.enclosure_residual_k[0] <= 1e-4);
    assert!(solution.stats.worst_energy_closure < 1e-6);
}
