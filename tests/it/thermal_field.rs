//! Terrain tiles solved as fields (docs/design.md §1.8 at terrain scale): the vertices of an
//! upright terrain tile are marched in blocks by the batched solver, with what they see from the
//! tile's horizon map; every other vertex as before. Checked against the same scene solved vertex
//! by vertex (rays and the adaptive solver), which is what the scene was before fields existed.

use crate::common;

use common::write_scene;
use irpol::progress::Silent;
use irpol::scene::{load_scene, Scene};
use irpol::thermal_scene::{solve_scene, vertex_surfaces, ThermalSolution};

/// A ball over a rough 8 m terrain tile of 32 × 32 cells (rms slope √2·0.2/1.0 ≈ 0.28), on a
/// clear midsummer morning in Munich.
const SCENE: &str = r#"[camera]
position = [6.0, -6.0, 3.0]
look_at = [0.0, 0.0, 0.5]
fov_deg = 40.0
resolution = [32, 24]

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
rho_d = 0.02
shadowing = "smith"

[thermal]
weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }
start_utc = "2026-06-21T03:00:00Z"
duration_h = 9
latitude_deg = 48.14
longitude_deg = 11.58
output_step_s = 3600

[thermal.layers.paint]
conductivity_w_mk = 0.2
density_kg_m3 = 1200.0
heat_capacity_j_kgk = 1500.0

[thermal.layers.steel]
conductivity_w_mk = 45.0
density_kg_m3 = 7850.0
heat_capacity_j_kgk = 470.0

[thermal.layers.soil]
conductivity_w_mk = 1.0
density_kg_m3 = 1600.0
heat_capacity_j_kgk = 1000.0

[[objects]]
name = "ball"
shape = { kind = "sphere", radius = 0.5, subdivisions = 2 }
translate = [0.0, 0.0, 1.2]
material = "paint"
[objects.thermal]
stack = [["paint", 0.0001], ["steel", 0.001]]
back = { convection_w_m2k = 3.0 }
solar_absorptance = 0.6

[[objects]]
name = "field"
shape = { kind = "terrain", size = [8.0, 8.0], divisions = [32, 32], rms_height_m = 0.2, correlation_length_m = 1.0, seed = 3 }
material = "paint"
temperature_k = 289.0
[objects.thermal]
stack = [["soil", 0.1]]
back = { temperature_k = 289.0 }
solar_absorptance = 0.8
"#;

/// The scene solved as it comes (the tile as a field), and solved with the tile forgotten as a
/// heightfield (its vertices one by one, with rays).
fn both_ways() -> (Scene, ThermalSolution, ThermalSolution) {
    let dir = tempfile::tempdir().unwrap();
    let path = write_scene(dir.path(), SCENE);
    let scene = load_scene(&path).unwrap();
    assert_eq!(
        scene.heightfields.len(),
        1,
        "the upright tile is a heightfield"
    );
    let field = solve_scene(&scene, &[], &Silent).unwrap();
    let mut one_by_one = load_scene(&path).unwrap();
    one_by_one.heightfields.clear();
    let reference = solve_scene(&one_by_one, &[], &Silent).unwrap();
    (scene, field, reference)
}

/// Mean, 99th percentile and largest |ΔT| over the recorded instants of the vertices `of`
/// selects.
fn differences(
    a: &ThermalSolution,
    b: &ThermalSolution,
    of: impl Fn(usize) -> bool,
) -> (f64, f64, f64) {
    let mut d: Vec<f64> = (a.surface_k.iter().zip(&b.surface_k))
        .flat_map(|(ra, rb)| {
            (0..ra.len())
                .filter(|&v| of(v))
                .map(move |v| (ra[v] - rb[v]).abs())
        })
        .collect();
    d.sort_by(f64::total_cmp);
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    (mean, d[d.len() * 99 / 100], d[d.len() - 1])
}

/// A flat tile: the horizon map and the rays see the same (nothing but the ball), so what is left
/// is the batched fixed-step solver on its grid against the adaptive one on the default grid
/// (measured: mean 0.5 mK, largest 6 mK).
#[test]
fn a_flat_field_is_the_adaptive_solution_within_ten_millikelvin() {
    let dir = tempfile::tempdir().unwrap();
    let path = write_scene(
        dir.path(),
        &SCENE.replace("rms_height_m = 0.2", "rms_height_m = 0.0"),
    );
    let scene = load_scene(&path).unwrap();
    let field = solve_scene(&scene, &[], &Silent).unwrap();
    let mut one_by_one = load_scene(&path).unwrap();
    one_by_one.heightfields.clear();
    let reference = solve_scene(&one_by_one, &[], &Silent).unwrap();
    let (mean, _, worst) = differences(&field, &reference, |_| true);
    eprintln!("flat: mean |ΔT| {mean:.2e} K, largest {worst:.2e} K");
    assert!(
        mean < 1e-3 && worst < 1e-2,
        "flat: mean {mean} K, largest {worst} K"
    );
}

#[test]
fn a_terrain_field_agrees_with_its_vertices_solved_one_by_one() {
    let (scene, field, reference) = both_ways();
    let surfaces = vertex_surfaces(&scene);
    let terrain = scene.heightfields[0].surface;
    assert_eq!(field.times_s, reference.times_s);
    assert_eq!(
        field.stats.thermal_vertices,
        reference.stats.thermal_vertices
    );
    // Where the two differ by more than a few tenths of a kelvin, the sun is seen by one and not
    // the other at a shadow instant: a low sun between two of the horizon map's azimuths, or a
    // ray grazing a neighbouring facet of the vertex (rays leave along the smooth normal, so the
    // planes of the adjacent facets are thin lines of false shadow in the rays' sky).
    let (mean, p99, worst) = differences(&field, &reference, |v| surfaces[v] == terrain);
    eprintln!("terrain: mean |ΔT| {mean:.4} K, 99 % below {p99:.3} K, largest {worst:.3} K");
    assert!(
        mean < 0.05 && p99 < 1.0,
        "terrain: mean {mean} K, 99 % {p99} K"
    );
    // The ball sees the tile through its horizon map instead of rays.
    let (mean, p99, worst) = differences(&field, &reference, |v| surfaces[v] != terrain);
    eprintln!("ball: mean |ΔT| {mean:.4} K, 99 % below {p99:.3} K, largest {worst:.3} K");
    assert!(
        mean < 0.02 && worst < 0.3,
        "ball: mean {mean} K, largest {worst} K"
    );
    // The morning sun warmed the soil: the field is not just its starting state.
    let last = field.surface_k.last().unwrap();
    let warmest = (0..last.len())
        .filter(|&v| surfaces[v] == terrain)
        .map(|v| last[v])
        .fold(0.0, f64::max);
    assert!(warmest > 300.0, "the noon field peaks at {warmest} K");
    assert!(field.stats.worst_energy_closure < 1e-6, "{:?}", field.stats);
}

/// A sphere and, after it, a terrain object turned by `rotate_deg`.
fn terrain_scene(rotate_deg: &str) -> String {
    format!(
        "[camera]\nposition = [0.0, -4.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\n\
         fov_deg = 36.0\nresolution = [8, 8]\n\
         [environment]\nair_temperature_k = 283.15\n\
         sky = {{ model = \"window\", zenith_emissivity = 0.75 }}\n\
         ground = {{ temperature_k = 288.0, emissivity = 0.95 }}\n\
         [materials.m]\ndistribution = \"cauchy\"\nsigma = 0.2\nq = 2.0\nn = 1.5\nk = 0.1\n\
         [[objects]]\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 1 }}\n\
         material = \"m\"\ntemperature_k = 300.0\n\
         [[objects]]\nname = \"ground\"\nmaterial = \"m\"\ntemperature_k = 290.0\n\
         shape = {{ kind = \"terrain\", size = [8.0, 6.0], divisions = [16, 10], \
         rms_height_m = 0.2, correlation_length_m = 2.0, seed = 3 }}\n\
         scale = 2.0\ntranslate = [1.0, 2.0, -0.5]\nrotate_deg = {rotate_deg}\n"
    )
}

#[test]
fn an_upright_terrain_is_kept_as_a_heightfield_and_a_tilted_one_is_not() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load_scene(&write_scene(dir.path(), &terrain_scene("[0.0, 0.0, 40.0]"))).unwrap();
    let [field] = scene.heightfields.as_slice() else {
        panic!("{} heightfields", scene.heightfields.len());
    };
    assert_eq!(scene.surfaces[field.surface as usize].object, 1);
    assert_eq!(field.divisions, [16, 10]);
    assert_eq!(field.cell_m, [1.0, 1.2]);
    // Every vertex of the terrain's surface is a grid point at its own height, and every grid
    // point is one of them.
    let mut seen = [false; 17 * 11];
    for (t, triangle) in scene.mesh.triangles.iter().enumerate() {
        let on_terrain = scene.mesh.triangle_surface[t] == field.surface;
        for &v in triangle {
            let p = scene.mesh.positions[v as usize];
            let g = field.grid_point(&p);
            assert_eq!(g.is_some(), on_terrain, "vertex {v} at {p:?}");
            if let Some(g) = g {
                assert_eq!(field.heights_m[g], p.z);
                seen[g] = true;
            }
        }
    }
    assert!(seen.iter().all(|&s| s));
    let tilted = write_scene(dir.path(), &terrain_scene("[0.0, 3.0, 40.0]"));
    assert!(load_scene(&tilted).unwrap().heightfields.is_empty());
}
