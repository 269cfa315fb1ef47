//! `fit_files`, the library side of `irpol fit`: fits every input, writes fits/<material>.toml
//! that loads back as the fitted material, and writes nothing when any input is bad.

use crate::fit_support;

use fit_support::{goniometer_geometry, model, synthetic_set, to_csv, LINEAR_ELEMENTS};
use irpol::fit::{fit_files, FitError, FitOptions};
use irpol::material::Material;
use irpol::pbrdf::DistributionKind;
use irpol::pbrdf::{Shadowing, SlopeDistribution};
use std::path::{Path, PathBuf};

fn write_synthetic(dir: &Path, name: &str, sigma: f64) -> PathBuf {
    let truth = model(
        SlopeDistribution::Gaussian { sigma },
        Shadowing::Smith,
        2.0,
        0.3,
        0.02,
    );
    let set = synthetic_set(
        name,
        &truth,
        &goniometer_geometry(),
        &LINEAR_ELEMENTS,
        1.0,
        11,
    );
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, to_csv(&set, true)).unwrap();
    path
}

fn options() -> FitOptions {
    FitOptions {
        distribution: Some(DistributionKind::Gaussian),
        ..FitOptions::default()
    }
}

#[test]
fn every_input_of_a_folder_is_fitted_and_written_to_the_library() {
    let inputs = tempfile::tempdir().unwrap();
    write_synthetic(inputs.path(), "matte", 0.3);
    write_synthetic(inputs.path(), "glossy", 0.08);
    let library = tempfile::tempdir().unwrap();
    let fits = library.path().join("fits");
    let outcomes = fit_files(
        &[inputs.path().to_owned()],
        &options(),
        &fits,
        &irpol::progress::Silent,
    )
    .unwrap();
    // Folder files come sorted by name.
    let names: Vec<&str> = outcomes
        .iter()
        .map(|o| o.material().name.as_str())
        .collect();
    assert_eq!(names, ["glossy", "matte"]);
    for (outcome, sigma) in outcomes.iter().zip([0.08, 0.3]) {
        let saved =
            Material::load(&fits.join(format!("{}.toml", outcome.material().name))).unwrap();
        assert_eq!(&saved, outcome.material());
        assert!((saved.model.distribution().sigma() / sigma - 1.0).abs() < 0.03);
        let record = saved.fit.unwrap();
        assert_eq!(
            record.source,
            inputs.path().join(format!("{}.csv", saved.name))
        );
        assert_eq!(record.elements.len(), 9);
        assert!(record.alternative.is_none());
        assert_eq!(record.settings["uncertainties"], "u_ columns of the file");
    }
}

#[test]
fn a_bad_input_fails_the_run_before_anything_is_written() {
    let inputs = tempfile::tempdir().unwrap();
    let good = write_synthetic(inputs.path(), "good", 0.2);
    let bad = inputs.path().join("bad.csv");
    std::fs::write(
        &bad,
        "# wavelength_um: 10\ntheta_i_deg,theta_r_deg,m00\n30,95,0.1\n",
    )
    .unwrap();
    let library = tempfile::tempdir().unwrap();
    let fits = library.path().join("fits");
    let error = fit_files(&[good, bad], &options(), &fits, &irpol::progress::Silent).unwrap_err();
    assert!(matches!(error, FitError::Read(_)), "{error}");
    assert!(error.to_string().contains("bad.csv:3:"), "{error}");
    assert!(!fits.exists());

    // Two files of one material at different wavelengths are one spectral set (same-wavelength
    // ones are merged, tests/cli.rs), unless they disagree on what was measured.
    let copy = inputs.path().join("copy");
    std::fs::create_dir(&copy).unwrap();
    let first = write_synthetic(inputs.path(), "twin", 0.2);
    let second = write_synthetic(&copy, "twin", 0.25);
    for (path, wavelength, distribution) in [(&first, 10.0, "gaussian"), (&second, 10.6, "cauchy")]
    {
        let text = std::fs::read_to_string(path).unwrap();
        let header = format!("# wavelength_um: {wavelength}\n# distribution: {distribution}\n");
        std::fs::write(path, text.replace("# wavelength_um: 10\n", &header)).unwrap();
    }
    let error = fit_files(
        &[first, second],
        &options(),
        &fits,
        &irpol::progress::Silent,
    )
    .unwrap_err();
    assert!(matches!(error, FitError::Measurement { .. }), "{error}");
    assert!(
        error
            .to_string()
            .contains("'# distribution: cauchy' disagrees"),
        "{error}"
    );
    assert!(!fits.exists());

    // Invalid options are refused before any fitting.
    let mut invalid = options();
    invalid.shadowing = Shadowing::Smith;
    invalid.distribution = Some(DistributionKind::Cauchy);
    invalid.fixed.insert(irpol::pbrdf::Parameter::Q, 1.2);
    let good = inputs.path().join("good.csv");
    let error = fit_files(&[good], &invalid, &fits, &irpol::progress::Silent).unwrap_err();
    assert!(matches!(error, FitError::Options(_)), "{error}");
    assert!(!fits.exists());
    assert!(matches!(
        fit_files(&[], &options(), &fits, &irpol::progress::Silent),
        Err(FitError::Options(_))
    ));
}
