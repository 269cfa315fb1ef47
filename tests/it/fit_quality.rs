//! What `irpol fit` says about its inputs' units and about a fit that does not describe its
//! data (issue 45): radians in a plain CSV are refused unless `--angles` says how to read them,
//! a misfit warns on a line of its own, marks the report and the library, and `--strict` refuses
//! it without touching earlier outputs; the shipped measurements trigger neither.

use crate::common::{fit_into, irpol};
use irpol::measure::{collect_measurement_files, is_angle_note, Layout, ReadOptions};
use std::path::{Path, PathBuf};

/// `measurements/paper_paint.csv` with its four angle columns written in radians (6 decimals),
/// as material `rad`.
fn paper_paint_in_radians(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string("measurements/paper_paint.csv").unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with("# material:"));
    let mut out = String::from("# material: rad\n");
    let mut header: Vec<String> = Vec::new();
    for line in lines.by_ref() {
        out.push_str(line);
        out.push('\n');
        if !line.starts_with('#') && !line.trim().is_empty() {
            header = line.split(',').map(str::to_owned).collect();
            break;
        }
    }
    for line in lines {
        let fields: Vec<String> = line
            .split(',')
            .zip(&header)
            .map(|(field, name)| match name.ends_with("_deg") {
                true => format!("{:.6}", field.parse::<f64>().unwrap().to_radians()),
                false => field.to_owned(),
            })
            .collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    let path = dir.join("rad.csv");
    std::fs::write(&path, out).unwrap();
    path
}

#[test]
fn radians_in_a_plain_csv_are_refused_for_either_distribution() {
    let dir = tempfile::tempdir().unwrap();
    let csv = paper_paint_in_radians(dir.path());
    for distribution in ["cauchy", "gaussian"] {
        let (ok, _, stderr) = fit_into(dir.path(), &[&csv], &["--distribution", distribution]);
        assert!(!ok, "{stderr}");
        let expected = format!(
            "irpol: error: {}:20:1: every zenith angle is within ±1.48353 (≤ π/2 = 1.5708) and \
             not all whole degrees (0.349066 on line 20): these look like radians, but the angles \
             are declared in degrees: convert them to degrees, or pass --angles radians to \
             convert them as the file is read (--angles degrees if they are degrees)",
            csv.display()
        );
        assert_eq!(stderr.trim_end(), expected);
        assert!(!dir.path().join("fits").exists());
    }
}

#[test]
fn angles_radians_converts_a_plain_csv_and_the_entry_records_it() {
    let dir = tempfile::tempdir().unwrap();
    let csv = paper_paint_in_radians(dir.path());
    let extra = ["--angles", "radians", "--terms", "external+depolarizer"];
    let (ok, stdout, stderr) = fit_into(dir.path(), &[&csv], &extra);
    assert!(ok, "{stderr}");
    assert!(stderr.starts_with(&format!(
        "irpol: note: {}: angles read as radians (--angles radians) and converted to degrees\n",
        csv.display()
    )));
    assert!(!stderr.contains("warning"), "{stderr}");
    // The generating σ = 0.1, recovered as from the file in degrees.
    assert!(stdout.contains("rad: cauchy sigma=0.0999"), "{stdout}");
    let entry = dir.path().join("fits/rad.toml");
    assert!(std::fs::read_to_string(&entry)
        .unwrap()
        .contains("angles = \"radians\""));
    // The report is rebuilt from the same file, read the same way.
    let reports = dir.path().join("again");
    let (ok, _, stderr) = irpol(&[
        "report",
        entry.to_str().unwrap(),
        "--reports",
        reports.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
}

/// Radians read as degrees on purpose (`--angles degrees`): a model that cannot describe the
/// data. The fit warns on a line of its own, the report's title and the index are marked,
/// `irpol library` flags it; with `--strict` it fails and writes nothing.
#[test]
fn a_fit_that_does_not_describe_its_data_warns_and_strict_refuses_it() {
    let dir = tempfile::tempdir().unwrap();
    let shipped = Path::new("measurements/paper_paint.csv");
    let (ok, _, stderr) = fit_into(dir.path(), &[shipped], &[]);
    assert!(ok && !stderr.contains("warning"), "{stderr}");
    let fits = dir.path().join("fits");
    let before: Vec<(PathBuf, Vec<u8>)> = [
        fits.join("paper_paint.toml"),
        dir.path().join("reports/index.html"),
    ]
    .into_iter()
    .map(|p| (p.clone(), std::fs::read(p).unwrap()))
    .collect();

    let csv = paper_paint_in_radians(dir.path());
    let told = ["--angles", "degrees", "--distribution", "gaussian"];
    let strict = [&told[..], &["--strict"]].concat();
    let (ok, _, stderr) = fit_into(dir.path(), &[&csv], &strict);
    assert!(!ok);
    let error = stderr.lines().last().unwrap();
    assert!(
        error.starts_with("irpol: error: rad: the fit does not describe its data: χ²_red = "),
        "{stderr}"
    );
    assert!(
        error.contains("; nothing written (--strict); note: "),
        "{error}"
    );
    assert!(!fits.join("rad.toml").exists());
    for (path, bytes) in &before {
        assert_eq!(&std::fs::read(path).unwrap(), bytes, "{}", path.display());
    }

    let (ok, _, stderr) = fit_into(dir.path(), &[&csv], &told);
    assert!(ok, "{stderr}");
    assert!(
        stderr
            .lines()
            .any(|l| l
                .starts_with("irpol: warning: rad: the fit does not describe its data: χ²_red = ")),
        "{stderr}"
    );
    let index = std::fs::read_to_string(dir.path().join("reports/index.html")).unwrap();
    assert_eq!(index.matches("does not describe its data").count(), 1);
    let (ok, stdout, stderr) = irpol(&["library", fits.to_str().unwrap()]);
    assert!(ok);
    assert!(stderr.contains("warning: rad: the fit does not describe its data"));
    let flagged: Vec<&str> = stdout.lines().filter(|l| l.ends_with(" !")).collect();
    assert!(
        flagged.len() == 1 && flagged[0].starts_with("rad "),
        "{stdout}"
    );
}

/// The shipped inputs read without a units refusal or note, and their fits (the shipped
/// library, and NIST's PTFE fitted by default) record no misfit.
#[test]
fn the_shipped_measurements_look_like_degrees_and_their_fits_describe_them() {
    let mut files = collect_measurement_files(&[PathBuf::from("measurements")]).unwrap();
    files.push(PathBuf::from("data/ptfe/PTFE_351_1064.csv"));
    let ptfe = ReadOptions {
        layout: Some(Layout::read(Path::new("data/ptfe/layout.toml")).unwrap()),
        ..Default::default()
    };
    for file in &files {
        let reading = match file.starts_with("data") {
            true => &ptfe,
            false => &ReadOptions::default(),
        };
        for set in reading.read(file).unwrap() {
            assert!(
                !set.notes.iter().any(|n| is_angle_note(n)),
                "{:?}",
                set.notes
            );
        }
    }
    for entry in std::fs::read_dir("fits").unwrap() {
        let material = irpol::material::Material::load(&entry.unwrap().path()).unwrap();
        assert_eq!(material.fit.unwrap().misfit(), Vec::<String>::new());
    }
    let dir = tempfile::tempdir().unwrap();
    let layout = ["--layout", "data/ptfe/layout.toml"];
    let (ok, _, stderr) = fit_into(
        dir.path(),
        &[Path::new("data/ptfe/PTFE_351_1064.csv")],
        &layout,
    );
    assert!(ok && !stderr.contains("warning"), "{stderr}");
}
