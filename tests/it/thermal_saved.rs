//! A thermal run saved once and rendered from (docs/design.md §2.7, `thermal_scene::saved`): its
//! key ignores the camera and the render settings but follows every thermal input and the run's
//! sample instants; a render from the saved run is bit for bit the render that solves the run
//! itself; a missing, damaged or foreign file is refused with an error naming it.

use crate::common;

use common::thermal_plate_scene;
use irpol::app::render::scene_to_render;
use irpol::app::saved_thermal::{scene_thermal_keys, scene_to_render_from, solve_and_save_scene};
use irpol::app::{one_line, AppError};
use irpol::output::Channel;
use irpol::progress::Silent;
use irpol::render::render;
use irpol::scene::Scene;
use irpol::thermal_scene::saved::FORMAT_VERSION;
use irpol::thermal_scene::{solve_scene, SavedSolutionError};
use std::path::{Path, PathBuf};

const SCENE: &str = "plate.toml";

fn key(text: &str, time_s: f64) -> String {
    let keys = scene_thermal_keys(Path::new(SCENE), text, &[time_s]).unwrap();
    keys[0].as_str().to_owned()
}

fn base() -> String {
    thermal_plate_scene(|s| s)
}

/// `base()` with `from` replaced by `to` (which must occur once).
fn edited(from: &str, to: &str) -> String {
    let text = base();
    assert_eq!(text.matches(from).count(), 1, "{from}");
    text.replace(from, to)
}

#[test]
fn the_key_ignores_the_camera_and_render_settings() {
    let reference = key(&base(), 3600.0);
    assert_eq!(reference.len(), 64);
    let same = [
        edited("position = [6.0, -6.0, 3.0]", "position = [-6.0, 6.0, 2.0]"),
        edited("resolution = [16, 12]", "resolution = [32, 24]"),
        edited("fov_deg = 40.0", "fov_deg = 30.0"),
        format!("{}\n[render]\nsamples = 3\nseed = 7\n", base()),
    ];
    for text in &same {
        assert_eq!(key(text, 3600.0), reference, "{text}");
    }
}

#[test]
fn the_key_follows_every_thermal_input() {
    let changed = [
        edited("air_max_k = 301.0", "air_max_k = 302.0"),
        edited("wind_m_s = 2.0", "wind_m_s = 3.0"),
        edited("latitude_deg = 48.14", "latitude_deg = 48.15"),
        edited(
            "start_utc = \"2026-06-21T00:00:00Z\"",
            "start_utc = \"2026-06-22T00:00:00Z\"",
        ),
        edited("duration_h = 2", "duration_h = 3"),
        edited("output_step_s = 3600", "output_step_s = 1800"),
        edited("conductivity_w_mk = 45.0", "conductivity_w_mk = 46.0"),
        edited(
            "stack = [[\"steel\", 0.001]]",
            "stack = [[\"steel\", 0.002]]",
        ),
        edited("solar_absorptance = 0.6", "solar_absorptance = 0.7"),
        edited("size = [0.5, 0.5]", "size = [0.6, 0.5]"),
        edited(
            "ground = { temperature_k = 290.0, emissivity = 0.95 }",
            "ground = { temperature_k = 291.0, emissivity = 0.95 }",
        ),
        edited("duration_h = 2", "duration_h = 2\nspinup_days = 1"),
        // the part's emissivity is its material's ε_0 unless given
        edited("sigma = 0.2", "sigma = 0.3"),
        edited(
            "solar_absorptance = 0.6",
            "solar_absorptance = 0.6\nemissivity = 0.9",
        ),
    ];
    let mut keys = vec![key(&base(), 3600.0)];
    for text in &changed {
        let k = key(text, 3600.0);
        assert!(!keys.contains(&k), "{text}");
        keys.push(k);
    }
}

#[test]
fn instants_share_a_key_only_on_the_runs_sample_grid() {
    let text = base();
    let on_grid = scene_thermal_keys(Path::new(SCENE), &text, &[0.0, 60.0, 1800.0, 7200.0]);
    let on_grid = on_grid.unwrap();
    assert!(on_grid.iter().all(|k| k == &on_grid[0]), "{on_grid:?}");
    let off_grid = key(&text, 1234.5);
    assert_ne!(off_grid, on_grid[0].as_str());
    assert_ne!(key(&text, 2345.5), off_grid);
    let outside = scene_thermal_keys(Path::new(SCENE), &text, &[7300.0]).unwrap_err();
    assert!(
        one_line(&outside).contains("thermal time 7300 s is outside the run 0…7200 s"),
        "{}",
        one_line(&outside)
    );
}

fn images(scene: &Scene) -> Vec<Vec<u32>> {
    let rendered = render(scene, &Silent).unwrap();
    Channel::ALL
        .iter()
        .map(|&c| {
            let values = rendered.image.channel(c);
            values.iter().map(|v| v.to_bits()).collect()
        })
        .collect()
}

fn bits(values: &[f64]) -> Vec<u64> {
    values.iter().map(|v| v.to_bits()).collect()
}

/// The scene at `time_s` from `file`, and as it is with the run solved for that instant alone.
fn both(text: &str, time_s: f64, file: &Path) -> (Scene, Scene) {
    let path = Path::new(SCENE);
    let saved = scene_to_render_from(path, text, Some(time_s), Some(file), &Silent).unwrap();
    let inline = scene_to_render(path, text, Some(time_s), &Silent).unwrap();
    (saved, inline)
}

#[test]
fn a_saved_run_renders_bit_for_bit_as_solving_each_instant() {
    let dir = tempfile::tempdir().unwrap();
    let text = base();
    let path = Path::new(SCENE);
    let file = dir.path().join("thermal").join("run.bin");
    // One run recording three instants of the grid (one between output steps) serves all three.
    let key = solve_and_save_scene(path, &text, &[7200.0, 1800.0, 3600.0], &file, &Silent);
    let key = key.unwrap();
    assert_eq!(key.as_str(), self::key(&text, 1800.0));
    for time_s in [1800.0, 3600.0, 7200.0] {
        let (saved, inline) = both(&text, time_s, &file);
        assert_eq!(
            bits(&saved.mesh.temperatures),
            bits(&inline.mesh.temperatures)
        );
        assert_ne!(saved.mesh.temperatures, base_temperatures(&text));
        assert_eq!(
            saved.air_temperature_k.to_bits(),
            inline.air_temperature_k.to_bits()
        );
        assert_eq!(images(&saved), images(&inline), "t = {time_s} s");
    }
    // An instant off the grid is a run of its own, and the same bit for bit.
    let off = dir.path().join("off.bin");
    solve_and_save_scene(path, &text, &[1234.5], &off, &Silent).unwrap();
    let (saved, inline) = both(&text, 1234.5, &off);
    assert_eq!(images(&saved), images(&inline));
    let error = solve_and_save_scene(path, &text, &[1234.5, 3600.0], &off, &Silent).unwrap_err();
    assert!(
        matches!(
            &error,
            AppError::SavedSolution(e) if matches!(**e, SavedSolutionError::SeparateRuns { .. })
        ),
        "{error:?}"
    );
}

/// Why instants off the sample grid get keys of their own: recording one changes the run's steps,
/// and so the temperatures at the other instants (in their last bits).
#[test]
fn an_instant_off_the_grid_changes_the_run_at_the_others() {
    let scene = irpol::scene::load_scene_text(Path::new(SCENE), &base()).unwrap();
    let at = |extra: &[f64]| {
        let run = solve_scene(&scene, extra, &Silent).unwrap();
        let i = run.times_s.iter().position(|&t| t == 3600.0).unwrap();
        bits(&run.surface_k[i])
    };
    assert_eq!(at(&[3600.0]), at(&[1800.0, 3600.0, 60.0]));
    assert_ne!(at(&[3600.0]), at(&[1234.5, 3600.0]));
}

/// The typed starting temperatures of the plate (what a solved run must differ from).
fn base_temperatures(text: &str) -> Vec<f64> {
    irpol::scene::load_scene_text(Path::new(SCENE), text)
        .unwrap()
        .mesh
        .temperatures
}

/// The error of rendering the plate at `time_s` from `file`, and its one-line message.
fn refusal(text: &str, time_s: f64, file: &Path) -> (AppError, String) {
    let error = scene_to_render_from(Path::new(SCENE), text, Some(time_s), Some(file), &Silent)
        .expect_err("refused");
    let message = one_line(&error);
    assert!(message.contains(&file.display().to_string()), "{message}");
    assert!(!message.contains('\n'), "{message}");
    (error, message)
}

fn rewritten(dir: &Path, name: &str, bytes: &[u8]) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn missing_damaged_and_foreign_solutions_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let text = base();
    let file = dir.path().join("run.bin");
    solve_and_save_scene(Path::new(SCENE), &text, &[3600.0], &file, &Silent).unwrap();
    let good = std::fs::read(&file).unwrap();

    let (error, message) = refusal(&text, 3600.0, &dir.path().join("none.bin"));
    assert!(error.is_io() && message.contains("cannot read the thermal solution"));

    let mut flipped = good.clone();
    let last = flipped.len() - 9;
    flipped[last] ^= 0x40;
    let (_, message) = refusal(&text, 3600.0, &rewritten(dir.path(), "flip.bin", &flipped));
    assert!(message.contains("checksum does not match"), "{message}");
    let cut = rewritten(dir.path(), "cut.bin", &good[..good.len() / 2]);
    assert!(refusal(&text, 3600.0, &cut)
        .1
        .contains("length does not match"));
    let header = rewritten(dir.path(), "header.bin", &good[..40]);
    assert!(refusal(&text, 3600.0, &header).1.contains("cut short"));
    let other = rewritten(dir.path(), "other.bin", b"time_s,air_k\n0,290\n");
    assert!(refusal(&text, 3600.0, &other)
        .1
        .contains("not a thermal solution"));
    let mut newer = good.clone();
    newer[16..20].copy_from_slice(&(FORMAT_VERSION + 1).to_le_bytes());
    let (_, message) = refusal(&text, 3600.0, &rewritten(dir.path(), "v.bin", &newer));
    assert!(
        message.contains("of format 2, this irpol reads format 1"),
        "{message}"
    );

    // The run of another weather is refused, not used; so is an instant it did not record.
    let warmer = text.replace("air_max_k = 301.0", "air_max_k = 305.0");
    let (error, message) = refusal(&warmer, 3600.0, &file);
    assert!(
        matches!(&error, AppError::SavedSolution(e) if matches!(**e, SavedSolutionError::KeyMismatch { .. })),
        "{message}"
    );
    assert!(
        message.contains("solved for other thermal inputs"),
        "{message}"
    );
    assert!(refusal(&text, 1234.5, &file)
        .1
        .contains("for other thermal inputs"));
    let (_, message) = refusal(&text, 1800.0, &file);
    assert!(message.contains("records no t = 1800 s"), "{message}");
}
