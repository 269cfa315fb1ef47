//! The thermal model's world around the parts (docs/design.md §1.8): the environment's ground as
//! a surface of its own, and enclosures (an air node behind its members' back faces), with the
//! bad input of their keys.

use crate::common;

use common::{irpol, record, vertices_of, write_scene};
use irpol::progress::Silent;
use irpol::scene::environment::Environment;
use irpol::scene::{load_scene, Scene};
use irpol::thermal_scene::{scene_at, solve_scene, ThermalSolution};

const LAYERS: &str = r#"
[thermal.layers.steel]
conductivity_w_mk = 45.0
density_kg_m3 = 7850.0
heat_capacity_j_kgk = 470.0

[thermal.layers.asphalt]
conductivity_w_mk = 0.75
density_kg_m3 = 2300.0
heat_capacity_j_kgk = 920.0

[thermal.layers.soil]
conductivity_w_mk = 1.0
density_kg_m3 = 1600.0
heat_capacity_j_kgk = 1000.0
"#;

const PAINT: &str = r#"
[materials.paint]
distribution = "cauchy"
sigma = 0.2
q = 2.0
n = 1.5
k = 0.2
rho_d = 0.02
shadowing = "smith"
"#;

/// Asphalt over soil with its deep soil fixed, as the shipped car's ground.
const GROUND_STACK: &str = r#"stack = [["asphalt", 0.05], ["soil", 0.5]]
back = { temperature_k = 288.0 }
solar_absorptance = 0.9
emissivity = 0.95"#;

/// A clear day at Munich with `ground` as `[environment] ground`, `thermal_extra` in `[thermal]`
/// and `objects` after the layers.
fn scene_text(ground: &str, thermal_extra: &str, objects: &str) -> String {
    format!(
        r#"[camera]
position = [6.0, -6.0, 3.0]
look_at = [0.0, 0.0, 0.5]
fov_deg = 40.0
resolution = [32, 24]

[environment]
air_temperature_k = 290.0
sky = {{ model = "window", zenith_emissivity = 0.75 }}
ground = {ground}

[render]
samples = 1
{PAINT}
[thermal]
weather = {{ clear_day = {{ air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 }} }}
start_utc = "2026-06-21T00:00:00Z"
latitude_deg = 48.14
longitude_deg = 11.58
output_step_s = 1800
{thermal_extra}
{LAYERS}
{objects}"#
    )
}

/// The environment's ground solved with the shipped car's stack (one line of TOML).
fn thermal_ground() -> String {
    format!(
        "{{ temperature_k = 288.0, emissivity = 0.95, thermal = {{ {} }} }}",
        GROUND_STACK.replace('\n', ", ")
    )
}

/// A flat horizontal slab with the ground's stack, and a vertical plate below the slab's horizon
/// (so nothing blocks the slab's sky or sun).
fn slab_and_plate() -> String {
    format!(
        r#"[[objects]]
name = "slab"
shape = {{ kind = "plane", size = [2.0, 2.0], divisions = [1, 1] }}
translate = [0.0, 0.0, 0.0]
material = "paint"
temperature_k = 288.0
[objects.thermal]
{GROUND_STACK}

[[objects]]
name = "plate"
shape = {{ kind = "plane", size = [1.0, 1.0], divisions = [1, 1] }}
rotate_deg = [90.0, 0.0, 0.0]
translate = [30.0, 0.0, -10.0]
material = "paint"
temperature_k = 290.0
[objects.thermal]
stack = [["steel", 0.001]]
solar_absorptance = 0.6
emissivity = 0.9
"#
    )
}

fn solved(dir: &std::path::Path, text: &str) -> (Scene, ThermalSolution) {
    let path = write_scene(dir, text);
    let scene = load_scene(&path).unwrap();
    let solution = solve_scene(&scene, &[], &Silent).unwrap();
    (scene, solution)
}

/// Acceptance: the environment's ground, with a part's stack, equals a flat unshadowed part of
/// that stack within 0.01 K all day (spun up), follows the day, and is what a render at an
/// instant sees below the horizon.
#[test]
fn the_environment_ground_equals_a_flat_unshadowed_part_of_its_stack() {
    let dir = tempfile::tempdir().unwrap();
    let text = scene_text(&thermal_ground(), "spinup_days = 1", &slab_and_plate());
    let (scene, solution) = solved(dir.path(), &text);
    let ground_k = solution.ground_k.as_ref().expect("a solved ground");
    let slab = vertices_of(&scene, "slab");
    // A 2 m plane solved on 0.25 m cells (thermal.plane_cell_m): 9 × 9 vertices.
    assert_eq!(slab.len(), 81);
    let worst = (solution.surface_k.iter().zip(ground_k))
        .flat_map(|(row, &g)| slab.iter().map(move |&v| (row[v] - g).abs()))
        .fold(0.0, f64::max);
    let (lo, hi) = ground_k
        .iter()
        .fold((f64::INFINITY, 0.0_f64), |(lo, hi), &t| {
            (lo.min(t), hi.max(t))
        });
    println!("environment ground {lo:.2}…{hi:.2} K; worst difference from the slab {worst:.2e} K");
    assert!(worst < 0.01, "{worst} K");
    assert!(hi - lo > 25.0, "the ground follows the day: {lo}…{hi} K");

    let noon = record(&solution, 43200.0);
    let at = scene_at(&scene, &solution, noon).unwrap();
    let mut environment = scene.thermal_rebuild.as_ref().unwrap().environment.clone();
    environment.air_temperature_k = solution.weather[noon].air_k;
    environment.ground.temperature_k = ground_k[noon];
    let expected = Environment::new(&environment, &scene.sensor.band).unwrap();
    assert_eq!(at.environment.ground_radiance(), expected.ground_radiance());
    let night = scene_at(&scene, &solution, record(&solution, 3600.0)).unwrap();
    assert!(at.environment.ground_radiance() > 1.2 * night.environment.ground_radiance());
}

/// The solved ground is what a part sees below its horizon: a vertical plate (half its view
/// below the horizon) is warmer at noon over a hot ground than over the typed 288 K one; without
/// the key nothing changes and nothing is solved for the ground.
#[test]
fn a_solved_ground_warms_what_sees_it_and_the_typed_ground_stays_as_it_was() {
    let dir = tempfile::tempdir().unwrap();
    let typed = "{ temperature_k = 288.0, emissivity = 0.95 }";
    let (scene, fixed) = solved(dir.path(), &scene_text(typed, "", &slab_and_plate()));
    assert!(fixed.ground_k.is_none() && fixed.enclosure_air_k.is_empty());
    let (_, warm) = solved(
        dir.path(),
        &scene_text(&thermal_ground(), "", &slab_and_plate()),
    );
    let plate = vertices_of(&scene, "plate");
    let noon = record(&fixed, 43200.0);
    let (cold, hot) = (
        fixed.surface_k[noon][plate[0]],
        warm.surface_k[noon][plate[0]],
    );
    let ground = warm.ground_k.as_ref().unwrap()[noon];
    println!(
        "vertical plate at noon: {cold:.2} K over the typed ground, {hot:.2} K over {ground:.2} K"
    );
    assert!(ground > 310.0);
    assert!(hot > cold + 1.0, "{hot} K vs {cold} K");
}

/// A closed 1 m cube high in the air: five opaque walls and a glazed lid around one air node,
/// emissivity 0 (no long-wave), constant air and diffuse sunlight, no direct sun.
fn box_scene(capacity_j_k: f64) -> String {
    format!(
        r#"[camera]
position = [6.0, -6.0, 3.0]
look_at = [0.0, 0.0, 0.5]
fov_deg = 40.0
resolution = [16, 12]

[environment]
air_temperature_k = 290.0
sky = {{ model = "window", zenith_emissivity = 0.75 }}
ground = {{ temperature_k = 290.0, emissivity = 0.95 }}

[render]
samples = 1
{PAINT}
[thermal]
weather = "weather.csv"
start_utc = "2026-06-21T00:00:00Z"
latitude_deg = 48.14
longitude_deg = 11.58
duration_h = 8
output_step_s = 3600
{LAYERS}
[thermal.enclosures.inside]
heat_capacity_j_k = {capacity_j_k}
air_exchange_w_k = {BOX_G}

[[objects]]
name = "box"
mesh = "box.obj"
translate = [0.0, 0.0, 10.0]
material = "paint"
temperature_k = 290.0
[objects.thermal]
stack = [["steel", 0.001]]
back = {{ convection_w_m2k = {BOX_H_BACK} }}
convection_w_m2k = {BOX_H_FRONT}
emissivity = 0.0
solar_absorptance = {BOX_ALPHA_WALL}
enclosure = "inside"
[objects.parts.lid.thermal]
stack = [["steel", 0.001]]
back = {{ convection_w_m2k = {BOX_H_BACK} }}
convection_w_m2k = {BOX_H_FRONT}
emissivity = 0.0
solar_absorptance = {BOX_ALPHA_LID}
solar_transmittance = {BOX_TAU_LID}
enclosure = "inside"
"#
    )
}

const BOX_G: f64 = 5.0;
const BOX_H_BACK: f64 = 5.0;
const BOX_H_FRONT: f64 = 10.0;
const BOX_ALPHA_WALL: f64 = 0.5;
const BOX_ALPHA_LID: f64 = 0.3;
const BOX_TAU_LID: f64 = 0.4;
const BOX_AIR_K: f64 = 290.0;
const BOX_DIFFUSE_W_M2: f64 = 400.0;

/// A unit cube, one normal per face: group `walls` (four sides and the bottom) and `lid` (top).
const BOX_OBJ: &str = "v -0.5 -0.5 -0.5\nv 0.5 -0.5 -0.5\nv 0.5 0.5 -0.5\nv -0.5 0.5 -0.5\n\
v -0.5 -0.5 0.5\nv 0.5 -0.5 0.5\nv 0.5 0.5 0.5\nv -0.5 0.5 0.5\n\
vn 0 0 -1\nvn 0 0 1\nvn 0 -1 0\nvn 1 0 0\nvn 0 1 0\nvn -1 0 0\n\
g walls\nf 1//1 3//1 2//1\nf 1//1 4//1 3//1\n\
f 1//3 2//3 6//3\nf 1//3 6//3 5//3\nf 2//4 3//4 7//4\nf 2//4 7//4 6//4\n\
f 3//5 4//5 8//5\nf 3//5 8//5 7//5\nf 4//6 1//6 5//6\nf 4//6 5//6 8//6\n\
g lid\nf 5//2 6//2 7//2\nf 5//2 7//2 8//2\n";

/// The box's steady air temperature by hand. Per unit area a wall passes
/// U (T_air − T_c) + α E U / h_f into the node, U = 1/(1/h_f + d/k + 1/h_b) (the front absorbs
/// αE, and of that U/h_f reaches the inside at steady state); the lid adds τ E. The node loses
/// G (T_c − T_air). With E = E_dh F_sky (1 on the lid, ½ on the sides, 0 under the floor):
/// T_c = T_air + Σ A E (α U/h_f + τ) / (G + Σ A U).
fn box_steady_state_k() -> f64 {
    let u = 1.0 / (1.0 / BOX_H_FRONT + 0.001 / 45.0 + 1.0 / BOX_H_BACK);
    let e = BOX_DIFFUSE_W_M2;
    let lid = e * (BOX_ALPHA_LID * u / BOX_H_FRONT + BOX_TAU_LID);
    let sides = 4.0 * 0.5 * e * (BOX_ALPHA_WALL * u / BOX_H_FRONT);
    BOX_AIR_K + (lid + sides) / (BOX_G + 6.0 * u)
}

/// Acceptance: the closed box reaches the lumped steady state within 0.05 K, both with a node
/// slower than the step (trapezoid) and with one faster (held, backward Euler), and the energy of
/// node and walls together closes to 1e-6.
#[test]
fn a_closed_box_reaches_its_steady_state_and_closes_its_energy() {
    let weather = format!(
        "time_s,air_temperature_k,diffuse_horizontal_w_m2\n0,{BOX_AIR_K},{BOX_DIFFUSE_W_M2}\n\
         30000,{BOX_AIR_K},{BOX_DIFFUSE_W_M2}\n"
    );
    let expected = box_steady_state_k();
    for capacity in [20_000.0, 100.0] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("box.obj"), BOX_OBJ).unwrap();
        std::fs::write(dir.path().join("weather.csv"), &weather).unwrap();
        let (scene, solution) = solved(dir.path(), &box_scene(capacity));
        assert_eq!(scene.mesh.positions.len(), 24);
        let air = &solution.enclosure_air_k[0];
        let last = *air.last().unwrap();
        let closure = solution.stats.worst_energy_closure;
        let residual = solution.enclosure_residual_k[0];
        println!(
            "box C = {capacity} J/K: {last:.4} K, by hand {expected:.4} K ({:.1e} K off); closure {closure:.2e}, \
             fixed-point residual {residual:.1e} K",
            (last - expected).abs()
        );
        assert!(expected > BOX_AIR_K + 10.0);
        assert!((last - expected).abs() < 0.05, "{last} vs {expected} K");
        assert!(closure < 1e-6, "{closure}");
        assert!(residual < 1e-3, "{residual}");
        // The parts' tables hold the node's temperature too.
        let csv = irpol::thermal_scene::part_series(&scene, &solution);
        assert!(csv.iter().any(|s| s.name == "enclosure/inside"));
    }
}

/// `irpol thermal SCENE --out OUT`: (success, stdout, stderr).
fn thermal_cli(dir: &std::path::Path, text: &str) -> (bool, String) {
    let scene = write_scene(dir, text);
    let out = dir.join("out");
    let (ok, _, stderr) = irpol(&[
        "thermal",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!out.exists() || ok, "a refused scene writes nothing");
    (ok, stderr)
}

/// A cabin scene: a plate that is a member of `cabin`, with `member_extra` in its thermal table
/// and `enclosure_table` as `[thermal.enclosures.cabin]`'s keys.
fn cabin_scene(member_extra: &str, enclosure_table: &str) -> String {
    let objects = format!(
        r#"[thermal.enclosures.cabin]
{enclosure_table}

[[objects]]
name = "plate"
shape = {{ kind = "plane", size = [1.0, 1.0], divisions = [1, 1] }}
material = "paint"
temperature_k = 290.0
[objects.thermal]
stack = [["steel", 0.001]]
solar_absorptance = 0.6
{member_extra}
"#
    );
    scene_text("{ temperature_k = 288.0, emissivity = 0.95 }", "", &objects)
}

/// Bad enclosure and ground keys: one line naming the file and the key, nothing written.
#[test]
fn bad_enclosures_and_grounds_are_refused_by_name() {
    let good = "heat_capacity_j_k = 40000.0\nair_exchange_w_k = 15.0";
    let member = "back = { convection_w_m2k = 3.0 }\nenclosure = \"cabin\"";
    let cases: Vec<(String, &str)> = vec![
        (
            cabin_scene("back = { convection_w_m2k = 3.0 }\nenclosure = \"cabn\"", good),
            "objects[0] 'plate' part 'surface': thermal.enclosure: 'cabn' is not defined in \
             [thermal.enclosures] (defined: cabin)",
        ),
        (
            cabin_scene(member, "heat_capacity_j_k = -1.0\nair_exchange_w_k = 15.0"),
            "thermal.enclosures.cabin.heat_capacity_j_k = -1 must be within (0, 1e12] J/K",
        ),
        (
            cabin_scene(member, "heat_capacity_j_k = 4e4\nair_exchange_w_k = -2"),
            "thermal.enclosures.cabin.air_exchange_w_k = -2 must be within [0, 1e9] W/K",
        ),
        (
            cabin_scene(member, "heat_capacity_j_k = 4e4"),
            "missing field `air_exchange_w_k`",
        ),
        (
            cabin_scene(member, &format!("{good}\nvolume_m3 = 3.0")),
            "unknown field `volume_m3`",
        ),
        (
            cabin_scene("enclosure = \"cabin\"", good),
            "thermal.enclosure needs back = { convection_w_m2k = … }",
        ),
        (
            cabin_scene("solar_transmittance = 0.5", good),
            "thermal.solar_transmittance needs enclosure = \"NAME\"",
        ),
        (
            cabin_scene(&format!("{member}\nsolar_transmittance = 0.5"), good),
            "solar_absorptance + solar_transmittance = 0.6 + 0.5 is more than 1",
        ),
        (
            cabin_scene(&format!("{member}\nsolar_transmittance = 1.5"), good),
            "thermal.solar_transmittance = 1.5 must be within [0, 1]",
        ),
        (
            cabin_scene("", good),
            "thermal.enclosures.cabin: no part's thermal table has enclosure = \"cabin\"",
        ),
        (
            scene_text(
                "{ temperature_k = 288.0, emissivity = 0.95, thermal = { stack = [[\"tarmac\", 0.1]], solar_absorptance = 0.9 } }",
                "",
                &slab_and_plate(),
            ),
            "environment.ground.thermal.stack: layer 'tarmac' is not defined in [thermal.layers]",
        ),
        (
            scene_text(
                "{ temperature_k = 288.0, emissivity = 0.95, thermal = { stack = [[\"soil\", 0.1]], solar_absorptance = 0.9, enclosure = \"cabin\" } }",
                "",
                &slab_and_plate(),
            ),
            "environment.ground.thermal.enclosure: the environment's ground has no enclosure",
        ),
    ];
    for (text, expected) in cases {
        let dir = tempfile::tempdir().unwrap();
        let (ok, stderr) = thermal_cli(dir.path(), &text);
        assert!(!ok, "{expected}");
        assert!(stderr.contains(expected), "{expected}: {stderr}");
        assert!(stderr.contains("scene.toml"), "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
}

/// A solved ground needs the run's weather: without `[thermal]` it is refused, by its key.
#[test]
fn a_thermal_ground_needs_a_thermal_section() {
    let dir = tempfile::tempdir().unwrap();
    let text = format!(
        r#"[camera]
position = [0.0, -5.0, 1.0]
look_at = [0.0, 0.0, 0.0]
fov_deg = 30.0
resolution = [16, 12]

[environment]
air_temperature_k = 288.0
sky = {{ model = "window", zenith_emissivity = 0.75 }}
ground = {}
{PAINT}
[[objects]]
shape = {{ kind = "sphere", radius = 1.0, subdivisions = 1 }}
material = "paint"
temperature_k = 300.0
"#,
        thermal_ground()
    );
    let scene = write_scene(dir.path(), &text);
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("environment.ground.thermal needs a [thermal] section"),
        "{stderr}"
    );
    assert!(!out.exists());
}

/// The solved ground's fixed back face is a typed temperature too: below 200 K it is warned
/// about as °C, by its key.
#[test]
fn a_celsius_back_under_the_ground_is_warned_about() {
    let dir = tempfile::tempdir().unwrap();
    let ground = thermal_ground().replace(
        "back = { temperature_k = 288.0 }",
        "back = { temperature_k = 15.0 }",
    );
    let path = write_scene(dir.path(), &scene_text(&ground, "", &slab_and_plate()));
    let warnings = load_scene(&path).unwrap().warnings;
    assert!(
        warnings
            .iter()
            .any(|w| w
                .contains("environment.ground.thermal.back.temperature_k = 15 K looks like °C")),
        "{warnings:?}"
    );
}
