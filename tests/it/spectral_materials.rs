//! Spectral materials (docs/design.md §1.9): a material whose n, k, ρ_d are tables over
//! wavelength is the pBRDF of SCATMECH at each wavelength; the shipped silicate_glass set (made
//! with SCATMECH from a Lorentz law, scripts/make_measurements.py) is recovered by the joint fit
//! and its Lorentz law found; bad spectral input is refused on one line.

use irpol::fit::{fit_inputs, Dispersion, FitOptions, MaterialFit};
use irpol::material::{Material, MaterialModel, SpectralModel};
use irpol::pbrdf::{Direction, Shadowing, SlopeDistribution};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The rows of the SCATMECH fixture, by column name.
fn fixture() -> Vec<HashMap<String, f64>> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(root().join("tests/data/scatmech_spectral.csv"))
        .unwrap();
    let headers = reader.headers().unwrap().clone();
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            headers
                .iter()
                .zip(r.iter())
                .map(|(h, v)| (h.to_owned(), v.parse().unwrap()))
                .collect()
        })
        .collect()
}

/// A spectral material with the fixture's wavelengths and indices, plus a node between two of
/// them (so that the fixture's wavelengths are not only the table's ends), written as TOML and
/// read back: the file format is part of what is tested.
fn fixture_material(dir: &Path) -> Material {
    let mut nodes: Vec<(f64, f64, f64)> = fixture()
        .iter()
        .map(|r| (r["wavelength_um"], r["n"], r["k"]))
        .collect();
    nodes.dedup();
    nodes.insert(1, (8.5, 0.6, 1.3));
    let model = SpectralModel {
        distribution: SlopeDistribution::Cauchy {
            sigma: 0.06,
            q: 2.8,
        },
        shadowing: Shadowing::Smith,
        wavelength_um: nodes.iter().map(|n| n.0).collect(),
        n: nodes.iter().map(|n| n.1).collect(),
        k: nodes.iter().map(|n| n.2).collect(),
        rho_d: vec![0.0; nodes.len()],
        volume: Default::default(),
        dispersion: None,
    };
    let material = Material {
        name: "silicate_glass".into(),
        tool_version: "test".into(),
        model: MaterialModel::Spectral(model),
        fit: None,
    };
    let path = dir.join("silicate_glass.toml");
    material.save(&path).unwrap();
    let loaded = Material::load(&path).unwrap();
    assert_eq!(loaded, material);
    loaded
}

/// Acceptance 1: at three wavelengths with very different N (n < 1 at 8 µm, k = 2.1 at 9 µm,
/// nearly transparent at 11.5 µm) the material's pBRDF is SCATMECH's: m00 within 1e-9 relative,
/// every element within 1e-9·m00.
#[test]
fn a_spectral_material_is_scatmech_at_each_wavelength() {
    let dir = tempfile::tempdir().unwrap();
    let material = fixture_material(dir.path());
    let mut wavelengths = Vec::new();
    for row in fixture() {
        let model = material.at(row["wavelength_um"]).unwrap();
        assert_eq!((model.n, model.k), (row["n"], row["k"]));
        let pbrdf = model.pbrdf().unwrap();
        let direction =
            |t: &str, p: &str| Direction::from_angles(row[t].to_radians(), row[p].to_radians());
        let got = pbrdf.mueller(
            &direction("theta_i_deg", "phi_i_deg"),
            &direction("theta_r_deg", "phi_r_deg"),
        );
        let m00 = row["m00"];
        for r in 0..4 {
            for c in 0..4 {
                let want = row[&format!("m{r}{c}")];
                let error = (got[(r, c)] - want).abs() / m00;
                assert!(
                    error < 1e-9,
                    "λ {} m{r}{c}: {} vs {want}",
                    row["wavelength_um"],
                    got[(r, c)]
                );
            }
        }
        wavelengths.push(row["wavelength_um"]);
    }
    wavelengths.dedup();
    assert_eq!(wavelengths, [8.0, 9.0, 11.5]);
}

/// `irpol eval --wavelength` evaluates the table there; outside it, it refuses with the
/// material's name and range; a spectral material without --wavelength is refused.
#[test]
fn eval_takes_a_wavelength_and_refuses_one_outside_the_table() {
    let dir = tempfile::tempdir().unwrap();
    let material = fixture_material(dir.path());
    let path = dir.path().join("silicate_glass.toml");
    let eval = |extra: &[&str]| {
        let mut args = vec!["eval", "--material", path.to_str().unwrap()];
        args.extend(["--theta-i", "30", "--theta-r", "30"]);
        args.extend(extra);
        std::process::Command::new(env!("CARGO_BIN_EXE_irpol"))
            .args(&args)
            .output()
            .unwrap()
    };
    let out = eval(&["--wavelength", "8.25"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    // The row after the CSV header; m00 follows theta_i, phi_i, theta_r, phi_r.
    let row = text.lines().filter(|l| !l.starts_with('#')).nth(1).unwrap();
    let m00: f64 = row.split(',').nth(4).unwrap().parse().unwrap();
    let model = material.at(8.25).unwrap();
    assert!((model.n - 0.5 * (material.at(8.0).unwrap().n + 0.6)).abs() < 1e-15);
    let want = model.pbrdf().unwrap().mueller(
        &Direction::from_angles(30f64.to_radians(), 0.0),
        &Direction::from_angles(30f64.to_radians(), std::f64::consts::PI),
    )[(0, 0)];
    assert!((m00 / want - 1.0).abs() < 1e-9, "{m00} vs {want}");

    for (extra, needle) in [
        (
            &["--wavelength", "14"][..],
            "material 'silicate_glass': wavelength 14 µm is outside its table, 8–11.5 µm",
        ),
        (
            &[][..],
            "material 'silicate_glass' is spectral (8–11.5 µm): give --wavelength UM",
        ),
    ] {
        let out = eval(extra);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success() && stderr.contains(needle), "{stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
}

fn fit_silicate(inputs: &[PathBuf], dispersion: Dispersion) -> Box<irpol::fit::SpectralFitOutcome> {
    let options = FitOptions {
        dispersion,
        ..FitOptions::default()
    };
    match fit_inputs(inputs, &options, &irpol::progress::Silent)
        .unwrap()
        .remove(0)
    {
        MaterialFit::Spectral(outcome) => outcome,
        MaterialFit::Grey(_) => panic!("the silicate set is spectral"),
    }
}

/// The truth of the shipped set, from its header lines.
fn silicate_truth() -> Vec<(f64, f64, f64)> {
    let text = std::fs::read_to_string(root().join("measurements/silicate_glass.csv")).unwrap();
    let line = text
        .lines()
        .find_map(|l| l.strip_prefix("# truth_n_k: "))
        .unwrap();
    line.split(", ")
        .map(|entry| {
            let (w, nk) = entry.split_once(':').unwrap();
            let (n, k) = nk.trim_end_matches('i').split_once('+').unwrap();
            (w.parse().unwrap(), n.parse().unwrap(), k.parse().unwrap())
        })
        .collect()
}

/// Acceptance 2: σ within 1 %, q 3 %, every n(λ) 1.5 %, k(λ) max(0.02, 5 %), ρ_d 0.003; the
/// Lorentz fit finds the resonance within 1 %.
#[test]
fn the_shipped_spectral_set_is_recovered_and_its_resonance_found() {
    let csv = root().join("measurements/silicate_glass.csv");
    let outcome = fit_silicate(std::slice::from_ref(&csv), Dispersion::Table);
    let model = &outcome.chosen.model;
    let SlopeDistribution::Cauchy { sigma, q } = model.distribution else {
        panic!("the truth is Cauchy: {:?}", model.distribution);
    };
    assert!((sigma / 0.06 - 1.0).abs() < 0.01, "σ = {sigma}");
    assert!((q / 2.8 - 1.0).abs() < 0.03, "q = {q}");
    let truth = silicate_truth();
    assert_eq!(truth.len(), 9);
    for (j, &(w, n, k)) in truth.iter().enumerate() {
        assert_eq!(model.wavelength_um[j], w);
        assert!(
            (model.n[j] / n - 1.0).abs() < 0.015,
            "n({w}) = {} vs {n}",
            model.n[j]
        );
        let k_tolerance = (0.05 * k).max(0.02);
        assert!(
            (model.k[j] - k).abs() < k_tolerance,
            "k({w}) = {} vs {k}",
            model.k[j]
        );
        assert!(
            model.rho_d[j].abs() < 0.003,
            "ρ_d({w}) = {}",
            model.rho_d[j]
        );
        // The stated errors are honest: the truth within 4σ.
        assert!((model.n[j] - n).abs() < 4.0 * outcome.chosen.n_errors[j] + 1e-5);
    }
    assert!(
        outcome.chosen.reduced_chi2 < 1.1,
        "{}",
        outcome.chosen.reduced_chi2
    );

    let lorentz = fit_silicate(&[csv], Dispersion::Lorentz(1));
    let law = lorentz.chosen.model.dispersion.as_ref().unwrap();
    let resonance = law.oscillators[0].resonance_um;
    assert!(
        (resonance / 9.3 - 1.0).abs() < 0.01,
        "resonance {resonance} µm"
    );
    // The record compares the two dispersions by AIC.
    let choice = lorentz
        .material
        .fit
        .as_ref()
        .unwrap()
        .dispersion
        .clone()
        .unwrap();
    assert_eq!(choice.chosen, "lorentz:1");
    assert!(choice.law_aic.unwrap() < choice.table_aic, "{choice:?}");

    // `irpol report` cannot rebuild a spectral report from the entry alone, and says so.
    let dir = tempfile::tempdir().unwrap();
    let entry = dir.path().join("fits/silicate_glass.toml");
    lorentz.material.save(&entry).unwrap();
    let message = irpol::report::fit_report::rebuild_report(&entry, &dir.path().join("reports"))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("a spectral material's report is written by `irpol fit`"),
        "{message}"
    );
    assert!(!dir.path().join("reports").exists());
}

/// The same spectral set as a folder of one file per wavelength (each with `# material:`)
/// fits to the same model as the one file with a wavelength column.
#[test]
fn a_folder_of_files_per_wavelength_is_one_spectral_set() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root().join("measurements/silicate_glass.csv")).unwrap();
    let header: Vec<&str> = text.lines().take_while(|l| l.starts_with('#')).collect();
    let columns = text.lines().find(|l| !l.starts_with('#')).unwrap();
    let mut by_wavelength: Vec<(String, Vec<&str>)> = Vec::new();
    for row in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let w = row.split(',').nth(4).unwrap().to_owned();
        match by_wavelength.iter_mut().find(|(x, _)| *x == w) {
            Some((_, rows)) => rows.push(row),
            None => by_wavelength.push((w, vec![row])),
        }
    }
    for (w, rows) in &by_wavelength {
        let body = [header.join("\n"), columns.to_owned(), rows.join("\n")].join("\n");
        std::fs::write(dir.path().join(format!("glass_{w}um.csv")), body).unwrap();
    }
    let folder = fit_silicate(&[dir.path().to_path_buf()], Dispersion::Table);
    let file = fit_silicate(
        &[root().join("measurements/silicate_glass.csv")],
        Dispersion::Table,
    );
    assert_eq!(folder.chosen.model, file.chosen.model);
}

/// Bad spectral input: a folder mixing files without `# material:`, and files of one material
/// that disagree on the Mueller convention, are refused naming the files; nothing is fitted.
#[test]
fn ambiguous_spectral_folders_are_refused_naming_files() {
    let dir = tempfile::tempdir().unwrap();
    let file = |name: &str, header: &str, w: f64| {
        let body = format!(
            "{header}# wavelength_um: {w}\ntheta_i_deg,theta_r_deg,m00\n30,30,1.0\n30,20,0.1\n\
             30,40,0.1\n30,25,0.4\n30,35,0.4\n"
        );
        std::fs::write(dir.path().join(name), body).unwrap();
    };
    file("a_8um.csv", "", 8.0);
    file("a_9um.csv", "", 9.0);
    let message = fit_inputs(
        &[dir.path().to_path_buf()],
        &FitOptions::default(),
        &irpol::progress::Silent,
    )
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("a_8um.csv") && message.contains("has no '# material:' line"),
        "{message}"
    );
    assert!(!message.contains('\n'));

    file("a_8um.csv", "# material: a\n# distribution: cauchy\n", 8.0);
    file(
        "a_9um.csv",
        "# material: a\n# distribution: gaussian\n",
        9.0,
    );
    let message = fit_inputs(
        &[dir.path().to_path_buf()],
        &FitOptions::default(),
        &irpol::progress::Silent,
    )
    .unwrap_err()
    .to_string();
    assert!(
        message.contains("a_9um.csv")
            && message.contains("a_8um.csv")
            && message.contains("disagrees"),
        "{message}"
    );
}
