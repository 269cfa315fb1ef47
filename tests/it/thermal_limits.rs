//! The thermal model's resource limits and solver cap (docs/thermal.md "Limits"): inputs that once
//! panicked, asked for terabytes or ran for hours are refused up front in one short line that
//! names the key and says each thing once, with numbers written concisely. Every run is under a
//! 4 GB address-space limit and a time limit, so a regression fails the test instead of the machine.

use crate::common;

use common::thermal_plate_scene as scene;
use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const TIME_LIMIT: Duration = Duration::from_secs(60);
const MEMORY_LIMIT_KB: u64 = 4_000_000;

/// The binary under test: `IRPOL_BIN` (e.g. an older build, to see the cases fail) or this one.
fn binary() -> std::path::PathBuf {
    std::env::var_os("IRPOL_BIN")
        .map(Into::into)
        .unwrap_or_else(|| env!("CARGO_BIN_EXE_irpol").into())
}

/// `irpol thermal scene.toml --out out` in `dir` under the limits: (exit code, stderr, seconds).
fn thermal(dir: &Path) -> (Option<i32>, String, f64) {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {MEMORY_LIMIT_KB} 2>/dev/null; exec \"$0\" \"$@\""
        ))
        .arg(binary())
        .args(["thermal", "scene.toml", "--out", "out"])
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let err = std::thread::spawn(move || {
        let mut text = String::new();
        let _ = stderr.read_to_string(&mut text);
        text
    });
    let start = Instant::now();
    let code = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break status.code();
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            panic!("irpol thermal hung (killed after {TIME_LIMIT:?})");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    (code, err.join().unwrap(), start.elapsed().as_secs_f64())
}

/// The scene (and `files`) refused in one short line holding every `needles`, nothing written,
/// no part of the message said twice, no number longer than 20 characters.
fn refused(text: &str, files: &[(&str, &str)], needles: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("scene.toml"), text).unwrap();
    for (name, content) in files {
        std::fs::write(dir.path().join(name), content).unwrap();
    }
    let (code, stderr, _) = thermal(dir.path());
    assert_eq!(code, Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    let line = stderr.trim_end();
    assert!(
        line.starts_with("irpol: error: ") && !line.contains('\n') && line.len() < 400,
        "{stderr}"
    );
    for needle in needles {
        assert!(line.contains(needle), "{line:?} lacks {needle:?}");
    }
    assert_says_each_thing_once(line);
    let longest_number = line
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == 'e' || c == '-'))
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest_number <= 20, "a long number in {line:?}");
    assert!(!dir.path().join("out").exists());
    line.to_owned()
}

/// No segment of a `a: b: c` message is repeated.
fn assert_says_each_thing_once(line: &str) {
    let segments: Vec<&str> = line.split(": ").filter(|s| s.len() > 8).collect();
    for (i, s) in segments.iter().enumerate() {
        assert!(!segments[i + 1..].contains(s), "'{s}' twice in {line:?}");
    }
}

#[test]
fn output_steps_beyond_the_limit_are_refused_before_anything_is_allocated() {
    // Once a capacity-overflow panic (1e-300) and a request for 3.5e14 bytes (1e-9).
    for step in ["1e-300", "1e-9", "0.1"] {
        let text = scene(|s| s.replace("output_step_s = 3600", &format!("output_step_s = {step}")));
        refused(
            &text,
            &[],
            &[
                "thermal.output_step_s = ",
                "steps over the run of 7200 s (at most 15000)",
            ],
        );
    }
    let text = scene(|s| s.replace("output_step_s = 3600", "time_step_s = 1e-3"));
    refused(
        &text,
        &[],
        &["thermal.time_step_s = 0.001 s makes 7.2e6 steps"],
    );
    let text = scene(|s| s.replace("duration_h = 2", "spinup_days = 4000000000"));
    refused(
        &text,
        &[],
        &["thermal.spinup_days = 4000000000 is more than 100 days"],
    );
}

#[test]
fn layers_beyond_the_physical_limits_are_refused_by_name() {
    // A subnormal thickness once asked for 2 GB of grid; 1e12 W/m/K ran 40 s for a day of one
    // plate (the round-off defeats the implicit steps) and closed its energy to 100 %.
    let cases = [
        (
            "[[\"steel\", 5e-324]]",
            "thickness = 5e-324 m is outside 1e-6…100 m",
        ),
        (
            "[[\"steel\", 1e9]]",
            "thickness = 1e9 m is outside 1e-6…100 m",
        ),
    ];
    for (stack, needle) in cases {
        let text =
            scene(|s| s.replace("stack = [[\"steel\", 0.001]]", &format!("stack = {stack}")));
        refused(
            &text,
            &[],
            &[
                "objects[0] 'plate' part 'surface': thermal.stack: layer 1 ('steel'): ",
                needle,
            ],
        );
    }
    let cases = [
        (
            "conductivity_w_mk = 45.0",
            "conductivity_w_mk = 1e12",
            "conductivity = 1e12 W/m/K is outside 0.001…10000 W/m/K",
        ),
        (
            "density_kg_m3 = 7850.0",
            "density_kg_m3 = 1e-300",
            "density = 1e-300 kg/m^3 is outside 0.1…100000 kg/m^3",
        ),
        (
            "heat_capacity_j_kgk = 470.0",
            "heat_capacity_j_kgk = 1e300",
            "heat capacity = 1e300 J/kg/K is outside 10…100000 J/kg/K",
        ),
    ];
    for (from, to, needle) in cases {
        let text = scene(|s| {
            s.replace(from, to)
                .replace("duration_h = 2", "duration_h = 24")
        });
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("scene.toml"), &text).unwrap();
        let (_, _, seconds) = thermal(dir.path());
        assert!(seconds < 5.0, "{to}: {seconds} s");
        refused(&text, &[], &[needle]);
    }
}

#[test]
fn weather_beyond_its_limits_is_refused_at_its_line() {
    // Sky long-wave of 9e18 W/m² once drove the surface to 3.5 million K.
    let weather = "time_s,air_temperature_k,longwave_down_w_m2,wind_speed_m_s\n\
                   0,290,300,2\n3600,290,9e18,2\n7200,290,300,2\n";
    let text = scene(|s| {
        s.replace(
            "weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }",
            "weather = \"weather.csv\"",
        )
    });
    refused(
        &text,
        &[("weather.csv", weather)],
        &["weather.csv:3:10: column 'longwave_down_w_m2': 9e18 W/m² is outside 0…100000 W/m²"],
    );
    let windy = weather.replace("9e18,2", "300,1e300");
    refused(
        &text,
        &[("weather.csv", &windy)],
        &["weather.csv:3:14: column 'wind_speed_m_s': 1e300 m/s is outside 0…150 m/s"],
    );
    let text = scene(|s| s.replace("wind_m_s = 2.0", "wind_m_s = 1e300"));
    refused(
        &text,
        &[],
        &["thermal.weather.clear_day: wind_m_s = 1e300 is outside 0…150 m/s"],
    );
    let text = scene(|s| s.replace("air_max_k = 301.0", "air_max_k = 1e-300"));
    let line = refused(
        &text,
        &[],
        &["air_min_k = 287 K is above air_max_k = 1e-300 K"],
    );
    assert!(!line.contains("clear day: "), "{line}");
}

#[test]
fn part_keys_beyond_their_limits_are_refused() {
    let cases = [
        (
            "internal_heat_w_m2 = -1e300",
            "internal_heat_w_m2 has a point [0 h, -1e300 W/m²] outside",
        ),
        (
            "convection_w_m2k = 1e300",
            "convection_w_m2k = 1e300 W/m²/K is outside 0…100000",
        ),
        (
            "back = { convection_w_m2k = 1e300 }",
            "back.convection_w_m2k = 1e300 W/m²/K is outside",
        ),
    ];
    for (key, needle) in cases {
        let text = scene(|s| {
            s.replace(
                "solar_absorptance = 0.6",
                &format!("solar_absorptance = 0.6\n{key}"),
            )
        });
        refused(&text, &[], &[needle]);
    }
}

#[test]
fn solver_failures_name_the_part_and_the_step_once() {
    // Once: "part 'surface': thermal solver: surface balance has no positive temperature (B = …,
    // D = -5995…<300 digits>): thermal solver: surface balance … (the same again)".
    let text = scene(|s| {
        s.replace(
            "solar_absorptance = 0.6",
            "solar_absorptance = 0.6\ninternal_heat_w_m2 = -1e6",
        )
    });
    let line = refused(
        &text,
        &[],
        &[
            "scene.toml: thermal run: objects[0] 'plate' part 'surface', step from t = 0 s: ",
            "no positive surface temperature balances the heat flows",
        ],
    );
    assert_eq!(line.matches("thermal").count(), 1, "{line}");
}

#[test]
fn tables_of_vertices_by_instants_beyond_their_limits_are_refused() {
    let fine = |s: String| s.replace("divisions = [1, 1]", "divisions = [200, 200]");
    let text = scene(|s| fine(s).replace("output_step_s = 3600", "shadow_step_s = 0.01"));
    refused(
        &text,
        &[],
        &["40401 thermal vertices × 720001 shadow instants = 2.91e10 values, more than 5e8"],
    );
    let text = scene(|s| fine(s).replace("output_step_s = 3600", "output_step_s = 1"));
    refused(
        &text,
        &[],
        &["40401 vertices × 7202 recorded instants = 2.91e8 values, more than 1e8"],
    );
}

#[test]
fn echoed_numbers_are_written_concisely() {
    // Rust writes 1e300 as 301 digits; each of these messages once did.
    let cases = [
        (
            "fov_deg = 40.0",
            "fov_deg = 1e300",
            "camera fov_deg = 1e300 must be",
        ),
        (
            "zenith_emissivity = 0.75",
            "zenith_emissivity = 1e300",
            "zenith_emissivity = 1e300 must be",
        ),
        (
            "emissivity = 0.95 }",
            "emissivity = -1e300 }",
            "ground.emissivity = -1e300 must be",
        ),
        (
            "latitude_deg = 48.14",
            "latitude_deg = 1e300",
            "thermal.latitude_deg = 1e300 must be",
        ),
        (
            "duration_h = 2",
            "duration_h = -1e300",
            "thermal.duration_h = -1e300 must be positive",
        ),
        (
            "[[objects]]",
            "[sensor]\nnetd_mk = -1e300\n\n[[objects]]",
            "sensor.netd_mk = -1e300 must be",
        ),
        (
            "[[objects]]",
            "[render]\naop_mask_dolp = 1e300\n\n[[objects]]",
            "render.aop_mask_dolp = 1e300 must be",
        ),
    ];
    for (from, to, needle) in cases {
        let text = scene(|s| s.replacen(from, to, 1));
        refused(&text, &[], &[needle]);
    }
}
