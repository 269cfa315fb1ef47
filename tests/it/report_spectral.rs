//! The spectral fit report end to end (docs/design.md §1.9): the shipped silicate glass set fitted jointly,
//! its report encoded in memory, the figure decoded and checked for ink in every panel, one grey
//! fit report per wavelength, and the emissivity map checked against the model's own ε0.

use irpol::fit::{fit_inputs, Dispersion, FitOptions, MaterialFit, SpectralFitOutcome};
use irpol::pbrdf::HemisphereQuadrature;
use irpol::report::fit_report::REPORT_SIZE;
use irpol::report::spectral_report::{
    emissivity_grid, encode_spectral_report, wavelength_report_path, MAP_ANGLES, MAP_WAVELENGTHS,
    SPECTRAL_REPORT_SIZE,
};
use std::path::{Path, PathBuf};

fn fit_silicate(dispersion: Dispersion) -> SpectralFitOutcome {
    let csv = Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/silicate_glass.csv");
    let options = FitOptions {
        dispersion,
        ..FitOptions::default()
    };
    let mut fits = fit_inputs(&[csv], &options, &irpol::progress::Silent).unwrap();
    assert_eq!(fits.len(), 1);
    match fits.remove(0) {
        MaterialFit::Spectral(outcome) => *outcome,
        MaterialFit::Grey(_) => panic!("silicate_glass is a spectral set"),
    }
}

/// Non-white pixels of the image in the rectangle at (x, y) of `size`.
fn ink(png: &image::RgbImage, (x, y): (u32, u32), (w, h): (u32, u32)) -> usize {
    (x..x + w)
        .flat_map(|x| (y..y + h).map(move |y| (x, y)))
        .filter(|&(x, y)| png.get_pixel(x, y).0 != [255, 255, 255])
        .count()
}

/// The report's files: the figure (size, ink in every panel), its SVG, and one grey report per
/// wavelength at `<material>/<λ>um.png`.
fn check_files(outcome: &SpectralFitOutcome, out: &Path, files: &[(PathBuf, Vec<u8>)]) {
    let wavelengths: Vec<f64> = outcome
        .measurements
        .iter()
        .map(|s| s.wavelength_um)
        .collect();
    assert_eq!(files.len(), 2 + wavelengths.len());
    assert_eq!(files[0].0, out.join("silicate_glass.png"));
    assert_eq!(files[1].0, out.join("silicate_glass.svg"));
    let png = image::load_from_memory(&files[0].1).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), SPECTRAL_REPORT_SIZE);
    // (a) n, (b) k, (d) χ², (c) the emissivity map, (e) the table: each panel is drawn.
    for (corner, size, least) in [
        ((0, 100), (1000, 800), 20_000),
        ((1000, 100), (1000, 800), 20_000),
        ((2000, 100), (1000, 800), 50_000),
        ((0, 900), (1800, 800), 600_000),
        ((1800, 900), (1200, 800), 10_000),
    ] {
        let inked = ink(&png, corner, size);
        assert!(inked > least, "panel at {corner:?}: {inked} inked pixels");
    }
    let svg = String::from_utf8(files[1].1.clone()).unwrap();
    for text in ["silicate_glass", "wavelength λ (µm)", "ε0", "χ²"] {
        assert!(svg.contains(text), "the SVG lacks {text:?}");
    }
    let dir = out.join("silicate_glass");
    for ((path, bytes), &w) in files[2..].iter().zip(&wavelengths) {
        assert_eq!(*path, wavelength_report_path(&dir, w));
        let page = image::load_from_memory(bytes).unwrap().to_rgb8();
        assert_eq!(page.dimensions(), REPORT_SIZE);
        assert!(
            ink(&page, (0, 0), REPORT_SIZE) > 500_000,
            "{}",
            path.display()
        );
    }
    assert_eq!(
        files[2].0.file_name().unwrap(),
        "8um.png",
        "named by the wavelength"
    );
}

#[test]
fn a_spectral_report_is_a_figure_its_svg_and_one_fit_report_per_wavelength() {
    let outcome = fit_silicate(Dispersion::Table);
    // A folder that does not exist, so that "nothing is written" holds whatever the working
    // tree holds (the demo writes reports too).
    let scratch = tempfile::tempdir().unwrap();
    let out = &scratch.path().join("reports");
    let report = encode_spectral_report(&outcome, out).unwrap();
    check_files(&outcome, out, &report.files);
    assert!(
        out.join("silicate_glass.png").metadata().is_err(),
        "nothing is written"
    );
}

#[test]
fn a_lorentz_fit_reports_its_law_and_the_table_it_was_compared_with() {
    let outcome = fit_silicate(Dispersion::Lorentz(1));
    assert!(outcome.table.is_some());
    let scratch = tempfile::tempdir().unwrap();
    let out = &scratch.path().join("reports");
    let report = encode_spectral_report(&outcome, out).unwrap();
    check_files(&outcome, out, &report.files);
    let svg = String::from_utf8(report.files[1].1.clone()).unwrap();
    for text in ["Lorentz law (chosen, lorentz:1)", "AIC law =", "table fit"] {
        assert!(svg.contains(text), "the SVG lacks {text:?}");
    }
}

#[test]
fn the_emissivity_map_is_the_models_own_and_dips_in_the_reststrahlen_band() {
    let outcome = fit_silicate(Dispersion::Table);
    let material = &outcome.material;
    let grid = emissivity_grid(material, MAP_WAVELENGTHS, MAP_ANGLES).unwrap();
    assert_eq!(grid.theta_deg.len(), MAP_ANGLES);
    assert_eq!(
        (grid.theta_deg[0], grid.theta_deg[MAP_ANGLES - 1]),
        (0.0, 85.0)
    );
    let column = |w: f64| grid.wavelength_um.iter().position(|&x| x == w).unwrap();
    // Every measured wavelength is a column, its ε0 the model's own there.
    let spectral = material.model.spectral().unwrap();
    let quadrature = HemisphereQuadrature::default();
    for &w in &spectral.wavelength_um {
        let pbrdf = spectral.at(w).unwrap().pbrdf().unwrap();
        for j in [0, 12, MAP_ANGLES - 1] {
            let theta = grid.theta_deg[j].to_radians();
            let expected = pbrdf.emissivity(theta, &quadrature)[0];
            let got = grid.e0[column(w)][j];
            assert!(
                (got - expected).abs() < 1e-12,
                "{w} µm, {j}: {got} vs {expected}"
            );
        }
    }
    // Near normal, the band where k is large (8.5–9.5 µm) reflects: ε0 well below 12.5 µm's.
    let clear = grid.e0[column(12.5)][0];
    for w in [8.5, 9.0, 9.5] {
        let band = grid.e0[column(w)][0];
        assert!(
            band < clear - 0.1,
            "ε0({w} µm) = {band}, ε0(12.5 µm) = {clear}"
        );
    }
    assert!(clear > 0.85 && clear < 1.0, "{clear}");
}
