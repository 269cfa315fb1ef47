//! What a thermal scene's keys mean when they are probably a mistake: a temperature in °C in any
//! temperature key is warned about by name (the library returns the warning, the binary prints
//! it), and a table written as an array is refused instead of read field by field.

use crate::common;

use common::{irpol, thermal_plate_scene as scene, write_scene};
use irpol::scene::load_scene;

/// The scene's warnings from the library, and the binary's stderr of `irpol thermal`.
fn warnings(text: &str, files: &[(&str, &str)]) -> (Vec<String>, String) {
    let dir = tempfile::tempdir().unwrap();
    for (name, content) in files {
        std::fs::write(dir.path().join(name), content).unwrap();
    }
    let path = write_scene(dir.path(), text);
    let loaded = load_scene(&path).unwrap().warnings;
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "thermal",
        path.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    (loaded, stderr)
}

#[test]
fn every_temperature_key_below_200_k_is_warned_about_as_celsius() {
    let text = scene(|s| {
        s.replace("air_temperature_k = 290.0", "air_temperature_k = 15.0")
            .replace(
                "{ temperature_k = 290.0, emissivity",
                "{ temperature_k = 17.0, emissivity",
            )
            .replace(
                "air_min_k = 287.0, air_max_k = 301.0",
                "air_min_k = 14.0, air_max_k = 28.0",
            )
            .replace(
                "duration_h = 2",
                "duration_h = 2\nground_temperature_k = 16.5",
            )
            .replace(
                "solar_absorptance = 0.6",
                "solar_absorptance = 0.6\nback = { temperature_k = 20.0 }",
            )
            .replace(
                "material = \"paint\"",
                "material = \"paint\"\ntemperature_k = 18.0",
            )
    });
    let (loaded, stderr) = warnings(&text, &[]);
    let expected = [
        "environment.air_temperature_k = 15 K looks like °C (temperatures are kelvin: 15 °C is 288.15 K)",
        "environment.ground.temperature_k = 17 K looks like °C",
        "thermal.ground_temperature_k = 16.5 K looks like °C",
        "thermal.weather.clear_day.air_min_k = 14 K looks like °C",
        "thermal.weather.clear_day.air_max_k = 28 K looks like °C (temperatures are kelvin: 28 °C is 301.15 K)",
        "objects[0] 'plate': temperature_k = 18 K looks like °C",
        "objects[0] 'plate': thermal.back.temperature_k = 20 K looks like °C",
    ];
    for needle in expected {
        assert_eq!(
            loaded.iter().filter(|w| w.contains(needle)).count(),
            1,
            "{needle}: {loaded:?}"
        );
        assert!(
            stderr.contains(&format!("irpol: warning: {needle}")),
            "{needle}: {stderr}"
        );
    }
    assert_eq!(loaded.len(), expected.len(), "{loaded:?}");
    // Kelvin draws no warning.
    let (loaded, stderr) = warnings(&scene(|s| s), &[]);
    assert!(
        loaded.is_empty() && !stderr.contains("warning"),
        "{loaded:?} {stderr}"
    );
}

#[test]
fn a_weather_file_in_celsius_is_warned_about_once() {
    let text = scene(|s| {
        s.replace(
            "weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }",
            "weather = \"weather.csv\"",
        )
    });
    let weather = "time_s,air_temperature_k\n0,12.5\n3600,15\n7200,18\n";
    let (loaded, stderr) = warnings(&text, &[("weather.csv", weather)]);
    let needle = "thermal.weather 'weather.csv': air temperatures down to 12.5 K look like °C";
    assert_eq!(loaded.len(), 1, "{loaded:?}");
    assert!(loaded[0].starts_with(needle), "{loaded:?}");
    assert_eq!(stderr.matches(needle).count(), 1, "{stderr}");
}

#[test]
fn a_table_written_as_an_array_is_refused_not_read_field_by_field() {
    // `ground = [0.0, 0.0, 0.0]` was read as { temperature_k = 0, emissivity = 0 }: a 0 K ground.
    let cases = [
        ("ground = { temperature_k = 290.0, emissivity = 0.95 }", "ground = [0.0, 0.0, 0.0]", "line 10, column 10: invalid type: sequence, expected a table"),
        ("ground = { temperature_k = 290.0, emissivity = 0.95 }", "ground = [290.0, 0.95]", "line 10, column 10: invalid type: sequence, expected a table"),
        ("sky = { model = \"window\", zenith_emissivity = 0.75 }", "sky = [\"window\", 0.75]", "line 9, column 7: invalid type: sequence, expected a table"),
        ("shape = { kind = \"plane\", size = [0.5, 0.5], divisions = [1, 1] }", "shape = [\"sphere\", 1.0, 2]", "expected a table"),
        ("[thermal.layers.steel]\nconductivity_w_mk = 45.0\ndensity_kg_m3 = 7850.0\nheat_capacity_j_kgk = 470.0", "[thermal.layers]\nsteel = [45.0, 7850.0, 470.0]", "expected a table"),
        ("{ clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }", "{ clear_day = [287.0, 301.0, 2.0] }", "a weather CSV path, or { clear_day = {"),
        ("solar_absorptance = 0.6", "solar_absorptance = 0.6\nback = [300.0]", "\"adiabatic\", { temperature_k = … } or { convection_w_m2k = … }"),
    ];
    for (from, to, needle) in cases {
        let text = scene(|s| s.replace(from, to));
        assert_ne!(text, scene(|s| s), "{from}");
        let dir = tempfile::tempdir().unwrap();
        let path = write_scene(dir.path(), &text);
        let error = load_scene(&path).unwrap_err().to_string();
        assert!(
            error.contains("not a valid scene") && error.contains(needle),
            "{to}: {error}"
        );
        let out = dir.path().join("out");
        let (ok, _, stderr) = irpol(&[
            "thermal",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(!ok && stderr.contains(needle), "{stderr}");
        assert!(!out.exists());
    }
}
