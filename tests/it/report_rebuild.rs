//! `irpol report` through the CLI after the source CSV was edited: edits that
//! leave the data alone (comments, blank lines) rebuild the report; a change of the data is
//! refused in one line that names the file and says what changed; library entries written before
//! the data fingerprint existed still rebuild from the unchanged bytes.

use crate::common;

use common::{fit_into, irpol};
use std::path::{Path, PathBuf};

struct Project {
    _dir: tempfile::TempDir,
    csv: PathBuf,
    toml: PathBuf,
    reports: PathBuf,
}

/// A copy of the shipped paper paint, fitted into a temporary project.
fn fitted_project() -> Project {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("paper_paint.csv");
    let shipped = Path::new(env!("CARGO_MANIFEST_DIR")).join("measurements/paper_paint.csv");
    std::fs::copy(shipped, &csv).unwrap();
    let (fits, reports) = (dir.path().join("fits"), dir.path().join("reports"));
    let (ok, _, stderr) = fit_into(dir.path(), &[&csv], &[]);
    assert!(ok, "{stderr}");
    Project {
        toml: fits.join("paper_paint.toml"),
        _dir: dir,
        csv,
        reports,
    }
}

fn report(project: &Project) -> (bool, String) {
    let (ok, _, stderr) = irpol(&[
        "report",
        project.toml.to_str().unwrap(),
        "--reports",
        project.reports.to_str().unwrap(),
    ]);
    (ok, stderr)
}

/// The data lines of the CSV with line `index` (0-based among data rows) edited by `edit`.
fn edit_data_row(csv: &Path, index: usize, edit: impl Fn(&str) -> String) {
    let text = std::fs::read_to_string(csv).unwrap();
    let mut seen = 0;
    let lines: Vec<String> = text
        .lines()
        .scan(false, |past_header, line| {
            let data = !line.trim().is_empty() && !line.starts_with('#');
            let row = data && *past_header;
            *past_header |= data;
            Some((row, line))
        })
        .map(|(row, line)| {
            let edited = if row && seen == index {
                edit(line)
            } else {
                line.to_owned()
            };
            seen += usize::from(row);
            edited
        })
        .collect();
    std::fs::write(csv, lines.join("\n") + "\n").unwrap();
}

#[test]
fn a_comment_added_to_the_csv_still_rebuilds_the_report() {
    let project = fitted_project();
    let png = project.reports.join("paper_paint.png");
    std::fs::remove_file(&png).unwrap();
    let mut text = std::fs::read_to_string(&project.csv).unwrap();
    text = text.replacen('\n', "\n# re-measured the dark current, no change\n\n", 1);
    text.push_str("# checked 2026-05-02\n");
    std::fs::write(&project.csv, text).unwrap();
    let (ok, stderr) = report(&project);
    assert!(ok, "{stderr}");
    assert!(png.is_file());
}

#[test]
fn changed_values_are_refused_naming_the_file_and_the_rows() {
    let project = fitted_project();
    // Data row 12 (1-based) gets another m00; 516 rows are fingerprinted in groups of 3.
    edit_data_row(&project.csv, 11, |line| {
        let mut fields: Vec<String> = line.split(',').map(str::to_owned).collect();
        let m00: f64 = fields[4].parse().unwrap();
        fields[4] = format!("{:e}", m00 * 1.01);
        fields.join(",")
    });
    let (ok, stderr) = report(&project);
    assert!(!ok);
    assert_eq!(
        stderr,
        format!(
            "irpol: error: {}: the data changed since the fit recorded in {}: data in rows \
             10–12 changed; refit it with `irpol fit`\n",
            project.csv.display(),
            project.toml.display()
        )
    );
}

#[test]
fn added_rows_are_counted() {
    let project = fitted_project();
    let mut text = std::fs::read_to_string(&project.csv).unwrap();
    let last = text.lines().last().unwrap().to_owned();
    for _ in 0..3 {
        text.push_str(&last);
        text.push('\n');
    }
    std::fs::write(&project.csv, text).unwrap();
    let (ok, stderr) = report(&project);
    assert!(!ok);
    assert!(stderr.contains(": 3 data rows added; refit it"), "{stderr}");
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
}

#[test]
fn an_entry_without_a_data_fingerprint_rebuilds_from_unchanged_bytes_only() {
    let project = fitted_project();
    // As fits/*.toml were written before the fingerprint: only the byte hash.
    let toml = std::fs::read_to_string(&project.toml).unwrap();
    let start = toml
        .find("[fit.source_data]")
        .expect("the fit records its data");
    let end = toml[start..]
        .find("\n\n")
        .map_or(toml.len(), |e| start + e + 2);
    std::fs::write(&project.toml, format!("{}{}", &toml[..start], &toml[end..])).unwrap();
    let (ok, stderr) = report(&project);
    assert!(ok, "{stderr}");

    let mut text = std::fs::read_to_string(&project.csv).unwrap();
    text.push_str("# a comment\n");
    std::fs::write(&project.csv, text).unwrap();
    let (ok, stderr) = report(&project);
    assert!(!ok);
    assert!(
        stderr.starts_with(&format!(
            "irpol: error: {}: source CSV changed since the fit",
            project.csv.display()
        )) && stderr.contains("refit it with `irpol fit`"),
        "{stderr}"
    );
}
