//! Interrupting `irpol thermal`: SIGTERM or SIGKILL at any moment (loading, solving, writing)
//! leaves the output folder holding the complete old set or the complete new one, SIGTERM leaves
//! no staging folder, and the next run removes a SIGKILLed one's.

use crate::common;

use common::{irpol, thermal_plate_scene};
use std::path::Path;
use std::process::Command;
use std::time::Duration;

/// A ball of 642 vertices (as many distinct solves) over a day: a few seconds of solving.
fn scene_text(absorptance: f64) -> String {
    thermal_plate_scene(|s| {
        s.replace("duration_h = 2", "duration_h = 24")
            .replace(
                "shape = { kind = \"plane\", size = [0.5, 0.5], divisions = [1, 1] }",
                "shape = { kind = \"sphere\", radius = 0.5, subdivisions = 3 }",
            )
            .replace(
                "solar_absorptance = 0.6",
                &format!("solar_absorptance = {absorptance}"),
            )
    })
}

/// Every file the folder's summary lists is there, and temperatures.csv is one run's (old or
/// new, told apart by their absorptance).
fn complete_set(out: &Path, old_csv: &[u8], new_csv: &[u8]) -> bool {
    let Ok(summary) = std::fs::read(out.join("summary.json")) else {
        return false;
    };
    let summary: serde_json::Value = serde_json::from_slice(&summary).unwrap();
    let all_there = summary["files"]
        .as_array()
        .unwrap()
        .iter()
        .all(|f| out.join(f.as_str().unwrap()).is_file());
    let csv = std::fs::read(out.join("temperatures.csv")).unwrap_or_default();
    all_there && (csv == old_csv || csv == new_csv)
}

/// Staging folders left beside the output folder.
fn staging(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.contains("irpol-staging"))
        .collect()
}

#[test]
fn an_interrupted_thermal_run_leaves_the_old_or_the_new_set() {
    let dir = tempfile::tempdir().unwrap();
    let (old_scene, new_scene) = (dir.path().join("old.toml"), dir.path().join("new.toml"));
    std::fs::write(&old_scene, scene_text(0.6)).unwrap();
    std::fs::write(&new_scene, scene_text(0.3)).unwrap();
    let out = dir.path().join("out");
    let run = |scene: &Path| {
        let (ok, _, err) = irpol(&[
            "thermal",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        std::fs::read(out.join("temperatures.csv")).unwrap()
    };
    let start = std::time::Instant::now();
    let new_csv = run(&new_scene);
    let run_ms = start.elapsed().as_millis() as u64;
    let old_csv = run(&old_scene);
    assert_ne!(old_csv, new_csv);
    let signals = ["TERM", "KILL", "TERM", "KILL", "TERM", "KILL", "TERM"];
    for (k, signal) in signals.iter().enumerate() {
        // Spread the interrupts over loading, solving and writing (and one after the end).
        let delay = 30 + run_ms * k as u64 / (signals.len() as u64 - 1);
        // Without the saved runs, so the interrupted run solves (it would reuse the first one's).
        let _ = std::fs::remove_dir_all(dir.path().join("thermal"));
        let mut child = Command::new(env!("CARGO_BIN_EXE_irpol"))
            .args([
                "thermal",
                new_scene.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
            ])
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(delay));
        Command::new("kill")
            .args([&format!("-{signal}"), &child.id().to_string()])
            .status()
            .unwrap();
        child.wait().unwrap();
        assert!(
            complete_set(&out, &old_csv, &new_csv),
            "after SIG{signal} at {delay} ms"
        );
        if *signal == "TERM" {
            let left = staging(dir.path());
            assert!(left.is_empty(), "left {left:?} after SIGTERM at {delay} ms");
        }
        // Back to the old set (this run also removes a SIGKILLed run's staging folder).
        run(&old_scene);
        assert!(staging(dir.path()).is_empty());
    }
}
