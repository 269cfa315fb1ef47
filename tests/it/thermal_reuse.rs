//! `irpol thermal` saves its run by content key beside its output folder
//! (`out/thermal/<key>.bin`) and `irpol render` at an instant of the run reuses it instead
//! of solving again, saying so; a changed scene has another key and is solved; `--thermal FILE`
//! takes a run from a file and refuses another scene's. A single instant and a series rendered
//! into one folder keep each other's files.

use crate::common;

use common::thermal_plate_scene;
use std::path::Path;

/// `irpol ARGS` run in `dir`: (success, stderr).
fn irpol_in(dir: &Path, args: &[&str]) -> (bool, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run irpol");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// The saved runs in `dir/out/thermal/`.
fn saved_runs(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir.join("out/thermal"))
        .map(|entries| {
            entries
                .flatten()
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}

#[test]
fn render_reuses_the_run_irpol_thermal_saved_and_solves_a_changed_scene() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("plate.toml"), thermal_plate_scene(|s| s)).unwrap();

    let (ok, stderr) = irpol_in(d, &["thermal", "plate.toml"]);
    assert!(ok, "{stderr}");
    let runs = saved_runs(d);
    assert_eq!(runs.len(), 1, "{runs:?}");
    let file = format!("out/thermal/{}", runs[0]);
    assert!(
        stderr.contains("thermal run solved in") && stderr.contains(&format!("saved to {file}")),
        "{stderr}"
    );

    // An instant on the run's grid: the saved run, no solve.
    let (ok, stderr) = irpol_in(
        d,
        &["render", "plate.toml", "--time-utc", "2026-06-21T01:00:00Z"],
    );
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains(&format!("thermal run reused from {file}")),
        "{stderr}"
    );
    assert!(!stderr.contains("thermal run solved"), "{stderr}");
    assert!(d.join("out/plate/S0.tif").is_file());
    // A series on the grid reuses it too.
    let (ok, stderr) = irpol_in(d, &["render", "plate.toml", "--times", "0:7200:3600"]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("thermal run reused from"), "{stderr}");
    // The single instant rendered before the series is still there beside the series.
    assert!(d.join("out/plate/S0.tif").is_file() && d.join("out/plate/summary.json").is_file());
    assert!(d.join("out/plate/001_3600s/S0.tif").is_file());
    // And a single instant again keeps the series.
    let (ok, stderr) = irpol_in(d, &["render", "plate.toml", "--time", "7200"]);
    assert!(ok, "{stderr}");
    assert!(
        d.join("out/plate/002_7200s/S0.tif").is_file() && d.join("out/plate/preview.gif").is_file()
    );

    // Other weather: another key, solved (not the stale run) and saved beside the first.
    let warmer = thermal_plate_scene(|s| s.replace("air_max_k = 301.0", "air_max_k = 305.0"));
    std::fs::write(d.join("plate.toml"), warmer).unwrap();
    let (ok, stderr) = irpol_in(d, &["render", "plate.toml", "--time", "3600"]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("thermal run solved in"), "{stderr}");
    assert!(!stderr.contains("reused"), "{stderr}");
    assert_eq!(saved_runs(d).len(), 2);

    // --thermal FILE: the first run belongs to the other weather, and is refused by name.
    let (ok, stderr) = irpol_in(
        d,
        &["render", "plate.toml", "--time", "3600", "--thermal", &file],
    );
    assert!(!ok);
    assert!(
        stderr.contains(&file) && stderr.contains("solved for other thermal inputs"),
        "{stderr}"
    );
}

#[test]
fn a_damaged_saved_run_is_solved_again_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("plate.toml"), thermal_plate_scene(|s| s)).unwrap();
    let (ok, stderr) = irpol_in(d, &["thermal", "plate.toml"]);
    assert!(ok, "{stderr}");
    let file = d.join("out/thermal").join(&saved_runs(d)[0]);
    let mut bytes = std::fs::read(&file).unwrap();
    let last = bytes.len() - 1;
    bytes[last] ^= 0xff;
    std::fs::write(&file, bytes).unwrap();
    let (ok, stderr) = irpol_in(d, &["render", "plate.toml", "--time", "3600"]);
    assert!(ok, "{stderr}");
    assert!(
        stderr.contains("irpol: warning: ")
            && stderr.contains("damaged thermal solution")
            && stderr.contains("(solving it again)")
            && stderr.contains("thermal run solved in"),
        "{stderr}"
    );
    // Solved again and saved whole: the next render reuses it.
    let (ok, stderr) = irpol_in(d, &["render", "plate.toml", "--time", "3600"]);
    assert!(ok && stderr.contains("thermal run reused from"), "{stderr}");
}
