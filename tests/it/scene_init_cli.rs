//! `irpol scene init` through the binary: the starter scene renders as written, from
//! the folder it is written into, and a second init never overwrites it.

use crate::common;

use common::irpol;

#[test]
fn the_starter_scene_renders_and_is_never_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    // A folder of its own, holding nothing else: the scene must need no other file.
    let scene = dir.path().join("fresh/scene.toml");
    let out = dir.path().join("out");
    let scene_arg = scene.to_str().unwrap();

    let (ok, stdout, stderr) = irpol(&["scene", "init", "--out", scene_arg]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("irpol render"), "{stdout}");
    let written = std::fs::read_to_string(&scene).unwrap();
    assert_eq!(
        std::fs::read_dir(scene.parent().unwrap()).unwrap().count(),
        1,
        "only the scene is written"
    );

    let (ok, stdout, stderr) = irpol(&["render", scene_arg, "--out", out.to_str().unwrap()]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("rendered"), "{stdout}");
    // The shading in words, not the setting's internal name ("Pixel shading").
    assert!(stdout.contains(", per-pixel shading"), "{stdout}");
    assert!(out.join("S0.tif").is_file());
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(out.join("summary.json")).unwrap()).unwrap();
    for object in ["sphere", "ground"] {
        let pixels = summary["pixels"]["per_object"][object]
            .as_u64()
            .unwrap_or(0);
        assert!(pixels > 0, "{object} is not in view: {summary}");
    }

    std::fs::write(&scene, "# my edits\n").unwrap();
    let (ok, _, stderr) = irpol(&["scene", "init", "--out", scene_arg]);
    assert!(!ok, "a second init must fail");
    assert!(
        stderr.starts_with("irpol: error: ") && stderr.contains("already exists"),
        "{stderr}"
    );
    assert_eq!(stderr.trim_end().lines().count(), 1, "{stderr}");
    assert_eq!(std::fs::read_to_string(&scene).unwrap(), "# my edits\n");
    assert_ne!(written, "# my edits\n");
}

/// By default the scene goes under `out/` (ignored by git), not into the current folder, which
/// is a checkout's root when the docs' command is run as written.
#[test]
fn init_writes_out_scene_toml_by_default() {
    let dir = tempfile::tempdir().unwrap();
    let status = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .args(["scene", "init"])
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(
        status.status.success(),
        "{}",
        String::from_utf8_lossy(&status.stderr)
    );
    assert!(dir.path().join("out/scene.toml").is_file());
    assert!(!dir.path().join("scene.toml").exists());
    let stdout = String::from_utf8_lossy(&status.stdout);
    assert!(stdout.contains("irpol render out/scene.toml"), "{stdout}");
}
