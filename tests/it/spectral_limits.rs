//! Nothing non-finite reaches a written material: measurement values and uncertainties beyond
//! what a fit can square are refused where they are read (file, line, column), and a material
//! entry holding NaN or inf is never written (a unit test of `Material::to_toml` covers the
//! guard). Wavelengths of a material table within the tolerance of one wavelength are called
//! a duplicate, not "not strictly ascending".

use crate::common;

use common::irpol;
use std::path::Path;

fn manifest(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The shipped silicate glass (a spectral set), its 6th data row's field `column` set to `value`.
fn edited_glass(column: &str, value: &str) -> String {
    let text = std::fs::read_to_string(manifest("measurements/silicate_glass.csv")).unwrap();
    let mut lines: Vec<String> = text.lines().map(str::to_owned).collect();
    let header = lines.iter().position(|l| !l.starts_with('#')).unwrap();
    let index = lines[header].split(',').position(|c| c == column).unwrap();
    let mut fields: Vec<String> = lines[header + 6].split(',').map(str::to_owned).collect();
    fields[index] = value.to_owned();
    lines[header + 6] = fields.join(",");
    lines.join("\n") + "\n"
}

#[test]
fn extreme_measurements_are_refused_where_read_and_nothing_is_written() {
    // Once: m00 = 1e308 or a subnormal uncertainty fitted to χ²_red = inf, and `nan` was written
    // into the correlation matrix of fits/silicate_glass.toml.
    let cases = [
        (
            "m00",
            "1e308",
            ":27:15: column 'm00': 1e308 sr⁻¹ is beyond ±1e12 sr⁻¹",
        ),
        (
            "m01",
            "-1e300",
            "column 'm01': -1e300 sr⁻¹ is beyond ±1e12 sr⁻¹",
        ),
        (
            "u_m00",
            "5e-324",
            "column 'u_m00': uncertainty 5e-324 sr⁻¹ is outside 1e-15…1e12 sr⁻¹",
        ),
        (
            "u_m22",
            "1e-300",
            "column 'u_m22': uncertainty 1e-300 sr⁻¹ is outside 1e-15…1e12 sr⁻¹",
        ),
    ];
    for (column, value, needle) in cases {
        let dir = tempfile::tempdir().unwrap();
        let csv = dir.path().join("silicate_glass.csv");
        std::fs::write(&csv, edited_glass(column, value)).unwrap();
        let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
        let (ok, stdout, stderr) = irpol(&[
            "fit",
            csv.to_str().unwrap(),
            "--distribution",
            "cauchy",
            "--out",
            fits.to_str().unwrap(),
            "--reports",
            reports.to_str().unwrap(),
        ]);
        assert!(!ok && stdout.is_empty(), "{column} = {value}: {stdout}");
        assert!(stderr.contains(needle), "{needle}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
        assert!(!fits.exists() && !reports.exists());
    }
}

#[test]
fn wavelengths_within_the_tolerance_are_a_duplicate_not_a_descent() {
    let shipped = std::fs::read_to_string(manifest("fits/silicate_glass.toml")).unwrap();
    let first = "wavelength_um = [\n    8.0,\n    8.5,";
    assert!(shipped.contains(first));
    let cases = [
        (
            "wavelength_um = [\n    8.0,\n    8.0000001,",
            "wavelength_um lists one wavelength twice: 8 µm and 8.0000001 µm are within 1e-6 µm",
        ),
        (
            "wavelength_um = [\n    8.0,\n    7.5,",
            "wavelength_um must be strictly ascending (8 µm then 7.5 µm)",
        ),
    ];
    for (edit, needle) in cases {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("glass.toml");
        std::fs::write(&path, shipped.replacen(first, edit, 1)).unwrap();
        let (ok, _, stderr) = irpol(&[
            "emissivity",
            "--material",
            path.to_str().unwrap(),
            "--wavelength",
            "10",
        ]);
        assert!(!ok, "{edit}");
        assert!(stderr.contains(needle), "{needle}: {stderr}");
        assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    }
}

/// `validate` of a file holding several wavelengths writes one page per wavelength, each named
/// with its wavelength (issue 42: every page had one name, the second write failed and the first
/// page stayed). The shipped PTFE table without `--wavelength`.
#[test]
fn validate_writes_one_page_per_wavelength_of_a_file() {
    let dir = tempfile::tempdir().unwrap();
    let reports = dir.path().join("reports");
    let (ok, stdout, stderr) = irpol(&[
        "validate",
        manifest("fits/rough_paint.toml").to_str().unwrap(),
        manifest("data/ptfe/PTFE_351_1064.csv").to_str().unwrap(),
        "--layout",
        manifest("data/ptfe/layout.toml").to_str().unwrap(),
        "--theta-i",
        "45",
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let mut pages: Vec<String> = std::fs::read_dir(&reports)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    pages.sort();
    assert_eq!(
        pages,
        [
            "rough_paint_validation_PTFE_351_1064_0.351um.png",
            "rough_paint_validation_PTFE_351_1064_1.064um.png"
        ]
    );
    for page in &pages {
        assert!(stdout.contains(page.as_str()), "{stdout}");
    }
}

/// A spectral material evaluated outside its table is refused naming the material's file and
/// where the wavelength came from: the flag, or the measurement file (issue 42: neither was named).
#[test]
fn a_wavelength_outside_a_spectral_table_names_the_material_and_data_files() {
    let glass = manifest("fits/silicate_glass.toml");
    let glass = glass.to_str().unwrap();
    let (ok, _, stderr) = irpol(&[
        "eval",
        "--material",
        glass,
        "--wavelength",
        "20",
        "--theta-i",
        "30",
        "--theta-r",
        "30",
    ]);
    assert!(!ok);
    let needle = format!(
        "{glass}: material 'silicate_glass': wavelength 20 µm is outside its table, 8–14 µm \
         (given by --wavelength)"
    );
    assert!(stderr.contains(&needle), "{needle}: {stderr}");
    let dir = tempfile::tempdir().unwrap();
    let reports = dir.path().join("reports");
    let data = manifest("data/ptfe/PTFE_351_1064.csv");
    let (ok, _, stderr) = irpol(&[
        "validate",
        glass,
        data.to_str().unwrap(),
        "--layout",
        manifest("data/ptfe/layout.toml").to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert!(!ok);
    let needle = format!("(the wavelength of {})", data.display());
    assert!(
        stderr.contains(&format!(
            "{glass}: material 'silicate_glass': wavelength 0.351 µm"
        )) && stderr.contains(&needle),
        "{needle}: {stderr}"
    );
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(!reports.exists());
}
