//! Interrupting `irpol render` (one instant or a `--times` series) and `irpol fit`: SIGTERM or
//! SIGKILL at any moment leaves the outputs holding the complete old set or the complete new one,
//! and SIGTERM leaves no temporary (a SIGKILLed run's is removed by the next run).

use crate::common;

use common::*;
use std::path::Path;
use std::process::Command;
use std::time::Duration;

fn scene_text(temperature: f64) -> String {
    format!(
        "{}{}{}[render]\nsamples = 8\n{}\
         [[objects]]\nname = \"floor\"\nshape = {{ kind = \"plane\", size = [6.0, 6.0], divisions = [4, 4] }}\n\
         material = \"m\"\ntemperature_k = 290.0\ntranslate = [0.0, 0.0, -1.0]\n",
        camera_toml(160),
        AUTUMN_ENVIRONMENT,
        material_toml(0.2, 2.0, 1.5, 0.1, 0.05),
        sphere_toml(4, temperature),
    )
}

/// Every file the folder's summary lists is there, and S0.tif is the one of the run that wrote
/// the summary (`a` or `b`, told apart by their sizes being equal but their bytes not).
fn complete_set(out: &Path, old_s0: &[u8], new_s0: &[u8]) -> bool {
    let Ok(summary) = std::fs::read(out.join("summary.json")) else {
        return false;
    };
    let summary: serde_json::Value = serde_json::from_slice(&summary).unwrap();
    let all_there = summary["files"]
        .as_array()
        .unwrap()
        .iter()
        .all(|f| out.join(f.as_str().unwrap()).is_file());
    let s0 = std::fs::read(out.join("S0.tif")).unwrap_or_default();
    all_there && (s0 == old_s0 || s0 == new_s0)
}

/// Starts `irpol args`, sends it `signal` ("TERM" or "KILL") after `delay_ms` and waits for it.
fn interrupt_after(args: &[&str], delay_ms: u64, signal: &str) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_irpol"))
        .args(args)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(delay_ms));
    Command::new("kill")
        .args([&format!("-{signal}"), &child.id().to_string()])
        .status()
        .unwrap();
    child.wait().unwrap();
}

#[test]
fn an_interrupted_render_leaves_the_old_or_the_new_set() {
    let dir = tempfile::tempdir().unwrap();
    let (old_scene, new_scene) = (dir.path().join("old.toml"), dir.path().join("new.toml"));
    std::fs::write(&old_scene, scene_text(300.0)).unwrap();
    std::fs::write(&new_scene, scene_text(310.0)).unwrap();
    let out = dir.path().join("out");
    let render = |scene: &Path| {
        let (ok, _, err) = irpol(&[
            "render",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ]);
        assert!(ok, "{err}");
        std::fs::read(out.join("S0.tif")).unwrap()
    };
    let new_s0 = render(&new_scene);
    let old_s0 = render(&old_scene);
    for (k, signal) in ["TERM", "KILL", "TERM", "KILL", "TERM", "TERM"]
        .iter()
        .enumerate()
    {
        // Spread the interrupts over loading, rendering and writing.
        let args = [
            "render",
            new_scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        interrupt_after(&args, 40 + 90 * k as u64, signal);
        assert!(
            complete_set(&out, &old_s0, &new_s0),
            "after SIG{signal} #{k}"
        );
        let staging: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains("irpol-staging"))
            .collect();
        if *signal == "TERM" {
            assert!(staging.is_empty(), "left {staging:?} after SIGTERM #{k}");
        }
        // Back to the old set for the next round (this run also clears a SIGKILL's leftovers).
        render(&old_scene);
    }
    let leftovers = std::fs::read_dir(dir.path())
        .unwrap()
        .flatten()
        .filter(|e| e.file_name().to_string_lossy().contains("irpol-staging"))
        .count();
    assert_eq!(leftovers, 0);
}

/// A small thermal scene: a steel ball over a steel floor through a summer morning.
fn thermal_scene_text() -> String {
    format!(
        "{}{}{}[render]\nsamples = 8\n\
         [thermal]\nweather = {{ clear_day = {{ air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 }} }}\n\
         start_utc = \"2026-06-21T00:00:00Z\"\nlatitude_deg = 48.14\nlongitude_deg = 11.58\n\
         output_step_s = 3600\nduration_h = 6\n\
         [thermal.layers.steel]\nconductivity_w_mk = 45.0\ndensity_kg_m3 = 7850.0\n\
         heat_capacity_j_kgk = 470.0\n\
         [[objects]]\nname = \"ball\"\nshape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 3 }}\n\
         material = \"m\"\nthermal = {{ stack = [[\"steel\", 0.002]], solar_absorptance = 0.6 }}\n\
         [[objects]]\nname = \"floor\"\nshape = {{ kind = \"plane\", size = [6.0, 6.0], divisions = [4, 4] }}\n\
         material = \"m\"\ntranslate = [0.0, 0.0, -1.0]\n\
         thermal = {{ stack = [[\"steel\", 0.01]], solar_absorptance = 0.9 }}\n",
        camera_toml(96),
        AUTUMN_ENVIRONMENT,
        material_toml(0.2, 2.0, 1.5, 0.1, 0.05),
    )
}

/// The entries of a series folder and the S0.tif of each frame, sorted by name.
fn series(out: &Path) -> Vec<(String, Vec<u8>)> {
    let mut entries: Vec<(String, Vec<u8>)> = std::fs::read_dir(out)
        .unwrap()
        .flatten()
        .map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            (
                name,
                std::fs::read(e.path().join("S0.tif")).unwrap_or_default(),
            )
        })
        .collect();
    entries.sort();
    entries
}

/// The folder holds one whole series, `a` or `b`: the same entries, each frame's S0.tif the same,
/// and every file each frame's summary lists.
fn one_series(out: &Path, a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)]) -> bool {
    let now = series(out);
    let frames_complete = now
        .iter()
        .filter(|(_, s0)| !s0.is_empty())
        .all(|(frame, _)| {
            let summary = std::fs::read(out.join(frame).join("summary.json")).unwrap_or_default();
            let summary: serde_json::Value = serde_json::from_slice(&summary).unwrap_or_default();
            summary["files"].as_array().is_some_and(|files| {
                files
                    .iter()
                    .all(|f| out.join(frame).join(f.as_str().unwrap()).is_file())
            })
        });
    (now == a || now == b) && frames_complete
}

/// SIGTERM or SIGKILL at any moment of `irpol render --times` leaves the complete earlier series
/// or the complete new one, never frames of both; SIGTERM leaves no staging folder.
#[test]
fn an_interrupted_series_leaves_the_old_or_the_new_series() {
    let dir = tempfile::tempdir().unwrap();
    let scene = dir.path().join("day.toml");
    std::fs::write(&scene, thermal_scene_text()).unwrap();
    let out = dir.path().join("out");
    let args = |times: &'static str| {
        [
            "render".to_owned(),
            scene.display().to_string(),
            "--times".to_owned(),
            times.to_owned(),
            "--out".to_owned(),
            out.display().to_string(),
        ]
    };
    let (old_times, new_times) = ("0:21600:10800", "0:21600:7200");
    let run = |times| {
        let args = args(times);
        let (ok, _, err) = irpol(&args.each_ref().map(String::as_str));
        assert!(ok, "{err}");
        series(&out)
    };
    let new = run(new_times);
    let old = run(old_times);
    assert_eq!(
        (old.len(), new.len()),
        (5, 6),
        "frames, preview and manifest"
    );
    let staging = || {
        std::fs::read_dir(dir.path())
            .unwrap()
            .flatten()
            .filter(|e| e.file_name().to_string_lossy().contains("irpol-staging"))
            .count()
    };
    for (k, signal) in ["TERM", "KILL", "TERM", "KILL", "TERM", "KILL"]
        .iter()
        .enumerate()
    {
        // Spread over the thermal solve, the frames and the commit.
        let args = args(new_times);
        interrupt_after(
            &args.each_ref().map(String::as_str),
            150 + 200 * k as u64,
            signal,
        );
        assert!(
            one_series(&out, &old, &new),
            "a mixed series after SIG{signal} #{k}"
        );
        if *signal == "TERM" {
            assert_eq!(staging(), 0, "a staging folder left after SIGTERM #{k}");
        }
        // Back to the old series (this run also clears a SIGKILL's leftovers).
        run(old_times);
        assert_eq!(staging(), 0);
    }
}

/// Every library entry in `fits` is from the same fit: all equal to `a` or all equal to `b`.
fn one_library(fits: &Path, a: &[(String, Vec<u8>)], b: &[(String, Vec<u8>)]) -> bool {
    let same_as = |set: &[(String, Vec<u8>)]| {
        set.iter()
            .all(|(name, bytes)| std::fs::read(fits.join(name)).ok().as_deref() == Some(bytes))
    };
    same_as(a) || same_as(b)
}

fn library(fits: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(fits)
        .unwrap()
        .flatten()
        .map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            (name, std::fs::read(e.path()).unwrap())
        })
        .collect();
    files.sort();
    files
}

fn temporaries(dirs: &[&Path]) -> Vec<String> {
    dirs.iter()
        .flat_map(|d| std::fs::read_dir(d).unwrap().flatten())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

/// SIGTERM or SIGKILL at any moment of `irpol fit` leaves the library as it was or wholly
/// replaced; SIGTERM leaves no temporary file, and the next fit removes a SIGKILLed one's.
#[test]
fn an_interrupted_fit_leaves_the_old_or_the_new_library() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
    let inputs: Vec<String> = [
        "paper_paint",
        "rough_paint",
        "smooth_glass",
        "anodized_panel",
    ]
    .iter()
    .map(|m| {
        root.join(format!("measurements/{m}.csv"))
            .display()
            .to_string()
    })
    .collect();
    let fit = |seed: &str| {
        let mut args = vec!["fit".to_owned()];
        args.extend(inputs.iter().cloned());
        args.extend(["--seed", seed, "--out"].map(str::to_owned));
        args.push(fits.display().to_string());
        args.push("--reports".into());
        args.push(reports.display().to_string());
        args
    };
    let run = |seed: &str| {
        let args = fit(seed);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, err) = irpol(&args);
        assert!(ok, "{err}");
        library(&fits)
    };
    let new = run("2");
    let old = run("1");
    assert_ne!(old, new, "the two seeds must give different entries");
    for k in 0..8u64 {
        let signal = if k % 3 == 2 { "KILL" } else { "TERM" };
        let args = fit("2");
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        interrupt_after(&args, 30 + 110 * k, signal);
        assert!(
            one_library(&fits, &old, &new),
            "a mixed library after SIG{signal} #{k}"
        );
        let left = temporaries(&[&fits, &reports]);
        if signal == "TERM" {
            assert!(left.is_empty(), "temporaries {left:?} after SIGTERM #{k}");
        }
        // The next fit also removes what a SIGKILLed one left.
        run("1");
        assert!(temporaries(&[&fits, &reports]).is_empty());
    }
}

/// Copies the folder `from` (files and subfolders) to `to`.
fn copy_folder(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for entry in std::fs::read_dir(from).unwrap().flatten() {
        let target = to.join(entry.file_name());
        if entry.file_type().unwrap().is_dir() {
            copy_folder(&entry.path(), &target);
        } else {
            std::fs::copy(entry.path(), &target).unwrap();
        }
    }
}

/// Staging folders (and staged files) anywhere under `dir`.
fn staged_under(dir: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Vec::new();
    };
    let mut found = Vec::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        if name.contains("irpol-staging") || name.ends_with(".tmp") {
            found.push(name);
        } else if entry.file_type().unwrap().is_dir() {
            found.extend(staged_under(&entry.path()));
        }
    }
    found
}

/// `irpol demo` runs several steps (fits, a render, a thermal day); SIGTERM while its day is being
/// staged removes that day's staging folders too, and the process exits with 128 + SIGTERM.
#[test]
fn an_interrupted_demo_leaves_no_staging_folder() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for folder in ["measurements", "fits", "scenes"] {
        copy_folder(&root.join(folder), &dir.path().join(folder));
    }
    let mut child = Command::new(env!("CARGO_BIN_EXE_irpol"))
        .arg("demo")
        .current_dir(dir.path())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    let demo = dir.path().join("out/demo");
    while !staged_under(&demo)
        .iter()
        .any(|n| n.starts_with(".car_day"))
    {
        let ended = child.try_wait().unwrap();
        assert!(ended.is_none(), "the demo ended before its day was staged");
        std::thread::sleep(Duration::from_millis(2));
    }
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert_eq!(child.wait().unwrap().code(), Some(128 + 15));
    let left = staged_under(dir.path());
    assert!(left.is_empty(), "left {left:?}");
}

/// `irpol validate` interrupted while its pages are staged: the one handler shared by every
/// command that writes removes the staged pages and exits with 128 + SIGTERM (issue 42: validate
/// had no handler and left `.…png.PID.tmp`).
#[test]
fn an_interrupted_validate_leaves_no_temporary() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let reports = dir.path().join("reports");
    let path = |p: &str| root.join(p).display().to_string();
    let mut child = Command::new(env!("CARGO_BIN_EXE_irpol"))
        .args([
            "validate".to_string(),
            path("fits/rough_paint.toml"),
            path("data/ptfe/PTFE_351_1064.csv"),
            "--layout".into(),
            path("data/ptfe/layout.toml"),
            "--reports".into(),
            reports.display().to_string(),
        ])
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .unwrap();
    // The first page is staged while the second is drawn.
    while !reports.is_dir() || temporaries(&[&reports]).is_empty() {
        let ended = child.try_wait().unwrap();
        assert!(ended.is_none(), "validate ended before a page was staged");
        std::thread::sleep(Duration::from_millis(1));
    }
    Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert_eq!(child.wait().unwrap().code(), Some(128 + 15));
    let left = staged_under(dir.path());
    assert!(left.is_empty(), "left {left:?}");
}
