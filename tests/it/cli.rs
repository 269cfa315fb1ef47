//! The `irpol` binary end to end: outputs that carry physics, and clear one-line errors (no panics)
//! for bad input.

use crate::common;

use common::{fit_into, irpol};

/// A column of CSV output, after its `#` header lines.
fn column(csv: &str, name: &str) -> Vec<f64> {
    let mut lines = csv.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let index = header.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(index).unwrap().parse().unwrap())
        .collect()
}

#[test]
fn eval_reproduces_the_scatmech_reference_through_a_geometry_file() {
    let dir = tempfile::tempdir().unwrap();
    let geometry = dir.path().join("geometry.csv");
    std::fs::write(
        &geometry,
        "label,theta_i_deg,phi_i_deg,theta_r_deg,phi_r_deg\nspec,30,0,30,180\noop,10,0,70,90\n",
    )
    .unwrap();
    let sigma = (0.3 / 2f64.sqrt()).to_string();
    let (ok, stdout, stderr) = irpol(&[
        "eval",
        "--distribution",
        "gaussian",
        "--sigma",
        &sigma,
        "--n",
        "1.5",
        "--k",
        "0.1",
        "--shadowing",
        "none",
        "--geometry",
        geometry.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    // `#` lines state the model, then the CSV.
    let mut lines = stdout.lines();
    assert!(
        lines
            .next()
            .unwrap()
            .contains("gaussian slopes, sigma = 0.2121"),
        "{stdout}"
    );
    assert_eq!(
        lines.next().unwrap(),
        "# N = n + ik: n = 1.5, k = 0.1; rho_d = 0; shadowing = none"
    );
    assert!(
        lines
            .next()
            .unwrap()
            .starts_with("label,theta_i_deg,phi_i_deg,theta_r_deg,phi_r_deg,m00,"),
        "{stdout}"
    );
    assert!(
        stdout.contains("\nspec,30,0,30,180,"),
        "extra columns are passed through: {stdout}"
    );
    let m00 = column(&stdout, "m00");
    assert!(
        (m00[0] / 5.08136012e-02 - 1.0).abs() < 1e-8
            && (m00[1] / 8.50772992e-04 - 1.0).abs() < 1e-8
    );
    let m20 = column(&stdout, "m20");
    assert!((m20[1] / 1.65370386e-04 - 1.0).abs() < 1e-7);
}

#[test]
fn emissivity_table_has_the_smooth_limit_and_reports_excess_reflectance() {
    let (ok, stdout, _) = irpol(&[
        "emissivity",
        "--sigma",
        "1e-4",
        "--q",
        "4",
        "--n",
        "1.5",
        "--k",
        "0.1",
        "--shadowing",
        "smith",
        "--theta",
        "60",
    ]);
    assert!(ok);
    let (e0, e1) = (column(&stdout, "e0")[0], column(&stdout, "e1")[0]);
    assert!(
        (e0 - 0.908286).abs() < 2e-6 && (e1 + 0.089534).abs() < 2e-6,
        "{stdout}"
    );
    let (ok, stdout, stderr) = irpol(&[
        "emissivity",
        "--sigma",
        "0.5",
        "--q",
        "1.6",
        "--n",
        "10",
        "--k",
        "60",
        "--shadowing",
        "none",
        "--theta",
        "85:89:2",
    ]);
    assert!(
        ok && stderr.contains("exceeds 1") && stderr.contains("89"),
        "{stderr}"
    );
    assert!(
        column(&stdout, "e0").iter().all(|&e| e < 0.0),
        "reported unclamped: {stdout}"
    );
}

#[test]
fn bad_input_gives_one_clear_line_and_a_failure_exit() {
    let dir = tempfile::tempdir().unwrap();
    let geometry = dir.path().join("g.csv");
    std::fs::write(&geometry, "theta_i_deg,theta_r_deg\n30,30\n95,10\n").unwrap();
    let g = geometry.to_str().unwrap();
    let geometry_arg = format!("eval --sigma 0.1 --q 1.8 --n 1.2 --k 0.2 --geometry {g}");
    let cases: Vec<(&str, &str)> = vec![
        (&geometry_arg, "g.csv:3: theta_i_deg = 95° is invalid"),
        (
            "eval --sigma 0.1 --q 1.8 --n 1.2 --k 0.2 --geometry /nonexistent.csv",
            "/nonexistent.csv: cannot open",
        ),
        (
            "eval --sigma -0.1 --q 1.8 --n 1.2 --k 0.2 --theta-i 0 --theta-r 0",
            "σ = -0.1",
        ),
        (
            "eval --sigma 0.1 --q 1.2 --n 1.2 --k 0.2 --shadowing smith --theta-i 0 --theta-r 0",
            "q > 1.5",
        ),
        (
            "eval --sigma 0.1 --q 1.8 --n 1.2 --k -1 --theta-i 0 --theta-r 0",
            "k = -1",
        ),
        (
            "eval --sigma 0.1 --q 1.8 --n 1.2 --k 0.2 --theta-i NaN --theta-r 0",
            "not finite",
        ),
        (
            "eval --sigma 0.1 --q 1.8 --n 1.2 --k 0.2 --theta-i 10 --theta-r 0:100:10",
            "theta_r_deg = 90° is invalid",
        ),
        (
            "emissivity --material /no/such.toml",
            "/no/such.toml: cannot read",
        ),
        ("emissivity --sigma 0.1 --n 1 --k 0", "missing --q"),
    ];
    for (command, needle) in cases {
        let args: Vec<&str> = command.split(' ').collect();
        let (ok, stdout, stderr) = irpol(&args);
        assert!(!ok, "{args:?} succeeded: {stdout}");
        assert!(
            stderr.contains(needle),
            "{args:?}: {stderr:?} lacks {needle:?}"
        );
        assert!(
            !stderr.contains("panicked") && stderr.lines().count() == 1,
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn fit_with_one_bad_file_writes_nothing_and_render_refuses_a_missing_scene() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, "theta_i_deg;theta_r_deg;m00\n30;30;0.1\n").unwrap();
    let good = concat!(env!("CARGO_MANIFEST_DIR"), "/measurements/paper_paint.csv");
    let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
    let (ok, _, stderr) = irpol(&[
        "fit",
        good,
        bad.to_str().unwrap(),
        "--out",
        fits.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("bad.csv:1:") && stderr.contains("';'"),
        "{stderr}"
    );
    assert!(
        !fits.exists() && !reports.exists(),
        "a failed fit must write nothing"
    );

    let (ok, _, stderr) = irpol(&[
        "render",
        "/no/scene.toml",
        "--out",
        dir.path().join("out").to_str().unwrap(),
    ]);
    assert!(
        !ok && stderr.contains("/no/scene.toml") && stderr.lines().count() == 1,
        "{stderr}"
    );
    assert!(!dir.path().join("out").exists());
}

/// `demo` outside the repository says what it needs instead of failing on the
/// first missing file, and writes nothing.
#[test]
fn demo_outside_the_repository_says_what_it_needs() {
    let dir = tempfile::tempdir().unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
        .arg("demo")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("must be started from its root folder")
            && stderr.contains("missing here: measurements, fits, scenes/car.toml"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// One default shadowing everywhere. `eval` and `emissivity` without
/// `--shadowing` use Smith, as `fit` does, and say so in their header.
#[test]
fn eval_and_emissivity_default_to_smith_shadowing() {
    let model = ["--sigma", "0.3", "--q", "2", "--n", "1.5", "--k", "0.1"];
    let eval = |extra: &[&str]| {
        let mut args = vec!["eval", "--theta-i", "60", "--theta-r", "80"];
        args.extend_from_slice(&model);
        args.extend_from_slice(extra);
        let (ok, stdout, stderr) = irpol(&args);
        assert!(ok, "{stderr}");
        (stdout.clone(), column(&stdout, "m00")[0])
    };
    let (default, m00) = eval(&[]);
    assert!(default.contains("shadowing = smith"), "{default}");
    assert_eq!(m00, eval(&["--shadowing", "smith"]).1);
    assert!(
        m00 < eval(&["--shadowing", "none"]).1,
        "Smith shadows at 80°"
    );
    let mut args = vec!["emissivity", "--theta", "60"];
    args.extend_from_slice(&model);
    let (ok, stdout, _) = irpol(&args);
    assert!(ok && stdout.contains("shadowing = smith"), "{stdout}");
}

/// `--free` fixes the other parameters; the summary line and the material TOML
/// say at which values, and a parameter both free and fixed is refused.
#[test]
fn fixed_parameters_are_recorded_and_contradictions_refused() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let csv = root.join("measurements/rough_paint.csv");
    let fit = |extra: &[&str]| {
        let mut args = vec!["--distribution", "cauchy"];
        args.extend_from_slice(extra);
        fit_into(dir.path(), &[&csv], &args)
    };
    let (ok, stdout, stderr) = fit(&["--free", "sigma,q,n", "--fix", "k=0.05"]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("(fixed: k=0.05") && stdout.contains("rho_d=0)"),
        "{stdout}"
    );
    let toml = std::fs::read_to_string(dir.path().join("fits/rough_paint.toml")).unwrap();
    assert!(
        toml.contains("[fit.fixed_parameters]") && toml.contains("k = 0.05"),
        "{toml}"
    );

    let (ok, _, stderr) = fit(&["--free", "sigma,q,n,k", "--fix", "k=0.05"]);
    assert!(
        !ok && stderr.contains("k is both free and fixed"),
        "{stderr}"
    );
}

/// The model flags of the signed-angle tests.
const EVAL_MODEL: [&str; 8] = ["--sigma", "0.2", "--q", "2", "--n", "1.5", "--k", "0.1"];

/// `irpol eval` with the model above and `args`: (stdout, stderr), asserting success.
fn eval(args: &[&str]) -> (String, String) {
    let mut all = vec!["eval"];
    all.extend_from_slice(&EVAL_MODEL);
    all.extend_from_slice(args);
    let (ok, stdout, stderr) = irpol(&all);
    assert!(ok, "{all:?}: {stderr}");
    (stdout, stderr)
}

/// The 16 Mueller values of each data row.
fn mueller_rows(csv: &str) -> Vec<Vec<String>> {
    csv.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').rev().take(16).map(str::to_owned).collect())
        .collect()
}

/// A signed detector zenith θ_r < 0 is the detector across the normal,
/// (|θ_r|, φ_r + 180°), in sweeps and geometry files, with one note; rows are echoed as given.
#[test]
fn eval_reads_signed_theta_r_across_the_normal() {
    let (signed, note) = eval(&["--theta-i", "40", "--theta-r", "-30", "--phi-r", "180"]);
    let (unsigned, quiet) = eval(&["--theta-i", "40", "--theta-r", "30", "--phi-r", "0"]);
    assert_eq!(mueller_rows(&signed), mueller_rows(&unsigned));
    assert!(
        signed.contains("\n40,0,-30,180,"),
        "echoed as given: {signed}"
    );
    assert_eq!(
        note,
        "irpol: note: --theta-r: 1 row with θ_r < 0 read as (|θ_r|, φ_r + 180°)\n"
    );
    assert_eq!(quiet, "");

    let (sweep, note) = eval(&["--theta-i", "40", "--theta-r", "-80:80:10"]);
    assert_eq!(mueller_rows(&sweep).len(), 17);
    assert_eq!(note.lines().count(), 1, "{note}");
    assert!(note.contains(": 8 rows with θ_r < 0"), "{note}");

    let dir = tempfile::tempdir().unwrap();
    let geometry = dir.path().join("g.csv");
    std::fs::write(
        &geometry,
        "theta_i_deg,theta_r_deg,phi_r_deg\n40,-30,180\n40,30,0\n40,-20,90\n",
    )
    .unwrap();
    let (table, note) = eval(&["--geometry", geometry.to_str().unwrap()]);
    let rows = mueller_rows(&table);
    assert_eq!(rows[0], rows[1]);
    assert!(table.contains("\n40,-30,180,"), "{table}");
    assert_eq!(
        note,
        format!(
            "irpol: note: {}: 2 rows with θ_r < 0 read as (|θ_r|, φ_r + 180°)\n",
            geometry.display()
        )
    );

    std::fs::write(&geometry, "theta_i_deg,theta_r_deg\n40,-30\n40,-90\n").unwrap();
    let mut args = vec!["eval"];
    args.extend_from_slice(&EVAL_MODEL);
    args.extend(["--geometry", geometry.to_str().unwrap()]);
    let (ok, _, stderr) = irpol(&args);
    assert!(
        !ok && stderr.contains("g.csv:3: theta_r_deg = -90° is invalid")
            && stderr.contains("(−90°, 90°)")
            && stderr.lines().count() == 1,
        "{stderr}"
    );
}

/// `--phi-r` sweeps like `--theta-r`; rows run over φ_r within each θ_r, and
/// the sweep bound holds for the product.
#[test]
fn eval_sweeps_phi_r_inside_theta_r() {
    let (table, _) = eval(&[
        "--theta-i",
        "30",
        "--theta-r",
        "10:20:10",
        "--phi-r",
        "0:180:90",
    ]);
    let geometry: Vec<String> = table
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| l.split(',').take(4).collect::<Vec<_>>().join(","))
        .collect();
    assert_eq!(
        geometry,
        [
            "30,0,10,0",
            "30,0,10,90",
            "30,0,10,180",
            "30,0,20,0",
            "30,0,20,90",
            "30,0,20,180"
        ]
    );
    let mut args = vec!["eval"];
    args.extend_from_slice(&EVAL_MODEL);
    args.extend([
        "--theta-i",
        "0:89:0.01",
        "--theta-r",
        "0:89:0.1",
        "--phi-r",
        "0:10:1",
    ]);
    let (ok, stdout, stderr) = irpol(&args);
    assert!(
        !ok && stdout.is_empty() && stderr.contains("at most 10000000"),
        "{stderr}"
    );
}

/// A measurement CSV of material `paint` at `wavelength` µm from SCATMECH-free synthetic rows:
/// m00 and m10 of the model of [`EVAL_MODEL`] at the given (θ_i, θ_r, φ_r), as `irpol eval`
/// computes them.
fn measurement_file(path: &std::path::Path, wavelength: &str, geometry: &[(f64, f64, f64)]) {
    let dir = path.parent().unwrap();
    let g = dir.join(".geometry.csv");
    let mut text = "theta_i_deg,theta_r_deg,phi_r_deg\n".to_owned();
    for (ti, tr, pr) in geometry {
        text.push_str(&format!("{ti},{tr},{pr}\n"));
    }
    std::fs::write(&g, text).unwrap();
    let (table, _) = eval(&["--geometry", g.to_str().unwrap()]);
    let (m00, m10) = (column(&table, "m00"), column(&table, "m10"));
    let mut csv = format!(
        "# material: paint\n# wavelength_um: {wavelength}\ntheta_i_deg,theta_r_deg,phi_r_deg,m00,m10\n"
    );
    for (((ti, tr, pr), a), b) in geometry.iter().zip(m00).zip(m10) {
        csv.push_str(&format!("{ti},{tr},{pr},{a:e},{b:e}\n"));
    }
    std::fs::write(path, csv).unwrap();
    std::fs::remove_file(g).unwrap();
}

/// In-plane scans at θ_i = 20°, 40°, 60°, detector −80…80° in `step`° steps.
fn in_plane_scan(step: usize) -> Vec<(f64, f64, f64)> {
    let mut geometry = Vec::new();
    for ti in [20.0, 40.0, 60.0] {
        for tr in (-80..=80).step_by(step) {
            geometry.push((ti, tr as f64, 180.0));
        }
    }
    geometry
}

/// A measurement file with signed θ_r fits (with one note), two files
/// of one material at one wavelength are merged as repeat measurements with a note, recorded in
/// the TOML, and `irpol report` rebuilds from both; with another wavelength they are one spectral
/// material.
#[test]
fn fit_merges_repeat_files_of_one_material_and_reads_signed_angles() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, far) = (
        dir.path().join("a.csv"),
        dir.path().join("b.csv"),
        dir.path().join("far.csv"),
    );
    measurement_file(&a, "10", &in_plane_scan(10));
    measurement_file(&b, "10.0000004", &in_plane_scan(20));
    measurement_file(&far, "10.6", &in_plane_scan(20));
    let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
    let fit = |inputs: &[&std::path::Path]| {
        let mut args = vec!["fit".to_owned()];
        args.extend(inputs.iter().map(|p| p.display().to_string()));
        args.extend(
            [
                "--distribution",
                "cauchy",
                "--optimizer",
                "lm",
                "--free",
                "sigma,q,n",
                "--fix",
                "k=0.1",
            ]
            .map(str::to_owned),
        );
        args.extend(["--out".to_owned(), fits.display().to_string()]);
        args.extend(["--reports".to_owned(), reports.display().to_string()]);
        irpol(&args.iter().map(String::as_str).collect::<Vec<_>>())
    };

    let (ok, stdout, stderr) = fit(&[&a, &far]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("paint: cauchy table, 2 wavelengths 10–10.6 µm: sigma=0.2"),
        "{stdout}"
    );
    let spectral = irpol::material::Material::load(&fits.join("paint.toml")).unwrap();
    assert_eq!(spectral.model.wavelengths_um(), [10.0, 10.6]);

    let (ok, stdout, stderr) = fit(&[&a, &b]);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("paint: cauchy sigma=0.2") && stdout.contains("q=2.0000"),
        "{stdout}"
    );
    let expected = [
        format!(
            "irpol: note: {}: 24 rows with θ_r < 0 read as (|θ_r|, φ_r + 180°)",
            a.display()
        ),
        format!(
            "irpol: note: {}: 12 rows with θ_r < 0 read as (|θ_r|, φ_r + 180°)",
            b.display()
        ),
        format!(
            "irpol: note: paint: merged {} (51 rows) and {} (27 rows) as repeat measurements",
            a.display(),
            b.display()
        ),
    ];
    assert_eq!(stderr.lines().collect::<Vec<_>>(), expected);
    let entry = fits.join("paint.toml");
    let material = irpol::material::Material::load(&entry).unwrap();
    let record = material.fit.unwrap();
    assert_eq!((record.source.as_path(), record.points), (a.as_path(), 78));
    assert_eq!(record.merged_sources.len(), 1);
    assert_eq!(
        (
            record.merged_sources[0].source.as_path(),
            record.merged_sources[0].points
        ),
        (b.as_path(), 27)
    );

    std::fs::remove_dir_all(&reports).unwrap();
    let (ok, stdout, stderr) = irpol(&[
        "report",
        entry.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert!(ok && stdout.contains("paint.png"), "{stderr}");
    // A comment in the merged file changes its bytes, not its data: the report rebuilds.
    std::fs::write(
        &b,
        std::fs::read_to_string(&b).unwrap() + "# re-checked the lamp\n",
    )
    .unwrap();
    let report = || {
        irpol(&[
            "report",
            entry.to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ])
    };
    let (ok, _, stderr) = report();
    assert!(ok, "{stderr}");
    std::fs::write(
        &b,
        std::fs::read_to_string(&b).unwrap() + "40,10,180,0.1,0.0\n",
    )
    .unwrap();
    let (ok, _, stderr) = report();
    assert!(
        !ok && stderr.contains("b.csv: the data changed") && stderr.contains("1 data row added"),
        "{stderr}"
    );
}

/// `irpol library` takes the folder `irpol fit --out` wrote as an argument,
/// and still as `--dir`.
#[test]
fn library_takes_its_folder_as_an_argument_or_dir() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let fits = root.join("fits");
    for args in [
        vec!["library", fits.to_str().unwrap()],
        vec!["library", "--dir", fits.to_str().unwrap()],
    ] {
        let (ok, stdout, stderr) = irpol(&args);
        assert!(ok, "{args:?}: {stderr}");
        assert!(
            stdout.starts_with("material") && stdout.contains("paper_paint"),
            "{args:?}: {stdout}"
        );
    }
    let empty = tempfile::tempdir().unwrap();
    let (ok, stdout, _) = irpol(&["library", empty.path().to_str().unwrap()]);
    assert!(ok && stdout.starts_with("no materials in"), "{stdout}");
}

/// A file in the library folder that is not a material (notes, an old draft) does not stop a
/// fit: the index skips it with a warning naming it, and the file is left as it was.
#[test]
fn fit_skips_a_file_in_the_library_that_is_not_a_material_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let fits = dir.path().join("fits");
    std::fs::create_dir_all(&fits).unwrap();
    std::fs::write(fits.join("notes.toml"), "todo = [\"refit glass\"]\n").unwrap();
    let good =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/paper_paint.csv");
    let (ok, _, stderr) = fit_into(dir.path(), &[&good], &["--optimizer", "lm"]);
    assert!(ok, "{stderr}");
    let warning = stderr
        .lines()
        .find(|l| l.starts_with("irpol: warning: ") && l.contains("notes.toml"))
        .unwrap_or_else(|| panic!("no warning naming notes.toml in {stderr}"));
    assert!(
        warning.contains("not a valid material TOML") && warning.contains("skipped"),
        "{warning}"
    );
    assert!(fits.join("paper_paint.toml").is_file());
    let index = std::fs::read_to_string(dir.path().join("reports/index.html")).unwrap();
    assert!(
        index.contains("paper_paint") && !index.contains("notes"),
        "index lists notes"
    );
    assert_eq!(
        std::fs::read_to_string(fits.join("notes.toml")).unwrap(),
        "todo = [\"refit glass\"]\n"
    );
}

/// Every error that quotes input quotes it cut short and with control characters escaped: a
/// scene name, a scene value the TOML reader quotes, a `--times` spec.
#[test]
fn quoted_input_is_cut_short_and_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let scene = |object_name: &str| {
        format!(
            "{}{}{}[[objects]]\nname = \"{object_name}\"\n\
             shape = {{ kind = \"sphere\", radius = 1.0, subdivisions = 1 }}\n\
             material = \"m\"\ntemperature_k = 300.0\n",
            common::camera_toml(8),
            common::AUTUMN_ENVIRONMENT,
            common::material_toml(0.2, 2.0, 1.5, 0.1, 0.05),
        )
    };
    let render = |text: &str, extra: &[&str]| {
        let path = dir.path().join("scene.toml");
        std::fs::write(&path, text).unwrap();
        let out = dir.path().join("out");
        let mut args = vec![
            "render",
            path.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let (ok, _, stderr) = irpol(&args);
        assert!(!ok && !out.exists(), "{stderr}");
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(stderr.chars().count() < 400, "{stderr}");
        assert!(
            !stderr.trim_end().chars().any(char::is_control),
            "{stderr:?}"
        );
        stderr
    };
    let long = "b".repeat(300);
    let stderr = render(&scene(&long), &[]);
    assert!(
        stderr.contains(&format!(
            "objects[0].name: the name '{}…' is 300 characters long; at most 100",
            "b".repeat(40)
        )),
        "{stderr}"
    );
    let stderr = render(&scene("car\\u001eleft"), &[]);
    assert!(
        stderr.contains("objects[0].name: the name 'car\\u{1e}left' contains a control character"),
        "{stderr}"
    );
    // The TOML reader's own message quotes the bad value: cut and escaped too.
    let bad_kind = scene("ball").replace("\"sphere\"", &format!("\"sph\\u001e{long}\""));
    let stderr = render(&bad_kind, &[]);
    assert!(stderr.contains("not a valid scene: line"), "{stderr}");
    let spec = format!("0:{}:1\u{1e}", "9".repeat(100_000));
    let stderr = render(&scene("ball"), &["--times", &spec]);
    assert!(
        stderr.contains(&format!("--times: '{}…' is not finite", "9".repeat(40))),
        "{stderr}"
    );
}
