//! Fit reports end to end: a synthetic measurement of a known pBRDF (seeded noise) written as a
//! CSV, a material with a hand-filled fit record, and the report's files, plus `irpol report`'s
//! refusals (docs/design.md §2.2, §4).

use crate::report_support;

use irpol::material::Material;
use irpol::report::fit_report::{
    panel_size, rebuild_report, write_fit_report, PANELS, REPORT_SIZE,
};
use report_support::{fitted_material, synthetic_set, LINEAR};
use std::path::{Path, PathBuf};

fn count_pixels(png: &image::RgbImage, color: [u8; 3]) -> usize {
    png.pixels().filter(|p| p.0 == color).count()
}

#[test]
fn a_report_is_a_3000_by_1800_png_and_an_svg_with_labelled_axes() {
    let dir = tempfile::tempdir().unwrap();
    let all: Vec<usize> = (0..16).collect();
    let (csv, set) = synthetic_set(dir.path(), "gloss_paint", &all);
    let material = fitted_material("gloss_paint", &set, &csv);
    let out = dir.path().join("reports");
    let started = std::time::Instant::now();
    let paths = write_fit_report(&material, &set, &out).unwrap();
    let elapsed = started.elapsed();
    assert_eq!(
        paths[..2],
        [out.join("gloss_paint.png"), out.join("gloss_paint.svg")]
    );

    let png = image::open(&paths[0]).unwrap().to_rgb8();
    assert_eq!(png.dimensions(), REPORT_SIZE);
    // The three incidence angles are drawn in their own colours (data points and curves).
    for color in [[31, 119, 180], [255, 127, 14], [44, 160, 44]] {
        assert!(count_pixels(&png, color) > 2000, "{color:?}");
    }
    // Mostly white paper, but every panel has ink.
    let white = count_pixels(&png, [255, 255, 255]);
    assert!(white > png.len() / 3 / 2 && white < png.len() / 3 * 95 / 100);
    for (x0, y0) in [
        (0, 100),
        (1200, 100),
        (1800, 100),
        (0, 666),
        (1200, 666),
        (1800, 666),
    ] {
        let ink = (x0..x0 + 600)
            .flat_map(|x| (y0..y0 + 566).map(move |y| (x, y)))
            .filter(|&(x, y)| png.get_pixel(x, y).0 != [255, 255, 255])
            .count();
        assert!(ink > 10_000, "panel at ({x0}, {y0}) has {ink} inked pixels");
    }

    let svg = std::fs::read_to_string(&paths[1]).unwrap();
    for label in [
        "gloss_paint",
        "detector zenith",
        "m00",
        "sr⁻¹",
        "φr − φi",
        "m12/m00 (rings)",
        "m22/m00",
        "DoLP",
        "emission angle",
        "ε0",
        "(data − model)/σ",
        "N(0, 1) expected",
        "polish starts",
        "gaussian fit (competing distribution)",
        "θi = 40°",
        "reduced χ²",
        "± 0.0021",
        "cauchy preferred",
    ] {
        assert!(svg.contains(label), "the SVG lacks {label:?}");
    }
    eprintln!("report rendered in {elapsed:?}");

    // The same material and measurement always give the same figure, byte for byte.
    let again = write_fit_report(&material, &set, &dir.path().join("again")).unwrap();
    for (first, second) in paths.iter().zip(&again) {
        assert_eq!(
            std::fs::read(first).unwrap(),
            std::fs::read(second).unwrap()
        );
    }
}

#[test]
fn markup_in_a_material_name_is_escaped_in_the_svg() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, set) = synthetic_set(dir.path(), "x", &[0]);
    let material = fitted_material("tar & <pitch>", &set, &csv);
    let paths = write_fit_report(&material, &set, dir.path()).unwrap();
    assert_eq!(paths[1], dir.path().join("tar & <pitch>.svg"));
    let svg = std::fs::read_to_string(&paths[1]).unwrap();
    assert!(svg.contains("tar &amp; &lt;pitch&gt;") && !svg.contains("<pitch>"));
}

#[test]
fn a_report_of_m00_only_says_what_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, set) = synthetic_set(dir.path(), "matte", &[0]);
    let mut material = fitted_material("matte", &set, &csv);
    material.fit = None;
    let paths = write_fit_report(&material, &set, dir.path()).unwrap();
    let svg = std::fs::read_to_string(&paths[1]).unwrap();
    assert!(svg.contains("only m00 was measured"));
    assert!(svg.contains("model only (m10, m20 not both measured)"));
    assert!(svg.contains("no fit record"));
    assert!(!svg.contains("competing distribution"));
}

#[test]
fn a_material_name_with_folders_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, set) = synthetic_set(dir.path(), "x", &[0]);
    let material = fitted_material("../escape", &set, &csv);
    let message = write_fit_report(&material, &set, dir.path())
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("'../escape' cannot name a report file"),
        "{message}"
    );
}

/// A project folder: measurements/<name>.csv and fits/<name>.toml, the fit recording the CSV
/// relative to the project root (as `irpol fit measurements/…` run there would).
fn project(name: &str) -> (tempfile::TempDir, PathBuf, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("measurements")).unwrap();
    let (csv, set) = synthetic_set(&dir.path().join("measurements"), name, &LINEAR);
    let relative = csv.strip_prefix(dir.path()).unwrap().to_owned();
    let material = fitted_material(name, &set, &relative);
    let toml = dir.path().join("fits").join(format!("{name}.toml"));
    std::fs::create_dir_all(toml.parent().unwrap()).unwrap();
    material.save(&toml).unwrap();
    (dir, csv, toml)
}

#[test]
fn rebuild_finds_the_source_beside_the_library_and_redraws_the_report() {
    let (dir, _, toml) = project("paint");
    let reports = dir.path().join("reports");
    let paths = rebuild_report(&toml, &reports).unwrap();
    assert_eq!(
        paths[..2],
        [reports.join("paint.png"), reports.join("paint.svg")]
    );
    assert_eq!(image::open(&paths[0]).unwrap().width(), REPORT_SIZE.0);
}

fn rebuild_error(toml: &Path, reports: &Path) -> String {
    rebuild_report(toml, reports).unwrap_err().to_string()
}

#[test]
fn rebuild_refuses_a_material_without_a_fit_record() {
    let (dir, _, toml) = project("paint");
    let mut material = Material::load(&toml).unwrap();
    material.fit = None;
    material.save(&toml).unwrap();
    let message = rebuild_error(&toml, dir.path());
    assert_eq!(
        message,
        format!(
            "{}: the material has no fit record, so there is no measurement to report against \
             (fit it with `irpol fit`)",
            toml.display()
        )
    );
}

#[test]
fn rebuild_refuses_a_missing_source_csv_and_says_where_it_looked() {
    let (dir, csv, toml) = project("paint");
    std::fs::remove_file(&csv).unwrap();
    let message = rebuild_error(&toml, dir.path());
    assert!(
        message.starts_with(&format!(
            "{}: its source CSV measurements/paint.csv is missing (looked for measurements/paint.csv, ",
            toml.display()
        )),
        "{message}"
    );
    assert!(message.contains(
        &dir.path()
            .join("measurements/paint.csv")
            .display()
            .to_string()
    ));
    assert!(!dir.path().join("paint.png").exists());
}

#[test]
fn rebuild_refuses_a_changed_source_csv_when_the_entry_has_only_its_byte_hash() {
    let (dir, csv, toml) = project("paint");
    let recorded = Material::load(&toml).unwrap().fit.unwrap().source_sha256;
    let mut text = std::fs::read_to_string(&csv).unwrap();
    text.push_str("# edited after the fit\n");
    std::fs::write(&csv, &text).unwrap();
    let message = rebuild_error(&toml, dir.path());
    // This record (as entries written before the data fingerprint) has only the byte hash.
    assert_eq!(
        message,
        format!(
            "{}: source CSV changed since the fit: its bytes are not those of sha256 {recorded} \
             recorded in {}, which records no fingerprint of the data to compare (written before \
             irpol kept one); refit it with `irpol fit`",
            csv.display(),
            toml.display()
        )
    );
}

#[test]
fn rebuild_passes_the_csv_readers_message_through() {
    let (dir, csv, toml) = project("paint");
    // A malformed file whose hash is the recorded one (e.g. a reader that became stricter).
    let broken = "theta_i_deg;theta_r_deg;m00\n60;60;0.2\n";
    std::fs::write(&csv, broken).unwrap();
    let mut material = Material::load(&toml).unwrap();
    material.fit.as_mut().unwrap().source_sha256 = sha256_hex(broken.as_bytes());
    material.save(&toml).unwrap();
    let message = rebuild_error(&toml, dir.path());
    assert_eq!(
        message,
        format!(
            "{}:1:12: fields are separated by ';', expected ','",
            dir.path().join("measurements/paint.csv").display()
        )
    );
}

fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect()
}

#[test]
fn rebuild_passes_a_broken_material_file_through() {
    let dir = tempfile::tempdir().unwrap();
    let toml = dir.path().join("bad.toml");
    std::fs::write(&toml, "name = 3\n").unwrap();
    let message = rebuild_error(&toml, dir.path());
    assert!(
        message.contains("bad.toml: not a valid material TOML"),
        "{message}"
    );
}

#[test]
fn each_panel_is_also_its_own_png_beside_the_figure() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, set) = synthetic_set(dir.path(), "gloss_paint", &LINEAR);
    let material = fitted_material("gloss_paint", &set, &csv);
    let out = dir.path().join("reports");
    let paths = write_fit_report(&material, &set, &out).unwrap();
    assert_eq!(paths.len(), 2 + PANELS.len());
    for (spec, path) in PANELS.iter().zip(&paths[2..]) {
        assert_eq!(
            *path,
            out.join("gloss_paint").join(format!("{}.png", spec.name))
        );
        let png = image::open(path).unwrap().to_rgb8();
        assert_eq!(png.dimensions(), panel_size(spec), "{}", spec.name);
        let ink = png.len() / 3 - count_pixels(&png, [255, 255, 255]);
        assert!(ink > 5_000, "{}: {ink} inked pixels", spec.name);
    }
}

#[test]
fn the_correlation_matrix_names_its_parameters_and_prints_its_values() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, set) = synthetic_set(dir.path(), "gloss_paint", &LINEAR);
    let material = fitted_material("gloss_paint", &set, &csv);
    let paths = write_fit_report(&material, &set, dir.path()).unwrap();
    let svg = std::fs::read_to_string(&paths[1]).unwrap();
    let texts: Vec<&str> = svg
        .split("</text>")
        .filter_map(|t| t.rsplit('>').next().map(str::trim))
        .collect();
    let count = |label: &str| texts.iter().filter(|t| **t == label).count();
    assert_eq!(count("(j) Correlation of the fitted parameters"), 1);
    // ρ(σ, q) = 0.87 both sides of the diagonal, five ones on it, the rest zero.
    assert_eq!(count("+0.87"), 2);
    assert_eq!(count("+1.00"), 5);
    assert_eq!(count("+0.00"), 18);
    // The symbols label both axes (besides their rows in the parameter table).
    for symbol in ["σ", "q", "n", "k", "ρd"] {
        assert!(count(symbol) >= 3, "{symbol}: {}", count(symbol));
    }
    // The colour bar's ends.
    assert!(count("+1") == 1 && count("−1") == 1);
}
