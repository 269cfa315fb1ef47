//! `reports/index.html` over a material library: every material with parameters ± 1σ, fit
//! quality, preferred distribution, provenance and its report figure, as one self-contained page
//! with relative links and escaped text.

use crate::report_support;

use irpol::report::fit_report::write_fit_report;
use irpol::report::index::{escape_html, write_library_index};
use report_support::{fitted_material, synthetic_set, LINEAR};
use std::path::Path;

/// project/{measurements, fits, reports}: `paint` (report drawn, source intact), `glass`
/// (source edited since the fit, no report), `primer` (no fit record), `<b>"tar" & pitch</b>` (a
/// name that needs escaping, its source gone).
fn library(project: &Path) {
    let measurements = project.join("measurements");
    let fits = project.join("fits");
    let reports = project.join("reports");
    for dir in [&measurements, &fits, &reports] {
        std::fs::create_dir_all(dir).unwrap();
    }
    let save = |file: &str, material: &irpol::material::Material| {
        material.save(&fits.join(format!("{file}.toml"))).unwrap()
    };

    let (csv, set) = synthetic_set(&measurements, "paint", &LINEAR);
    let paint = fitted_material("paint", &set, &csv);
    write_fit_report(&paint, &set, &reports).unwrap();
    save("paint", &paint);

    let (csv, set) = synthetic_set(&measurements, "glass", &LINEAR);
    save("glass", &fitted_material("glass", &set, &csv));
    std::fs::write(&csv, "# edited\n").unwrap();

    let mut primer = fitted_material("primer", &set, &csv);
    primer.fit = None;
    save("primer", &primer);

    let tricky = fitted_material("<b>\"tar\" & pitch</b>", &set, Path::new("gone/tar.csv"));
    save("tar", &tricky);
}

#[test]
fn the_index_lists_every_material_with_its_fit_and_provenance() {
    let dir = tempfile::tempdir().unwrap();
    library(dir.path());
    let index = write_library_index(&dir.path().join("fits"), &dir.path().join("reports"))
        .unwrap()
        .path;
    assert_eq!(index, dir.path().join("reports/index.html"));
    let html = std::fs::read_to_string(&index).unwrap();

    assert!(html.starts_with("<!DOCTYPE html>") && html.trim_end().ends_with("</html>"));
    assert!(
        html.contains("<style>") && !html.contains("<link"),
        "self-contained"
    );
    assert!(html.contains("4 materials in"));
    for name in ["paint", "glass", "primer"] {
        assert!(html.contains(&format!("<h2>{name}</h2>")), "{name}");
    }
    // Parameters with their 1-σ, fit quality and the model comparison.
    assert!(html.contains("0.2000 ± 0.0021") && html.contains("2.500 ± 0.034"));
    assert!(html.contains("<tr><td>reduced χ²</td><td>1.02"));
    assert!(html.contains("cauchy preferred: ΔAIC ="));
    assert!(html.contains("<tr><td>competing fit</td><td>gaussian: reduced χ² 2.7"));
    // Provenance: the source, its hash prefix, and whether the file still matches.
    let paint_sha =
        irpol::measure::read_measurement_csv(&dir.path().join("measurements/paint.csv"))
            .unwrap()
            .sha256;
    assert!(html.contains(&format!("<code>{}…</code>", &paint_sha[..16])));
    assert!(html.contains("<td class=\"ok\">source unchanged</td>"));
    assert!(html.contains("<td class=\"warn\">source CSV changed since the fit</td>"));
    assert!(html.contains("<td class=\"warn\">source CSV not found</td>"));
    assert!(html.contains("<td class=\"warn\">not fitted by irpol</td>"));
    // The drawn report is embedded by a relative link; the others say how to draw theirs.
    assert!(html.contains("<a href=\"paint.svg\"><img class=\"report\" src=\"paint.png\""));
    assert!(html.contains("No report figure yet: <code>irpol report "));
    assert!(html.contains("<a href=\"../fits/paint.toml\">material file</a>"));
    for attribute in ["src=\"/", "href=\"/", "file:"] {
        assert!(!html.contains(attribute), "absolute link {attribute}");
    }
}

#[test]
fn material_text_is_escaped() {
    let dir = tempfile::tempdir().unwrap();
    library(dir.path());
    let index = write_library_index(&dir.path().join("fits"), &dir.path().join("reports"))
        .unwrap()
        .path;
    let html = std::fs::read_to_string(index).unwrap();
    assert!(!html.contains("<b>\"tar\""));
    assert!(html.contains("<h2>&lt;b&gt;&quot;tar&quot; &amp; pitch&lt;/b&gt;</h2>"));
    // The anchor is percent-encoded, so it is a valid attribute and fragment.
    assert!(html.contains("id=\"m-%3Cb%3E%22tar%22%20%26%20pitch%3C%2Fb%3E\""));
    assert_eq!(escape_html("a<b>&\"c'"), "a&lt;b&gt;&amp;&quot;c&#39;");
}

#[test]
fn an_empty_library_gives_a_page_that_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let fits = dir.path().join("fits");
    std::fs::create_dir_all(&fits).unwrap();
    let index = write_library_index(&fits, &dir.path().join("reports"))
        .unwrap()
        .path;
    let html = std::fs::read_to_string(index).unwrap();
    assert!(html.contains("0 materials in") && html.contains("No materials yet"));
}

/// A file of the library folder that is not a material is skipped by the index with a warning
/// naming it and why, not refused: one stray file must not stop the index of the others.
#[test]
fn a_broken_library_entry_is_skipped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let fits = dir.path().join("fits");
    std::fs::create_dir_all(&fits).unwrap();
    std::fs::write(fits.join("broken.toml"), "name = \"x\"\n").unwrap();
    let written = write_library_index(&fits, &dir.path().join("reports")).unwrap();
    let [warning] = written.warnings.as_slice() else {
        panic!("{:?}", written.warnings)
    };
    assert!(
        warning.contains("broken.toml: not a valid material TOML")
            && warning.ends_with("; skipped, the library holds only material files"),
        "{warning}"
    );
    let html = std::fs::read_to_string(written.path).unwrap();
    assert!(
        html.contains("0 materials in") && !html.contains("broken"),
        "{html}"
    );
}

/// The summary-table row of `material` in an index page.
fn summary_row<'a>(html: &'a str, material: &str) -> &'a str {
    let start = html
        .find(&format!("<tr><td><a href=\"#m-{material}\">"))
        .unwrap_or_else(|| panic!("no summary row of {material}"));
    let end = start + html[start..].find("</tr>").unwrap();
    &html[start..end]
}

/// The shipped library (fits/ over measurements/): a spectral material's source is a file of
/// several wavelengths, verified by the spectral reader; a parameter the data bound from one side
/// shows that bound, as the fit's line and the report do, not a ± around a value on its bound.
#[test]
fn the_shipped_library_index_verifies_spectral_sources_and_shows_one_sided_bounds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = tempfile::tempdir().unwrap();
    let index = write_library_index(&root.join("fits"), dir.path())
        .unwrap()
        .path;
    let html = std::fs::read_to_string(index).unwrap();

    let glass = summary_row(&html, "silicate_glass");
    assert!(
        glass.contains("<td class=\"ok\">source unchanged</td>"),
        "{glass}"
    );
    assert!(!html.contains("reader of one wavelength"));
    for material in [
        "paper_paint",
        "rough_paint",
        "smooth_glass",
        "anodized_panel",
    ] {
        let row = summary_row(&html, material);
        assert!(row.contains("source unchanged"), "{row}");
    }

    let paint = summary_row(&html, "paper_paint");
    assert!(
        paint.contains("<td class=\"num\">0 † &lt; 3.721e-6 ‡</td>"),
        "{paint}"
    );
    assert!(
        !paint.contains("(at bound)") && !paint.contains("± 0.0000032"),
        "{paint}"
    );
    assert!(html.contains("† at a bound of its search interval"));
    assert!(html.contains("‡ one-sided 95 % profile-likelihood bounds, where a ± would mislead"));
}
