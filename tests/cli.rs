//! The `irpol` binary end to end: outputs that carry physics, and clear one-line errors (no panics)
//! for bad input.

mod common;

use common::irpol;

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
    // `#` lines state the model, then the CSV (issue 16 item 5).
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

/// Issue 16 item 11: `demo` outside the repository says what it needs instead of failing on the
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
            && stderr.contains("missing here: measurements, scenes/car.toml"),
        "{stderr}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Issue 16 item 5: one default shadowing everywhere. `eval` and `emissivity` without
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

/// Issue 16 item 8: `--free` fixes the other parameters; the summary line and the material TOML
/// say at which values, and a parameter both free and fixed is refused.
#[test]
fn fixed_parameters_are_recorded_and_contradictions_refused() {
    let dir = tempfile::tempdir().unwrap();
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let csv = root.join("measurements/rough_paint.csv");
    let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
    let base = [
        "fit",
        csv.to_str().unwrap(),
        "--distribution",
        "cauchy",
        "--out",
        fits.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ];
    let mut args = base.to_vec();
    args.extend(["--free", "sigma,q,n", "--fix", "k=0.05"]);
    let (ok, stdout, stderr) = irpol(&args);
    assert!(ok, "{stderr}");
    assert!(
        stdout.contains("(fixed: k=0.05") && stdout.contains("rho_d=0)"),
        "{stdout}"
    );
    let toml = std::fs::read_to_string(fits.join("rough_paint.toml")).unwrap();
    assert!(
        toml.contains("[fit.fixed_parameters]") && toml.contains("k = 0.05"),
        "{toml}"
    );

    let mut args = base.to_vec();
    args.extend(["--free", "sigma,q,n,k", "--fix", "k=0.05"]);
    let (ok, _, stderr) = irpol(&args);
    assert!(
        !ok && stderr.contains("k is both free and fixed"),
        "{stderr}"
    );
}
