//! Robustness of the `irpol` binary against hostile or mistaken input: no panic, no
//! hang, no allocation beyond what the input can hold, no wrong input accepted, no corrupt output,
//! and error messages of one short line without the input's control characters. Every case runs
//! the built binary in a scratch folder and checks that a refusal is a clean one-line
//! `irpol: error: …`, a failure exit, and that no file was written or changed.
//!
//! The binary runs under a 4 GB address-space limit and a time limit, so that a regression shows
//! as a failed test rather than a machine out of memory or a suite that never ends. Set
//! `IRPOL_BIN` to run the cases against another build (e.g. an older one, to see them fail).

use std::collections::BTreeMap;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const TIME_LIMIT: Duration = Duration::from_secs(120);
const MEMORY_LIMIT_KB: u64 = 4_000_000;

fn binary() -> PathBuf {
    std::env::var_os("IRPOL_BIN")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_irpol")))
}

fn manifest(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// What a run of the binary did.
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    timed_out: bool,
}

/// Runs `irpol args…` in `dir` under the memory and time limits.
fn irpol(dir: &Path, args: &[&str]) -> Run {
    let mut child = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "ulimit -v {MEMORY_LIMIT_KB} 2>/dev/null; exec \"$0\" \"$@\""
        ))
        .arg(binary())
        .args(args)
        .current_dir(dir)
        .env("RUST_BACKTRACE", "0")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run irpol");
    // Read both pipes on threads so a chatty child cannot block on a full pipe.
    let mut stdout = child.stdout.take().unwrap();
    let mut stderr = child.stderr.take().unwrap();
    let out = std::thread::spawn(move || {
        let mut text = Vec::new();
        let _ = stdout.read_to_end(&mut text);
        text
    });
    let err = std::thread::spawn(move || {
        let mut text = Vec::new();
        let _ = stderr.read_to_end(&mut text);
        text
    });
    let start = Instant::now();
    let (status, timed_out) = loop {
        if let Some(status) = child.try_wait().unwrap() {
            break (Some(status), false);
        }
        if start.elapsed() > TIME_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            break (None, true);
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    Run {
        code: status.and_then(|s| s.code()),
        stdout: String::from_utf8_lossy(&out.join().unwrap()).into_owned(),
        stderr: String::from_utf8_lossy(&err.join().unwrap()).into_owned(),
        timed_out,
    }
}

/// Every file under `dir` with its bytes.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut files = BTreeMap::new();
    let mut pending = vec![dir.to_owned()];
    while let Some(folder) = pending.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                files.insert(path.clone(), Vec::new());
                pending.push(path);
            } else {
                files.insert(path.clone(), std::fs::read(&path).unwrap());
            }
        }
    }
    files
}

/// A refusal: exit code 1, stdout empty, stderr exactly one short line `irpol: error: …`
/// containing `needle`, no control characters, no panic, no backtrace.
fn assert_refused(run: &Run, needle: &str) {
    assert!(!run.timed_out, "hung (killed after {TIME_LIMIT:?})");
    let stderr = &run.stderr;
    assert_eq!(run.code, Some(1), "not a clean failure exit: {stderr}");
    assert!(
        run.stdout.is_empty(),
        "output despite the error: {}",
        run.stdout
    );
    assert!(
        !stderr.contains("panicked") && !stderr.contains("backtrace"),
        "{stderr}"
    );
    let line = stderr.strip_suffix('\n').unwrap_or(stderr);
    assert!(
        line.starts_with("irpol: error: ") && !line.contains('\n'),
        "not one error line: {stderr:?}"
    );
    assert!(
        !line.chars().any(char::is_control) && line.chars().count() < 600,
        "control characters or a long excerpt: {line:?}"
    );
    assert!(line.contains(needle), "{line:?} lacks {needle:?}");
}

/// Runs `command` (arguments separated by single spaces) in a scratch folder prepared by `files`
/// and expects a refusal that changes nothing.
fn refuse(files: &[(&str, &[u8])], command: &str, needle: &str) {
    let dir = tempfile::tempdir().unwrap();
    for (name, bytes) in files {
        let path = dir.path().join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, bytes).unwrap();
    }
    let before = snapshot(dir.path());
    let args: Vec<&str> = command.split(' ').collect();
    let run = irpol(dir.path(), &args);
    assert_refused(&run, needle);
    assert_eq!(
        snapshot(dir.path()).keys().collect::<Vec<_>>(),
        before.keys().collect::<Vec<_>>(),
        "files were written by {command}"
    );
    assert!(
        snapshot(dir.path()) == before,
        "files were changed by {command}"
    );
}

fn shipped(path: &str) -> Vec<u8> {
    std::fs::read(manifest(path)).unwrap()
}

/// The shipped paint measurement with `edit` applied to its data rows (a line's fields).
fn edited_paint(edit: impl Fn(usize, &mut Vec<String>)) -> Vec<u8> {
    let text = String::from_utf8(shipped("measurements/paper_paint.csv")).unwrap();
    let mut row = 0;
    let mut lines = Vec::new();
    let mut header_seen = false;
    for line in text.lines() {
        if line.starts_with('#') || !header_seen {
            header_seen |= !line.starts_with('#');
            lines.push(line.to_owned());
            continue;
        }
        let mut fields: Vec<String> = line.split(',').map(str::to_owned).collect();
        edit(row, &mut fields);
        row += 1;
        lines.push(fields.join(","));
    }
    (lines.join("\n") + "\n").into_bytes()
}

/// Column index of `name` in the shipped paint measurement.
fn paint_column(name: &str) -> usize {
    let text = String::from_utf8(shipped("measurements/paper_paint.csv")).unwrap();
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    header.split(',').position(|c| c == name).unwrap()
}

/// A scene of one mesh object `mesh`, with `sensor` as its [sensor] table.
fn scene(mesh: &str, sensor: &str) -> String {
    format!(
        "[camera]\nposition = [0.0, -4.0, 0.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 0.0, 1.0]\n\
         fov_deg = 36.0\nresolution = [8, 8]\n{sensor}\
         [environment]\nair_temperature_k = 283.15\n\
         sky = {{ model = \"window\", zenith_emissivity = 0.75 }}\n\
         ground = {{ temperature_k = 288.0, emissivity = 0.95 }}\n\
         [materials.m]\ndistribution = \"cauchy\"\nsigma = 0.2\nq = 2.0\nn = 1.5\nk = 0.1\n\
         rho_d = 0.0\nshadowing = \"smith\"\n\
         [[objects]]\nname = \"thing\"\nmesh = \"{mesh}\"\nmaterial = \"m\"\ntemperature_k = 300.0\n"
    )
}

const TRIANGLE_OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 0 0 1\ng panel\nf 1 2 3\n";

/// A binary PLY of one triangle whose header declares `faces` faces, `version` its version.
fn ply(faces: u64, version: &str) -> Vec<u8> {
    let mut bytes = format!(
        "ply\nformat binary_little_endian {version}\nelement vertex 3\nproperty float x\n\
         property float y\nproperty float z\nelement face {faces}\n\
         property list uchar int vertex_indices\nend_header\n"
    )
    .into_bytes();
    for v in [0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0] {
        bytes.extend(v.to_le_bytes());
    }
    bytes.push(3);
    for i in [0i32, 1, 2] {
        bytes.extend(i.to_le_bytes());
    }
    bytes
}

/// A valid material file with `edit` applied to its text.
fn material(edit: impl Fn(String) -> String) -> Vec<u8> {
    let text = "name = \"paint\"\ntool_version = \"irpol test\"\n\n[model]\n\
                distribution = \"cauchy\"\nsigma = 0.1\nq = 1.8\nshadowing = \"smith\"\n\
                n = 1.2\nk = 0.2\nrho_d = 0.0\nwavelength_um = 9.925\n";
    edit(text.to_owned()).into_bytes()
}

/// The shipped fitted paint with a misspelt key in its [fit] table.
fn fitted_with_unknown_fit_key() -> Vec<u8> {
    let text = String::from_utf8(shipped("fits/paper_paint.toml")).unwrap();
    text.replace("[fit]\n", "[fit]\ncost_typo = 1.0\n")
        .into_bytes()
}

/// Model flags for eval and emissivity.
const MODEL: &str = "--sigma 0.2 --q 2 --n 1.5 --k 0.1";

/// A fit that runs in about a second (one distribution, one local stage).
/// Whether a material entry holds `nan` or `inf` outside its comments.
fn has_non_finite_value(entry: &str) -> bool {
    entry
        .lines()
        .filter(|line| !line.trim_start().starts_with('#'))
        .flat_map(|line| line.split(|c: char| !(c.is_alphanumeric() || c == '_')))
        .any(|token| token == "nan" || token == "inf")
}

const QUICK_FIT: &str = "--distribution cauchy --optimizer lm --out fits --reports reports";

const RENDER: &str = "render scene.toml --out out";

// ---- 1. Panics on user input -----------------------------------------------------------------

#[test]
fn extreme_model_parameters_are_refused_not_panicked_on() {
    let huge = material(|t| t.replace("sigma = 0.1", "sigma = 1e308"));
    let cases = [
        (
            "emissivity --sigma 0.2 --q 1e308 --n 1.5 --k 0.1 --shadowing smith",
            "q = 1e308 is invalid",
        ),
        (
            "emissivity --sigma 0.2 --q 1e308 --n 1.5 --k 0.1",
            "within (1, 100]",
        ),
        (
            "eval --sigma 1e308 --q 3 --n 1.5 --k 0.1 --shadowing smith --theta-i 30 --theta-r 30",
            "σ = 1e308 is invalid",
        ),
        (
            "eval --sigma 0.2 --q 2 --n 1e308 --k 0.1 --theta-i 30 --theta-r 30",
            "n = 1e308 is invalid",
        ),
        (
            "eval --material m.toml --theta-i 30 --theta-r 30",
            "σ = 1e308 is invalid",
        ),
    ];
    for (command, needle) in cases {
        refuse(&[("m.toml", &huge)], command, needle);
    }
}

#[test]
fn a_fit_with_an_absurd_fixed_value_is_refused_before_fitting() {
    let csv = shipped("measurements/paper_paint.csv");
    refuse(
        &[("paint.csv", &csv)],
        "fit paint.csv --fix sigma=1e308 --out fits --reports reports",
        "sigma = 1e308 is outside [0.0001, 10]",
    );
}

// ---- 2. Hangs, and a fit's outputs written as a whole ----------------------------------------

/// Values a fit can square fit and report without hanging; beyond ±1e12 sr⁻¹ (or an uncertainty
/// outside 1e-15…1e12) they are refused where read: they once fitted to χ² = inf and wrote `inf`
/// and `nan` into the material file.
#[test]
fn extreme_measured_values_fit_and_report_without_hanging() {
    let (m00, u_m00) = (paint_column("m00"), paint_column("u_m00"));
    for (name, column, value, refusal) in [
        (
            "huge",
            m00,
            "1e308",
            Some("column 'm00': 1e308 sr⁻¹ is beyond ±1e12 sr⁻¹"),
        ),
        ("large", m00, "1e12", None),
        ("subnormal", m00, "1e-320", None),
        (
            "uncertain",
            u_m00,
            "1e308",
            Some("column 'u_m00': uncertainty 1e308 sr⁻¹ is outside 1e-15…1e12 sr⁻¹"),
        ),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let csv = edited_paint(|row, fields| {
            if row == 0 {
                fields[column] = value.to_owned();
            }
        });
        std::fs::write(dir.path().join("m.csv"), csv).unwrap();
        let command = format!("fit m.csv {QUICK_FIT}");
        let run = irpol(dir.path(), &command.split(' ').collect::<Vec<_>>());
        assert!(!run.timed_out, "{name}: the fit or its report hung");
        if let Some(needle) = refusal {
            assert_refused(&run, needle);
            assert!(!dir.path().join("fits").exists(), "{name}");
            continue;
        }
        assert_eq!(run.code, Some(0), "{name}: {}", run.stderr);
        let entry = std::fs::read_to_string(dir.path().join("fits/paper_paint.toml")).unwrap();
        assert!(
            !has_non_finite_value(&entry),
            "{name}: a non-finite number in the entry"
        );
        // The file's `# material:` header names the outputs.
        for out in [
            "fits/paper_paint.toml",
            "reports/paper_paint.png",
            "reports/index.html",
        ] {
            assert!(dir.path().join(out).is_file(), "{name}: no {out}");
        }
    }
}

/// Every measured element subnormal (the data say "nothing scattered"): the data cannot determine
/// the facet or body parameters, so their uncertainties are infinite. The entry is written with
/// those parameters flagged as undetermined, for the default terms and for each slope law; it was
/// once refused as "fits/paper_paint.toml: not written: … is not a finite number", blaming the
/// output for what the input lacked.
#[test]
fn a_fit_the_data_cannot_determine_is_written_with_its_parameters_flagged() {
    let csv = edited_paint(|_, fields| {
        for value in &mut fields[4..20] {
            *value = format!("{:e}", value.parse::<f64>().unwrap() * 1e-310);
        }
    });
    for flags in ["", "--distribution gaussian", "--distribution cauchy"] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("m.csv"), &csv).unwrap();
        let command = format!("fit m.csv {flags} --out fits --reports reports");
        let run = irpol(dir.path(), &command.split_whitespace().collect::<Vec<_>>());
        assert_eq!(run.code, Some(0), "{flags}: {}", run.stderr);
        assert!(
            run.stdout.contains("NOT DETERMINED by the data"),
            "{flags}: {}",
            run.stdout
        );
        let entry = std::fs::read_to_string(dir.path().join("fits/paper_paint.toml")).unwrap();
        assert!(entry.contains("undetermined"), "{flags}: {entry}");
        assert!(!has_non_finite_value(&entry), "{flags}: {entry}");
    }
}

#[test]
fn a_fit_whose_report_cannot_be_written_leaves_the_library_unchanged() {
    let csv = shipped("measurements/paper_paint.csv");
    let old_entry = material(|t| t.replace("\"paint\"", "\"paper_paint\""));
    // A file where the reports folder should be: drawing succeeds, writing the report fails.
    refuse(
        &[
            ("paper_paint.csv", &csv),
            ("fits/paper_paint.toml", &old_entry),
            ("reports", b"not a folder"),
        ],
        &format!("fit paper_paint.csv {QUICK_FIT}"),
        "reports",
    );
}

// ---- 3. Out of memory from small inputs --------------------------------------------------------

#[test]
fn a_small_ply_declaring_billions_of_faces_is_refused() {
    let mesh = ply(4_294_967_295, "1.0");
    assert!(mesh.len() < 400);
    let scene = scene("m.ply", "");
    refuse(
        &[("m.ply", &mesh), ("scene.toml", scene.as_bytes())],
        RENDER,
        "4294967295",
    );
    // Within the item limit but beyond what the bytes can hold.
    let mesh = ply(1_000_000, "1.0");
    refuse(
        &[("m.ply", &mesh), ("scene.toml", scene.as_bytes())],
        RENDER,
        "bytes follow",
    );
}

#[test]
fn a_sensor_band_to_a_kilometre_is_refused() {
    let scene = scene("panel.obj", "[sensor]\nband_um = [8.0, 1e9]\n");
    refuse(
        &[
            ("panel.obj", TRIANGLE_OBJ),
            ("scene.toml", scene.as_bytes()),
        ],
        RENDER,
        "0.1 ≤ lower < upper ≤ 1000 µm",
    );
}

#[test]
fn a_vanishing_roughness_or_step_and_a_huge_sweep_are_refused() {
    refuse(
        &[],
        "emissivity --sigma 1e-300 --q 2 --n 1.5 --k 0.1 --theta 60",
        "σ = 1e-300 is invalid",
    );
    refuse(
        &[],
        &format!("eval {MODEL} --theta-i 30 --theta-r 0:89:1e-300"),
        "at most 1000000",
    );
    refuse(
        &[],
        &format!("eval {MODEL} --theta-i 0:89:1e-4 --theta-r 0:89:1e-4"),
        "at most 10000000",
    );
}

// ---- 4. Wrong input accepted --------------------------------------------------------------------

#[test]
fn material_files_with_unknown_keys_or_wrong_wavelengths_are_refused() {
    let cases = [
        (
            material(|t| t.replace("rho_d = 0.0", "rho = 0.5")),
            "unknown field `rho`",
        ),
        (fitted_with_unknown_fit_key(), "unknown field `cost_typo`"),
        (
            material(|t| t.replace("9.925", "-1.0")),
            "wavelength_um = -1 is outside",
        ),
        (
            material(|t| t.replace("9.925", "nan")),
            "wavelength_um = NaN is outside",
        ),
    ];
    for (text, needle) in cases {
        refuse(
            &[("m.toml", &text)],
            "eval --material m.toml --theta-i 30 --theta-r 30",
            needle,
        );
    }
}

#[test]
fn measurements_of_zeros_or_impossible_wavelengths_are_refused() {
    let m00 = paint_column("m00");
    let zeros = edited_paint(|_, fields| fields[m00] = "0".into());
    let fit = "fit m.csv --out fits --reports reports";
    let text = String::from_utf8(shipped("measurements/paper_paint.csv")).unwrap();
    let header_line = text.lines().position(|l| !l.starts_with('#')).unwrap() + 1;
    refuse(&[("m.csv", &zeros)], fit, &format!("m.csv:{header_line}:"));
    refuse(&[("m.csv", &zeros)], fit, "'m00' is 0 on every row");
    let far = text.replace("# wavelength_um: 9.925", "# wavelength_um: 1e-300");
    refuse(&[("m.csv", far.as_bytes())], fit, "outside 0.1–1000 µm");
}

#[test]
fn eval_refuses_duplicate_columns_and_model_flags_beside_a_material() {
    let geometry = b"theta_i_deg,theta_r_deg,theta_r_deg\n30,30,40\n";
    refuse(
        &[("g.csv", geometry)],
        &format!("eval {MODEL} --geometry g.csv"),
        "duplicate column 'theta_r_deg'",
    );
    let paint = material(|t| t);
    for flags in ["--rho 0.5", "--distribution gaussian"] {
        refuse(
            &[("m.toml", &paint)],
            &format!("eval --material m.toml {flags} --theta-i 30 --theta-r 30"),
            "not both",
        );
    }
}

#[test]
fn unsupported_ply_versions_are_refused() {
    let scene = scene("m.ply", "");
    refuse(
        &[("m.ply", &ply(1, "7.5")), ("scene.toml", scene.as_bytes())],
        RENDER,
        "PLY version 7.5 is not supported",
    );
}

// ---- 5. Corrupt output -------------------------------------------------------------------------

#[test]
fn eval_keeps_quoted_fields_quoted() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("g.csv"),
        "label,theta_i_deg,theta_r_deg\n\"a,b\",30,30\n\"say \"\"hi\"\"\",10,20\n",
    )
    .unwrap();
    let command = format!("eval {MODEL} --geometry g.csv");
    let run = irpol(dir.path(), &command.split(' ').collect::<Vec<_>>());
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    // The `#` lines before the table state the model.
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_reader(run.stdout.as_bytes());
    assert_eq!(reader.headers().unwrap().len(), 19);
    let labels: Vec<String> = reader
        .records()
        .map(|r| {
            let record = r.expect("a rectangular CSV");
            assert_eq!(record.len(), 19, "{record:?}");
            record[0].to_owned()
        })
        .collect();
    assert_eq!(labels, ["a,b", "say \"hi\""]);
}

// ---- 6. Error messages ---------------------------------------------------------------------------

#[test]
fn readers_escape_control_characters_and_cut_long_excerpts() {
    // One whitespace-free token: two million digits, then an escape sequence and a bell.
    let junk = format!("{}\u{1b}[2J\u{7}", "9".repeat(2_000_000));
    let obj_scene = scene("m.obj", "");
    for (obj, needle) in [
        (
            format!("v 0 0 0\n{junk} 1\n"),
            "line 2: unsupported OBJ statement",
        ),
        (format!("v 0 0 {junk}\n"), "is not a number"),
    ] {
        let files: [(&str, &[u8]); 2] = [
            ("m.obj", obj.as_bytes()),
            ("scene.toml", obj_scene.as_bytes()),
        ];
        refuse(&files, RENDER, needle);
    }

    let ply_text = format!(
        "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
         property float z\nend_header\n0 0 {junk}\n"
    );
    let ply_scene = scene("m.ply", "");
    let files: [(&str, &[u8]); 2] = [
        ("m.ply", ply_text.as_bytes()),
        ("scene.toml", ply_scene.as_bytes()),
    ];
    refuse(&files, RENDER, "not a readable PLY");

    let geometry = format!("theta_i_deg,theta_r_deg\n{junk},30\n");
    refuse(
        &[("g.csv", geometry.as_bytes())],
        &format!("eval {MODEL} --geometry g.csv"),
        "is not a finite number",
    );

    let toml = material(|t| t.replace("sigma = 0.1", &format!("sigma = 0.1{junk}")));
    refuse(
        &[("m.toml", &toml)],
        "eval --material m.toml --theta-i 30 --theta-r 30",
        "not a valid material TOML: line 6",
    );
}

// ---- Issue 42 ---------------------------------------------------------------------------------

/// One rule for echoing a user's number (issue 42): at most 12 significant digits, the exponent
/// kept — for flags, a crate's message about them and the TOML reader's own message.
#[test]
fn user_numbers_are_echoed_short_with_their_exponent() {
    let (ptfe, layout) = (
        shipped("data/ptfe/PTFE_351_1064.csv"),
        shipped("data/ptfe/layout.toml"),
    );
    let paint = shipped("fits/rough_paint.toml");
    let files: [(&str, &[u8]); 3] = [
        ("p.csv", &ptfe),
        ("layout.toml", &layout),
        ("m.toml", &paint),
    ];
    let validate = "validate m.toml p.csv --layout layout.toml --reports reports --wavelength";
    refuse(
        &files,
        &format!("{validate} 1e308"),
        "at the selected wavelength 1e308 µm;",
    );
    refuse(
        &files,
        &format!("{validate} 1e-300"),
        "at the selected wavelength 1e-300 µm;",
    );
    refuse(
        &[],
        "sun --latitude 1e308 --longitude 0 --time-utc 2026-06-21T10:00:00Z",
        "invalid latitude 1e308",
    );
    let tiny_samples = scene("m.obj", "[render]\nsamples = 1e-300\n");
    refuse(
        &[
            ("scene.toml", tiny_samples.as_bytes()),
            ("m.obj", TRIANGLE_OBJ),
        ],
        RENDER,
        "invalid type: floating point `1e-300`",
    );
}

/// A library entry or the index that is a folder is found before anything is written: the fit's
/// outputs are put in place together or not at all (issue 42: the reports were written first).
#[test]
fn a_fit_whose_entry_or_index_is_a_folder_writes_nothing() {
    let csv = shipped("measurements/paper_paint.csv");
    for folder in ["fits/paper_paint.toml", "reports/index.html"] {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("paper_paint.csv"), &csv).unwrap();
        std::fs::create_dir_all(dir.path().join(folder)).unwrap();
        let before = snapshot(dir.path());
        let command = format!("fit paper_paint.csv {QUICK_FIT}");
        let args: Vec<&str> = command.split(' ').collect();
        let run = irpol(dir.path(), &args);
        assert_refused(&run, &format!("{folder}: cannot write: it is a folder"));
        assert!(
            snapshot(dir.path()) == before,
            "{folder}: files were written"
        );
    }
}

/// A render's time is estimated before any work from its expensive dimensions (frames, pixels ×
/// path vertices, wavelength nodes) and refused beyond `--max-minutes` with the estimate and the
/// value to give (issue 42: `--times` took 1e5 frames, ≈ 13 h, without a word).
#[test]
fn a_render_estimated_beyond_its_limit_is_refused_before_any_work() {
    let many_paths = scene("m.obj", "[render]\nsamples = 4000000000\n");
    refuse(
        &[
            ("scene.toml", many_paths.as_bytes()),
            ("m.obj", TRIANGLE_OBJ),
        ],
        RENDER,
        "scene.toml: this render is estimated at ",
    );
    let dir = tempfile::tempdir().unwrap();
    let day = manifest("scenes/car_day.toml");
    let args = [
        "render",
        day.to_str().unwrap(),
        "--times",
        "0:100000:1",
        "--out",
        "out",
    ];
    let run = irpol(dir.path(), &args);
    assert_refused(&run, "(100001 frames × ");
    assert!(run
        .stderr
        .contains("more than --max-minutes 60: give --max-minutes "));
    assert!(snapshot(dir.path()).is_empty(), "files were written");
}

/// A spectral file of `wavelengths` wavelengths, each with the shipped paint's first `rows` rows.
fn many_wavelengths(wavelengths: usize, rows: usize) -> Vec<u8> {
    let text = String::from_utf8(shipped("measurements/paper_paint.csv")).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header = lines
        .next()
        .unwrap()
        .replacen(",m00,", ",wavelength_um,m00,", 1);
    let data: Vec<&str> = lines.take(rows).collect();
    let mut out = format!("# material: paint\n# mueller_convention: psps\n{header}\n");
    for w in 0..wavelengths {
        let at = format!("{:.4}", 8.0 + 6.0 * w as f64 / wavelengths as f64);
        for row in &data {
            let fields: Vec<&str> = row.split(',').collect();
            out += &format!("{},{at},{}\n", fields[..4].join(","), fields[4..].join(","));
        }
    }
    out.into_bytes()
}

/// A fit's cost is estimated before any work, as a render's is (issue 42: a spectral fit of
/// 2000 wavelengths aborted on a 2.3 GB allocation, one of 300 ran for minutes without a word):
/// a joint problem past its coordinate limit is refused naming the file and what to do, and a
/// fit estimated beyond `--max-minutes` names its factors and the value to give.
#[test]
fn a_fit_estimated_beyond_its_limits_is_refused_before_any_work() {
    refuse(
        &[("many.csv", &many_wavelengths(400, 3))],
        "fit many.csv --out fits --reports reports",
        "many.csv: 400 wavelengths make a joint fit of 1206 coordinates, more than the 1000",
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("some.csv"), many_wavelengths(50, 40)).unwrap();
    let run = irpol(
        dir.path(),
        &["fit", "some.csv", "--max-minutes", "0.01", "--out", "fits"],
    );
    assert_refused(&run, "some.csv: this fit is estimated at ");
    for factor in [
        "2000 rows × 6 candidate models × (1 + 5 folds)",
        "156 coordinates",
    ] {
        assert!(run.stderr.contains(factor), "{factor}: {}", run.stderr);
    }
    assert!(run
        .stderr
        .contains("more than --max-minutes 0.01: give --max-minutes 1 "));
    assert!(snapshot(dir.path()).len() == 1, "files were written");
}

/// `--free`/`--fix` of a parameter the terms lack is refused when the terms are given, and under
/// the default choice leaves out the sets without it (issue 42: `--fix rho_s=…` with the default
/// terms and `--fix rho_d=…` with internal+subsurface were ignored, the output byte-identical).
#[test]
fn fixing_a_parameter_the_terms_lack_is_refused_or_chooses_terms_that_have_it() {
    let csv = shipped("measurements/paper_paint.csv");
    for (flags, needle) in [
        (
            "--terms external+depolarizer --fix rho_s=0.1",
            "--free/--fix name rho_s, which the terms external+depolarizer do not have",
        ),
        (
            "--terms internal+subsurface --fix rho_d=0.1",
            "--free/--fix name rho_d, which the terms internal+subsurface do not have",
        ),
        (
            "--fix rho_d=0.1,rho_s=0.1",
            "--free/--fix name parameters of different terms",
        ),
    ] {
        refuse(
            &[("paint.csv", &csv)],
            &format!("fit paint.csv {flags} {QUICK_FIT}"),
            needle,
        );
    }
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("paint.csv"), &csv).unwrap();
    let command = format!("fit paint.csv --fix rho_s=0.05 {QUICK_FIT}");
    let run = irpol(dir.path(), &command.split(' ').collect::<Vec<_>>());
    assert_eq!(run.code, Some(0), "{}", run.stderr);
    let entry = std::fs::read_to_string(dir.path().join("fits/paper_paint.toml")).unwrap();
    assert!(entry.contains("rho_s = 0.05"), "{entry}");
}

/// The subsurface terms on the shipped glass and paint, whose data cannot determine d and d_c
/// (ρ_s → 0): fitted, the parameters flagged, the entry written (issue 42: refused with "not
/// written: … is not a finite number", blaming the data).
#[test]
fn subsurface_terms_on_the_shipped_glass_and_paint_are_written_with_their_flags() {
    for name in ["smooth_glass", "paper_paint"] {
        let dir = tempfile::tempdir().unwrap();
        let csv = shipped(&format!("measurements/{name}.csv"));
        std::fs::write(dir.path().join("m.csv"), csv).unwrap();
        for terms in ["external+subsurface", "internal+subsurface"] {
            let command = format!("fit m.csv --terms {terms} {QUICK_FIT}");
            let run = irpol(dir.path(), &command.split(' ').collect::<Vec<_>>());
            assert_eq!(run.code, Some(0), "{name} {terms}: {}", run.stderr);
            assert!(!run.stderr.contains("not written"), "{}", run.stderr);
            let entry = std::fs::read_to_string(dir.path().join(format!("fits/{name}.toml")));
            let entry = entry.unwrap();
            assert!(entry.contains(&format!("terms = \"{terms}\"")), "{entry}");
            assert!(entry.contains("rho_s = "), "{entry}");
            assert!(!has_non_finite_value(&entry), "{name} {terms}");
        }
    }
}
