//! The volume-scattering terms of docs/design.md §1.10 — internal facets and the polarized
//! subsurface term — against closed-form limits (today's ideal depolarizer, reciprocity, energy),
//! recovery from data made by the independent numpy implementation (scripts/
//! make_volume_measurements.py, tests/data/volume/), the choice of terms by AIC and
//! cross-validation, the energy constraint of the fit and `irpol validate`.

use irpol::fit::{fit_grey, largest_reflectance, FitOptions, ENERGY_TOLERANCE};
use irpol::material::Material;
use irpol::measure::read_measurement_csv;
use irpol::optics::{Mueller, RefractiveIndex};
use irpol::pbrdf::{
    Body, Direction, FacetSide, HemisphereQuadrature, ModelTerms, Parameter, Pbrdf, Shadowing,
    SlopeDistribution, Subsurface, Term, Transmission,
};
use std::path::Path;
use std::process::Command;

fn irpol() -> Command {
    Command::new(env!("CARGO_BIN_EXE_irpol"))
}

fn model(n: f64, k: f64, rho_d: f64, side: FacetSide, subsurface: Option<Subsurface>) -> Pbrdf {
    Pbrdf::new(
        SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
        Shadowing::Smith,
        RefractiveIndex::new(n, k),
        rho_d,
    )
    .unwrap()
    .with_volume(side, subsurface)
    .unwrap()
}

fn subsurface(rho_s: f64, d: f64) -> Option<Subsurface> {
    Some(Subsurface {
        term: Term::Subsurface,
        rho_s,
        d,
        n_sub: None,
        d_c: None,
        d1: None,
    })
}

/// Directions over the hemisphere, away from the horizon.
fn directions() -> Vec<Direction> {
    let mut out = Vec::new();
    for theta in [0.0, 12.0, 33.0, 51.0, 68.0, 80.0] {
        for phi in [0.0, 47.0, 133.0, 180.0, 251.0] {
            out.push(Direction::from_degrees(theta, phi));
        }
    }
    out
}

/// With N = 1 and d = 0 the subsurface term is today's ideal depolarizer (ρ/π) diag(1,0,0,0)
/// bit for bit: every Fresnel reflectance is exactly 0 and the normalization exactly 1.
#[test]
fn index_matched_subsurface_term_is_the_ideal_depolarizer_bit_for_bit() {
    let depolarizer = model(1.0, 0.0, 0.37, FacetSide::External, None);
    let subsurface_term = model(1.0, 0.0, 0.0, FacetSide::External, subsurface(0.37, 0.0));
    for i in directions() {
        for r in directions() {
            let (a, b) = (depolarizer.mueller(&i, &r), subsurface_term.mueller(&i, &r));
            assert!(a.iter().zip(b.iter()).all(|(x, y)| x == y), "{a} {b}");
        }
    }
}

/// Sekera's reciprocity M(ω_r→ω_i) = Q M(ω_i→ω_r)ᵀ Q with the Q that makes §1.3's facet term
/// reciprocal, diag(1, 1, −1, 1), holds for internal facets and the subsurface term too.
#[test]
fn every_term_is_reciprocal_with_the_facet_terms_q() {
    let q = Mueller::from_diagonal(&nalgebra::Vector4::new(1.0, 1.0, -1.0, 1.0));
    let models = [
        model(1.5, 0.1, 0.0, FacetSide::External, None),
        model(1.35, 0.0, 0.0, FacetSide::Internal, None),
        model(1.6, 0.2, 0.0, FacetSide::Internal, None),
        model(1.0, 0.0, 0.0, FacetSide::External, subsurface(0.8, 0.6)),
        model(1.45, 0.02, 0.05, FacetSide::Internal, subsurface(0.9, 0.3)),
        // d(Θ) = d + d1 cos Θ: cos Θ = −ω_i·ω_r is symmetric in the two directions.
        model(
            1.3,
            0.0,
            0.0,
            FacetSide::External,
            Some(Subsurface {
                term: Term::Subsurface,
                rho_s: 0.9,
                d: 0.3,
                n_sub: Some(1.1),
                d_c: Some(0.61),
                d1: Some(-0.5),
            }),
        ),
    ];
    for (m, pbrdf) in models.iter().enumerate() {
        for i in directions() {
            for r in directions() {
                let forward = pbrdf.mueller(&i, &r);
                let backward = pbrdf.mueller(&r, &i);
                let error = (backward - q * forward.transpose() * q).abs().max();
                assert!(
                    error <= 1e-12 * forward[(0, 0)].max(1e-300),
                    "model {m}: {error}"
                );
            }
        }
    }
}

/// The subsurface term's directional-hemispherical reflectance is at most ρ_s (1 − R(θ_i)) ≤ ρ_s
/// over a parameter grid (its normalization Z), and the model's Mueller matrices are all
/// realizable (Cloude's coherency eigenvalues ≥ 0).
#[test]
fn subsurface_term_conserves_energy_and_stays_realizable() {
    let quadrature = HemisphereQuadrature::default();
    // d_c absent (= d) and at the edge of the realizable values, 2d − 1; with d1, the edge
    // 2(|d| + |d1|) − 1 of an angle-dependent d(Θ) = d + d1 cos Θ (|d| + |d1| up to 1).
    let cases = [0.0, 0.4, 1.0]
        .into_iter()
        .flat_map(|d| [(d, None, None), (d, Some(2.0 * d - 1.0), None)])
        .chain([
            (0.3, Some(0.61), Some(-0.5)),
            (0.0, Some(0.2), Some(0.6)),
            (0.5, Some(1.0), Some(0.5)),
        ]);
    for n in [1.0, 1.3, 1.6, 2.4] {
        for (d, d_c, d1) in cases.clone() {
            let only_subsurface = Pbrdf::new(
                SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
                Shadowing::Smith,
                RefractiveIndex::new(1.0, 0.0),
                0.0,
            )
            .unwrap()
            .with_volume(
                FacetSide::External,
                Some(Subsurface {
                    term: Term::Subsurface,
                    rho_s: 1.0,
                    d,
                    n_sub: Some(n),
                    d_c,
                    d1,
                }),
            )
            .unwrap();
            let eps = RefractiveIndex::new(n, 0.0).permittivity();
            for theta in [0.0f64, 30.0, 60.0, 80.0, 89.0] {
                let albedo = only_subsurface
                    .directional_hemispherical_reflectance(theta.to_radians(), &quadrature);
                let bound = Transmission::at(theta.to_radians().cos(), eps).plus;
                assert!(
                    albedo <= bound + 2e-4,
                    "n {n} d {d} d_c {d_c:?} d1 {d1:?} θ {theta}: {albedo} > {bound}"
                );
                assert!(albedo <= 1.0);
            }
            for i in directions() {
                for r in directions() {
                    let m = only_subsurface.mueller(&i, &r);
                    let lowest = irpol::optics::coherency_eigenvalues(&m)
                        .into_iter()
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        lowest >= -1e-12 * m[(0, 0)],
                        "n {n} d {d} d_c {d_c:?} d1 {d1:?}: {lowest}"
                    );
                }
            }
        }
    }
}

/// A circular residual polarization outside [2d − 1, 1] would make D unphysical: refused.
#[test]
fn an_unrealizable_subsurface_depolarizer_is_refused() {
    let base = model(1.4, 0.0, 0.0, FacetSide::Internal, None);
    let with = |d: f64, d_c: f64| {
        base.clone().with_volume(
            FacetSide::Internal,
            Some(Subsurface {
                term: Term::Subsurface,
                rho_s: 0.5,
                d,
                n_sub: None,
                d_c: Some(d_c),
                d1: None,
            }),
        )
    };
    assert!(with(0.4, -0.19).is_ok());
    let message = with(0.4, -0.21).unwrap_err().to_string();
    assert!(
        message.contains("d_c must be within [2d − 1, 1]"),
        "{message}"
    );
    assert!(with(0.0, 1.5).is_err());
    // d(Θ) = d + d1 cos Θ reaches |d| + |d1|: beyond 1, or with d_c below 2(|d| + |d1|) − 1,
    // refused.
    let angular = |d1: f64, d_c: f64| {
        base.clone().with_volume(
            FacetSide::Internal,
            Some(Subsurface {
                term: Term::Subsurface,
                rho_s: 0.5,
                d: 0.4,
                n_sub: None,
                d_c: Some(d_c),
                d1: Some(d1),
            }),
        )
    };
    assert!(angular(-0.3, 0.4).is_ok());
    assert!(angular(-0.3, 0.39).is_err());
    let message = angular(0.7, 1.0).unwrap_err().to_string();
    assert!(message.contains("keep |d| + |d1| ≤ 1"), "{message}");
}

fn volume_data(name: &str) -> irpol::measure::MeasurementSet {
    read_measurement_csv(&Path::new("tests/data/volume").join(name)).unwrap()
}

fn within(value: f64, truth: f64, relative: f64) -> bool {
    (value - truth).abs() <= relative * truth.abs()
}

/// Data made by the numpy implementation with noise: each file's own terms are chosen by both
/// AIC and 5-fold cross-validation, and its parameters recovered (σ, q within 2 %, n 1 %, ρ_s 2 %,
/// d and d_c within 0.02).
#[test]
fn synthetic_volume_scatterers_are_recovered_and_their_terms_chosen() {
    let cases = [
        (
            "external_subsurface.csv",
            ModelTerms::new(FacetSide::External, Body::Subsurface),
            [
                (Parameter::Sigma, 0.15),
                (Parameter::Q, 2.5),
                (Parameter::N, 1.45),
            ],
            0.8,
            0.2,
        ),
        (
            "internal_subsurface.csv",
            ModelTerms::new(FacetSide::Internal, Body::Subsurface),
            [
                (Parameter::Sigma, 0.8),
                (Parameter::N, 1.35),
                (Parameter::N, 1.35),
            ],
            0.6,
            0.1,
        ),
    ];
    for (file, terms, shape, rho_s, d) in cases {
        let set = volume_data(file);
        let options = FitOptions {
            term_candidates: ModelTerms::ALL.to_vec(),
            cv_folds: Some(5),
            ..FitOptions::default()
        };
        let outcome = fit_grey(&set, &options).unwrap();
        let choice = outcome.terms_choice.as_ref().unwrap();
        assert_eq!(choice.scores[choice.chosen].terms, terms, "{file}: CV");
        assert_eq!(
            choice.scores[choice.best_by_aic()].terms,
            terms,
            "{file}: AIC"
        );
        let model = &outcome.chosen.model;
        for (p, truth) in shape {
            let tolerance = if p == Parameter::N { 0.01 } else { 0.02 };
            let value = model.parameter(p).unwrap();
            assert!(within(value, truth, tolerance), "{file}: {p} = {value}");
        }
        assert!(
            within(model.parameter(Parameter::RhoS).unwrap(), rho_s, 0.02),
            "{file}: {model:?}"
        );
        assert!(
            (model.parameter(Parameter::D).unwrap() - d).abs() <= 0.02,
            "{file}: {model:?}"
        );
        // The data were made with D's circular part equal to d (d_c absent): the free d_c finds it.
        let d_c = model.parameter(Parameter::DC).unwrap();
        assert!((d_c - d).abs() <= 0.02, "{file}: d_c = {d_c}");
    }
}

/// A volume model in a material file reads back as written, the keys of the subsurface term are
/// refused without ρ_s, and a spectral table keeps them.
#[test]
fn material_files_carry_the_volume_terms() {
    let grey = "name = \"m\"\ntool_version = \"irpol\"\n[model]\ndistribution = \"cauchy\"\n\
                sigma = 0.2\nq = 2.5\nshadowing = \"smith\"\nn = 1.35\nk = 0.0\n\
                facet = \"internal\"\nrho_s = 0.9\nd = 0.1\nn_sub = 1.2\nwavelength_um = 1.064\n";
    let material: Material = toml::from_str(grey).unwrap();
    let spec = material.grey_model().unwrap();
    assert_eq!(spec.facet, FacetSide::Internal);
    assert_eq!(
        [Parameter::RhoS, Parameter::D, Parameter::NSub].map(|p| spec.lobe_keys.get(p).copied()),
        [Some(0.9), Some(0.1), Some(1.2)]
    );
    let pbrdf = spec.pbrdf().unwrap();
    assert_eq!(pbrdf.facet_side(), FacetSide::Internal);
    let orphan = grey.replace("rho_s = 0.9\n", "");
    let error = toml::from_str::<Material>(&orphan).unwrap_err().to_string();
    assert!(error.contains("need rho_s"), "{error}");
    let spectral = grey
        .replace("n = 1.35", "n = [1.35, 1.36]")
        .replace("k = 0.0", "k = [0.0, 0.0]")
        .replace("wavelength_um = 1.064", "wavelength_um = [1.0, 2.0]");
    // A spectral table carries the same terms (docs/design.md §1.10): at 1 µm it is the grey
    // model with n = 1.35.
    let read: Material = toml::from_str(&spectral).unwrap();
    let at = read.at(1.0).unwrap();
    assert_eq!(at.facet, FacetSide::Internal);
    assert_eq!(
        [Parameter::RhoS, Parameter::D, Parameter::NSub].map(|p| at.lobe_keys.get(p).copied()),
        [Some(0.9), Some(0.1), Some(1.2)]
    );
    assert_eq!(at.n, 1.35);
}

/// NIST's PTFE through its layout (1.064 µm): today's model fits it only by creating energy
/// (ρ_d ≈ 0.94 with n ≈ 0.79 reflects more than 1 at grazing incidence), so the fit's energy
/// constraint holds ρ_d and says so; internal facets with the subsurface term need no hold, and
/// predict the incidences the fit did not see (15°, 45°) with less m00 error. Numbers in
/// docs/measurements.md.
#[test]
fn ptfe_fits_conserve_energy_and_the_volume_model_predicts_better() {
    let dir = tempfile::tempdir().unwrap();
    let fit = |terms: &str, name: &str| {
        let (fits, reports) = (dir.path().join(name), dir.path().join("reports"));
        let output = irpol()
            .args([
                "fit",
                "data/ptfe/PTFE_351_1064.csv",
                "--layout",
                "data/ptfe/layout.toml",
            ])
            .args([
                "--wavelength",
                "1.064",
                "--theta-i",
                "0,30,60,75",
                "--terms",
                terms,
            ])
            .arg("--out")
            .arg(&fits)
            .arg("--reports")
            .arg(&reports)
            .output()
            .unwrap();
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let entry = std::fs::read_dir(&fits)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "toml"))
            .unwrap();
        let material = Material::load(&entry).unwrap();
        let pbrdf = material.grey_model().unwrap().pbrdf().unwrap();
        let (largest, theta) = largest_reflectance(&pbrdf);
        assert!(
            largest <= 1.0 + ENERGY_TOLERANCE,
            "{terms}: {largest} at {theta}°"
        );
        let validation = irpol()
            .arg("validate")
            .arg(&entry)
            .args([
                "data/ptfe/PTFE_351_1064.csv",
                "--layout",
                "data/ptfe/layout.toml",
            ])
            .args(["--wavelength", "1.064", "--theta-i", "15,45", "--reports"])
            .arg(dir.path().join("validation"))
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&validation.stdout).into_owned();
        assert!(
            validation.status.success(),
            "{}",
            String::from_utf8_lossy(&validation.stderr)
        );
        let figure = |label: &str| -> f64 {
            stdout
                .split(label)
                .nth(1)
                .and_then(|s| s.split_whitespace().next())
                .and_then(|s| s.parse().ok())
                .unwrap_or_else(|| panic!("no '{label}' in {stdout}"))
        };
        (
            material,
            figure("m00 relative RMS "),
            figure("m_ij/m00 RMS "),
        )
    };
    let (today, today_m00, today_normalized) = fit("external+depolarizer", "today");
    let record = today.fit.as_ref().unwrap();
    assert!(
        record.settings["energy"].contains("rho_d held at"),
        "{record:?}"
    );
    let (volume, volume_m00, volume_normalized) = fit("internal+subsurface", "volume");
    let spec = volume.grey_model().unwrap();
    assert!((1.25..1.45).contains(&spec.n), "{spec:?}");
    // Measured on the unseen incidences: m00 4.5 % against 14.3 %, m_ij/m00 0.0199 against
    // 0.0204 (docs/measurements.md).
    assert!(
        volume_m00 < 0.5 * today_m00,
        "{volume_m00} % vs {today_m00} %"
    );
    assert!(
        volume_normalized < today_normalized,
        "m_ij/m00 RMS {volume_normalized} vs {today_normalized}"
    );
}

/// `irpol fit --terms … --cv K` prints the candidates side by side; `irpol validate` scores a
/// material on a file and writes its page.
#[test]
fn fit_with_cross_validation_and_validate_from_the_command_line() {
    let dir = tempfile::tempdir().unwrap();
    let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
    let output = irpol()
        .args([
            "fit",
            "tests/data/volume/external_subsurface.csv",
            "--terms",
        ])
        .args(["external+depolarizer,external+subsurface", "--cv", "3"])
        .arg("--out")
        .arg(&fits)
        .arg("--reports")
        .arg(&reports)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    assert!(stdout.contains("* external+subsurface"), "{stdout}");
    assert!(stdout.contains("CV χ²/obs"), "{stdout}");
    let entry = fits.join("external_subsurface.toml");
    let output = irpol()
        .arg("validate")
        .arg(&entry)
        .arg("tests/data/volume/external_subsurface.csv")
        .arg("--reports")
        .arg(&reports)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    // Its own data: χ²/obs near 1 with the file's uncertainties.
    let chi2: f64 = stdout
        .split("χ²/obs ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|s| s.parse().ok())
        .unwrap();
    assert!((0.8..1.3).contains(&chi2), "{stdout}");
    assert!(reports
        .join("external_subsurface_validation_external_subsurface.png")
        .is_file());
    let bad = irpol()
        .args([
            "fit",
            "tests/data/volume/external_subsurface.csv",
            "--terms",
            "inside+x",
        ])
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&bad.stderr);
    assert!(
        !bad.status.success() && stderr.contains("unknown terms 'inside+x'"),
        "{stderr}"
    );
}

/// docs/design.md §1.10 "physically admissible by default": the default of `irpol fit`
/// (`--terms auto`, the options the command line and Python parse from no flags) keeps §1.3's
/// model on every shipped measurement, which §1.3's model made (SCATMECH), grey and spectral —
/// the one-standard-error rule does not let a bigger model win on noise.
#[test]
fn the_default_keeps_the_facet_model_on_data_it_made() {
    let options = irpol::app::fit::FitFlags::default().options().unwrap();
    assert!(options.choose_terms && options.term_candidates.len() == 3);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements");
    let inputs: Vec<std::path::PathBuf> = ["paper_paint.csv", "silicate_glass.csv"]
        .iter()
        .map(|f| root.join(f))
        .collect();
    let outcomes = irpol::fit::fit_inputs(&inputs, &options, &irpol::progress::Silent).unwrap();
    for outcome in &outcomes {
        let (choice, terms) = match outcome {
            irpol::fit::MaterialFit::Grey(o) => (o.terms_choice.as_ref(), o.chosen.terms),
            irpol::fit::MaterialFit::Spectral(o) => (
                o.terms_choice.as_ref(),
                o.material.model.spectral().unwrap().terms(),
            ),
        };
        let choice = choice.expect("the default chooses its terms");
        let name = &outcome.material().name;
        assert_eq!(terms, ModelTerms::default(), "{name}:\n{}", choice.table());
        assert!(choice.folds == Some(5), "{name}");
        assert!(
            choice.scores[choice.chosen].inadmissible.is_none(),
            "{name}: {}",
            choice.table()
        );
    }
}

/// The default on NIST's measured PTFE (both wavelengths, one spectral material): a set of terms
/// whose index means PTFE's (n within 1.25–1.45, not falling below the value at 1.064 µm toward
/// the UV by more than 0.02), which conserves energy at both wavelengths and keeps every term in
/// the file it writes; §1.3's model alone is not admissible there (it needs n < 1).
#[test]
fn the_default_on_measured_ptfe_is_physical_and_keeps_its_terms() {
    let dir = tempfile::tempdir().unwrap();
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("data/ptfe");
    let out = irpol()
        .arg("fit")
        .arg(data.join("PTFE_351_1064.csv"))
        .arg("--layout")
        .arg(data.join("layout.toml"))
        .args(["--out", dir.path().to_str().unwrap()])
        .args(["--reports", dir.path().join("r").to_str().unwrap()])
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("external+depolarizer") && stdout.contains("no: n = 0.6"),
        "{stdout}"
    );
    let material = Material::load(&dir.path().join("PTFE_351_1064.toml")).unwrap();
    let model = material.model.spectral().expect("one spectral material");
    assert_eq!(model.terms().body, Body::Subsurface, "{stdout}");
    let (n_uv, n_ir) = (model.n[0], model.n[1]);
    assert!(
        (1.25..=1.45).contains(&n_uv) && (1.25..=1.45).contains(&n_ir),
        "{n_uv} {n_ir}"
    );
    assert!(n_uv >= n_ir - 0.02, "{n_uv} {n_ir}");
    for node in model.nodes() {
        let pbrdf = node.pbrdf().unwrap();
        assert_eq!(
            pbrdf.subsurface_lobes().count(),
            1,
            "the term survives the file"
        );
        let (reflectance, _) = largest_reflectance(&pbrdf);
        assert!(reflectance <= 1.0 + ENERGY_TOLERANCE, "{reflectance}");
    }
}

/// docs/design.md §1.10 "Identification": a parameter resting on a bound (paper_paint's ρ_d = 0)
/// is named in the summary line and above its key in the file; the subsurface terms on the same
/// data, whose d and d_c the data cannot determine (ρ_s → 0), are fitted, flagged and written —
/// not refused for an infinite uncertainty.
#[test]
fn parameters_the_data_do_not_determine_are_named_not_refused() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/paper_paint.csv");
    for terms in ["external+depolarizer", "external+subsurface"] {
        let dir = tempfile::tempdir().unwrap();
        let out = irpol()
            .arg("fit")
            .arg(&data)
            .args(["--terms", terms, "--distribution", "cauchy"])
            .args(["--out", dir.path().to_str().unwrap()])
            .args(["--reports", dir.path().join("r").to_str().unwrap()])
            .output()
            .unwrap();
        let stdout = String::from_utf8_lossy(&out.stdout);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{terms}: {stdout}{stderr}");
        let line = stdout.lines().next().unwrap();
        assert!(
            line.contains("; NOT DETERMINED by the data: "),
            "{terms}: {line}"
        );
        let text = std::fs::read_to_string(dir.path().join("paper_paint.toml")).unwrap();
        let flagged = text
            .find("# NOT DETERMINED by the data: ")
            .expect("flagged in the file");
        if terms == "external+depolarizer" {
            assert!(
                line.contains("rho_d at a bound of its search interval"),
                "{line}"
            );
            assert!(
                text[flagged..].starts_with("# NOT DETERMINED by the data: rho_d"),
                "{text}"
            );
        }
        Material::load(&dir.path().join("paper_paint.toml")).unwrap();
    }
}

/// Subsurface lobes add: the term is linear in ρ_s (F_ss = ρ_s/(πZ) · …, Z independent of ρ_s),
/// so two lobes of ρ_s = 0.3 and 0.2 with the same d, n_sub, d_c, d1 are one lobe of ρ_s = 0.5 —
/// in every Mueller element and in the albedo the renderer samples.
#[test]
fn subsurface_lobes_add_as_one_lobe_of_their_summed_reflectance() {
    let lobe = |rho_s| Subsurface {
        term: Term::Subsurface,
        rho_s,
        d: 0.3,
        n_sub: Some(1.3),
        d_c: Some(0.1),
        d1: Some(0.2),
    };
    let model = |lobes: Vec<Subsurface>| {
        Pbrdf::new(
            SlopeDistribution::Cauchy { sigma: 0.4, q: 2.2 },
            Shadowing::Smith,
            RefractiveIndex::new(1.4, 0.01),
            0.05,
        )
        .unwrap()
        .with_volume(FacetSide::Internal, lobes)
        .unwrap()
    };
    let (two, one) = (model(vec![lobe(0.3), lobe(0.2)]), model(vec![lobe(0.5)]));
    assert_eq!(two.subsurface_lobes().count(), 2);
    assert!((two.body_albedo() - one.body_albedo()).abs() < 1e-15);
    for (ti, tr, phi) in [(0.0, 30.0, 180.0), (45.0, 60.0, 90.0), (75.0, 10.0, 20.0)] {
        let (wi, wr) = (
            Direction::from_degrees(ti, 0.0),
            Direction::from_degrees(tr, phi),
        );
        let (a, b) = (two.mueller(&wi, &wr), one.mueller(&wi, &wr));
        assert!(
            (a - b).abs().max() <= 1e-14 * b[(0, 0)],
            "{ti} {tr} {phi}: {a} {b}"
        );
    }
    // A lobe outside its domain is refused whichever lobe it is.
    let bad = Pbrdf::new(
        SlopeDistribution::Gaussian { sigma: 0.2 },
        Shadowing::Smith,
        RefractiveIndex::new(1.4, 0.0),
        0.0,
    )
    .unwrap()
    .with_volume(FacetSide::External, vec![lobe(0.3), lobe(1.5)]);
    assert!(bad.is_err());
}

/// The subsurface lobe's flags of `irpol eval` come from the parameter registry: the model they
/// give is the one the same keys give in a material file (every key, d_c and d1 included), a
/// lobe's key without its ρ_s is refused in the flags' own words, and a flag beside --material
/// is named.
#[test]
fn eval_flags_of_the_subsurface_lobe_match_the_material_file() {
    let dir = tempfile::tempdir().unwrap();
    let lobe = [
        ("rho_s", "0.8"),
        ("d", "0.2"),
        ("n_sub", "1.3"),
        ("d_c", "0.1"),
        ("d1", "-0.3"),
    ];
    let mut file = "name = \"m\"\ntool_version = \"irpol\"\n[model]\ndistribution = \"cauchy\"\n\
                    sigma = 0.2\nq = 2.5\nshadowing = \"smith\"\nn = 1.5\nk = 0.01\n\
                    facet = \"internal\"\nwavelength_um = 10.0\n"
        .to_owned();
    let mut flags = vec!["--sigma", "0.2", "--q", "2.5", "--n", "1.5", "--k", "0.01"];
    flags.extend(["--facet", "internal"]);
    let names: Vec<String> = lobe
        .iter()
        .map(|(key, _)| format!("--{}", key.replace('_', "-")))
        .collect();
    for ((key, value), flag) in lobe.iter().zip(&names) {
        file.push_str(&format!("{key} = {value}\n"));
        flags.extend([flag.as_str(), value]);
    }
    let path = dir.path().join("m.toml");
    std::fs::write(&path, &file).unwrap();
    let geometry = ["--theta-i", "50", "--theta-r", "0:80:20", "--phi-r", "60"];
    let run = |model: &[&str]| {
        let args: Vec<&str> = ["eval"]
            .iter()
            .chain(model)
            .chain(&geometry)
            .copied()
            .collect();
        let (ok, stdout, stderr) = super::common::irpol(&args);
        assert!(ok, "{stderr}");
        stdout
            .lines()
            .filter(|l| !l.starts_with('#'))
            .map(str::to_owned)
            .collect::<Vec<_>>()
    };
    let from_flags = run(&flags);
    let from_file = run(&["--material", path.to_str().unwrap()]);
    assert_eq!(from_flags, from_file);
    // d1 and d_c change the table: the flags are read, not ignored.
    let without_d1 = run(&flags[..flags.len() - 2]);
    assert_ne!(from_flags, without_d1);

    let orphan = [
        "eval", "--sigma", "0.2", "--q", "2.5", "--n", "1.5", "--k", "0", "--d-c", "0.1",
    ];
    let (ok, _, stderr) =
        super::common::irpol(&orphan.iter().chain(&geometry).copied().collect::<Vec<_>>());
    assert!(!ok);
    assert!(
        stderr.contains("--d, --n-sub, --d-c and --d1 need --rho-s"),
        "{stderr}"
    );
    let beside = ["eval", "--material", path.to_str().unwrap(), "--d1", "0.1"];
    let (ok, _, stderr) =
        super::common::irpol(&beside.iter().chain(&geometry).copied().collect::<Vec<_>>());
    assert!(!ok && stderr.contains("--d1 with --material"), "{stderr}");
}
