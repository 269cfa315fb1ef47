//! `reports/index.html`: one self-contained page over the material library (docs/design.md §4) — every
//! material with its parameters ± 1σ, fit quality, preferred distribution, provenance (source
//! CSV, SHA-256, whether the file still matches) and its report figure. Inline CSS and relative
//! links only, so the page works from a file browser and when the folder is copied elsewhere.

use super::fit_report::{
    fitted_cells, format_plain, is_free, parameters, preference, sha_prefix, source_unchanged,
    FOOTNOTE_BOUND, FOOTNOTE_PROFILE,
};
use super::ReportError;
use crate::atomic::write_atomically;
use crate::material::{list_library, FitRecord, Material, MaterialModel};
use crate::pbrdf::Parameter;
use std::fmt::Write as _;
use std::path::{Component, Path, PathBuf};

/// The index written, and a warning for each file of the library folder it skipped.
pub struct WrittenIndex {
    pub path: PathBuf,
    pub warnings: Vec<String>,
}

/// Writes `<reports_dir>/index.html` for the library in `library_dir` (skipping files that are
/// not materials, with a warning each).
pub fn write_library_index(
    library_dir: &Path,
    reports_dir: &Path,
) -> Result<WrittenIndex, ReportError> {
    let library = list_library(library_dir)?;
    let materials = library.materials.as_slice();
    let index = reports_dir.join("index.html");
    std::fs::create_dir_all(reports_dir).map_err(|source| ReportError::Write {
        path: reports_dir.to_owned(),
        source,
    })?;
    let html = library_index_html(library_dir, reports_dir, materials, &[]);
    write_atomically(&index, html.as_bytes()).map_err(|source| ReportError::Write {
        path: index.clone(),
        source,
    })?;
    Ok(WrittenIndex {
        path: index,
        warnings: library.warnings(),
    })
}

/// Text made safe for HTML element content and attribute values.
pub fn escape_html(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            _ => out.push(c),
        }
    }
    out
}

/// A relative path as a URL: each segment percent-encoded (RFC 3986 unreserved characters kept),
/// joined by '/'. Escape the result with [`escape_html`] only if it can hold '&' (it cannot).
fn url_of(path: &Path) -> String {
    path.components()
        .map(|c| match c {
            Component::ParentDir => "..".to_owned(),
            Component::CurDir => ".".to_owned(),
            other => percent_encode(&other.as_os_str().to_string_lossy()),
        })
        .collect::<Vec<_>>()
        .join("/")
}

fn percent_encode(segment: &str) -> String {
    let mut out = String::new();
    for byte in segment.bytes() {
        if byte.is_ascii_alphanumeric() || b"-._~".contains(&byte) {
            out.push(byte as char);
        } else {
            let _ = write!(out, "%{byte:02X}");
        }
    }
    out
}

/// `path` resolved on disk as far as it exists, the rest appended: a fit writes the index before
/// the library entries and folders it links to exist.
fn resolved(path: &Path) -> std::io::Result<PathBuf> {
    let mut existing = path;
    let mut rest = Vec::new();
    loop {
        match existing.canonicalize() {
            Ok(base) => return Ok(rest.iter().rev().fold(base, |p, c| p.join(c))),
            Err(error) => match (existing.parent(), existing.file_name()) {
                (Some(parent), Some(name)) => {
                    rest.push(name.to_owned());
                    existing = if parent.as_os_str().is_empty() {
                        Path::new(".")
                    } else {
                        parent
                    };
                }
                _ => return Err(error),
            },
        }
    }
}

/// `target` relative to the folder `from`, both resolved on disk ([`resolved`]); the absolute
/// target when they share no root (another drive) or cannot be resolved.
fn relative_to(from: &Path, target: &Path) -> PathBuf {
    let (Ok(from), Ok(target)) = (resolved(from), resolved(target)) else {
        return target.to_owned();
    };
    let from: Vec<Component> = from.components().collect();
    let to: Vec<Component> = target.components().collect();
    let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
    if common == 0 {
        return target;
    }
    let mut relative = PathBuf::new();
    for _ in common..from.len() {
        relative.push("..");
    }
    for component in &to[common..] {
        relative.push(component.as_os_str());
    }
    relative
}

/// "value ± σ" of one parameter in the index, "value (fixed)", or the report's cells of a
/// parameter on a bound ("0 † < 3.722e-6 ‡"; [`footnotes`] explains the marks).
fn parameter_text(material: &Material, name: &str, value: f64) -> String {
    match material.fit.as_ref() {
        Some(fit) if is_free(fit, name) => {
            let (value, sigma, _) = fitted_cells(fit, name, value);
            format!("{value} {sigma}")
        }
        Some(_) => format!("{} (fixed)", format_plain(value)),
        None => format_plain(value),
    }
}

/// The notes on the marks the parameter cells of `materials` carry, one paragraph (or nothing).
fn footnotes(materials: &[(PathBuf, Material)]) -> String {
    let fits = || materials.iter().filter_map(|(_, m)| m.fit.as_ref());
    let mut notes = Vec::new();
    if fits().any(|fit| !fit.at_bound.is_empty()) {
        notes.push(FOOTNOTE_BOUND.to_owned());
    }
    if fits().any(|fit| !fit.profile_bounds.is_empty()) {
        notes.push(format!("{FOOTNOTE_PROFILE}, where a ± would mislead"));
    }
    if notes.is_empty() {
        String::new()
    } else {
        format!(
            "<p class=\"muted\">{}.</p>\n",
            escape_html(&notes.join("; "))
        )
    }
}

/// Whether the fit's source files are still the files that were fitted, each read by the reader
/// of the material's kind (a spectral file may hold several wavelengths).
fn provenance(material_path: &Path, material: &Material) -> (String, &'static str) {
    let Some(fit) = material.fit.as_ref() else {
        return ("not fitted by irpol".into(), "warn");
    };
    let spectral = matches!(material.model, MaterialModel::Spectral(_));
    match source_unchanged(material_path, fit, spectral) {
        Ok(_) => ("source unchanged".into(), "ok"),
        Err(ReportError::SourceChanged { .. } | ReportError::SourceDataChanged { .. }) => {
            ("source CSV changed since the fit".into(), "warn")
        }
        Err(ReportError::SourceMissing { .. }) => ("source CSV not found".into(), "warn"),
        Err(other) => (other.to_string(), "warn"),
    }
}

const STYLE: &str = "
body { font-family: 'DejaVu Sans', Helvetica, Arial, sans-serif; margin: 24px auto; max-width: 1500px;
       color: #1b1b1b; background: #fafafa; padding: 0 16px; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
p.lead { color: #555; margin-top: 0; }
table { border-collapse: collapse; background: #fff; }
th, td { padding: 5px 10px; border-bottom: 1px solid #e2e2e2; text-align: left; vertical-align: top; }
th { background: #f0f0f0; font-weight: 600; }
td.num { font-variant-numeric: tabular-nums; white-space: nowrap; }
section.material { background: #fff; border: 1px solid #ddd; border-radius: 6px; margin: 28px 0;
                   padding: 12px 18px; }
section.material h2 { margin: 4px 0 8px; font-size: 1.3em; }
.facts { display: flex; flex-wrap: wrap; gap: 28px; }
.facts table { font-size: 0.95em; }
img.report { width: 100%; height: auto; border: 1px solid #ddd; margin-top: 12px; }
.ok { color: #1a7f37; } .warn { color: #b42318; } .muted { color: #666; }
code { font-family: 'DejaVu Sans Mono', Menlo, Consolas, monospace; font-size: 0.92em; }
";

/// The index page of `materials` (library entries and their files), not written. Materials named
/// in `new_reports` have a report figure although it is not on disk yet (a fit writes the page and
/// the figures together), the others have one when `<reports_dir>/<name>.png` exists.
pub fn library_index_html(
    library_dir: &Path,
    reports_dir: &Path,
    materials: &[(PathBuf, Material)],
    new_reports: &[&str],
) -> String {
    let mut html = String::new();
    let _ = write!(
        html,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n\
         <title>irpol material library</title>\n<style>{STYLE}</style>\n</head>\n<body>\n\
         <h1>irpol material library</h1>\n<p class=\"lead\">{} material{} in <code>{}</code>; \
         polarimetric BRDF fits (docs/design.md §1.3), parameters with 1-σ uncertainties.</p>\n",
        materials.len(),
        if materials.len() == 1 { "" } else { "s" },
        escape_html(&library_dir.display().to_string())
    );
    if materials.is_empty() {
        html.push_str("<p>No materials yet: run <code>irpol fit</code>.</p>\n</body>\n</html>\n");
        return html;
    }
    summary_table(&mut html, materials);
    html.push_str(&footnotes(materials));
    for (path, material) in materials {
        let has_report = new_reports.contains(&material.name.as_str())
            || reports_dir.join(format!("{}.png", material.name)).is_file();
        material_section(&mut html, reports_dir, path, material, has_report);
    }
    let _ = write!(
        html,
        "<p class=\"muted\">Written by irpol {}.</p>\n</body>\n</html>\n",
        env!("CARGO_PKG_VERSION")
    );
    html
}

fn anchor(material: &Material) -> String {
    format!("m-{}", percent_encode(&material.name))
}

/// The reduced χ² cell: the number, and in red, for a fit that does not describe its data, why
/// ([`crate::material::FitRecord::misfit`]).
fn misfit_cell(fit: &crate::material::FitRecord) -> String {
    let chi2 = format_plain(fit.reduced_chi2);
    let misfit = fit.misfit();
    if misfit.is_empty() {
        return chi2;
    }
    format!(
        "{chi2} <span class=\"warn\">does not describe its data: {}</span>",
        escape_html(&misfit.join(", "))
    )
}

fn summary_table(html: &mut String, materials: &[(PathBuf, Material)]) {
    html.push_str(
        "<table>\n<tr><th>material</th><th>distribution</th><th>shadowing</th><th>λ (µm)</th>\
         <th>σ</th><th>q</th><th>n</th><th>k</th><th>ρ<sub>d</sub></th><th>reduced χ²</th>\
         <th>points</th><th>provenance</th></tr>\n",
    );
    for (path, material) in materials {
        let model = &material.model;
        let (wavelength, cells) = model_cells(material);
        let (chi2, points) = material.fit.as_ref().map_or(("—".into(), "—".into()), |f| {
            (misfit_cell(f), f.points.to_string())
        });
        let (status, class) = provenance(path, material);
        let _ = write!(
            html,
            "<tr><td><a href=\"#{}\">{}</a></td><td>{}</td><td>{}</td><td class=\"num\">{}</td>",
            anchor(material),
            escape_html(&material.name),
            model.distribution().name(),
            model.shadowing().name(),
            escape_html(&wavelength)
        );
        for cell in cells {
            let _ = write!(html, "<td class=\"num\">{cell}</td>");
        }
        let _ = writeln!(
            html,
            "<td class=\"num\">{chi2}</td><td class=\"num\">{points}</td>\
             <td class=\"{class}\">{}</td></tr>",
            escape_html(&status)
        );
    }
    html.push_str("</table>\n");
}

/// The summary table's λ cell and its σ, q, n, k, ρ_d cells (HTML-escaped). A spectral material
/// shows its table's range: λ first–last, n, k, ρ_d min–max (its section lists every node).
fn model_cells(material: &Material) -> (String, Vec<String>) {
    let cell = |name: &str, value: Option<f64>| match value {
        Some(value) => escape_html(&parameter_text(material, name, value)),
        None => "—".into(),
    };
    match &material.model {
        MaterialModel::Grey(model) => (
            format_plain(model.wavelength_um),
            // The summary's columns are §1.3's σ, q, n, k, ρ_d; a volume model's own parameters
            // are in its section below.
            ["sigma", "q", "n", "k", "rho_d"]
                .into_iter()
                .map(|name| {
                    let value = parameters(model)
                        .into_iter()
                        .find(|(_, n, _)| *n == name)
                        .and_then(|(_, _, v)| v);
                    cell(name, value)
                })
                .collect(),
        ),
        MaterialModel::Spectral(model) => {
            let (first, last) = model.range_um();
            let q = model.distribution.parameter(Parameter::Q);
            (
                format!("{}–{}", format_plain(first), format_plain(last)),
                vec![
                    cell("sigma", Some(model.distribution.sigma())),
                    cell("q", q),
                    escape_html(&span(&model.n)),
                    escape_html(&span(&model.k)),
                    escape_html(&span(&model.rho_d)),
                ],
            )
        }
    }
}

/// "min–max" of a table's values (one value if they are all equal).
fn span(values: &[f64]) -> String {
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if lo == hi {
        format_plain(lo)
    } else {
        format!("{}–{}", format_plain(lo), format_plain(hi))
    }
}

/// The parameter table of a material's section: σ, q, n, k, ρ_d of a grey material; σ, q and
/// then n, k, ρ_d at each wavelength of a spectral one.
fn parameter_table(html: &mut String, material: &Material) {
    html.push_str("<table>\n<tr><th>parameter</th><th>value ± 1σ</th></tr>\n");
    let mut row = |symbol: &str, text: String| {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td class=\"num\">{}</td></tr>",
            escape_html(symbol),
            escape_html(&text)
        );
    };
    match &material.model {
        MaterialModel::Grey(model) => {
            for (symbol, name, value) in parameters(model) {
                if let Some(value) = value {
                    row(symbol, parameter_text(material, name, value));
                }
            }
        }
        MaterialModel::Spectral(model) => {
            row(
                "σ",
                parameter_text(material, "sigma", model.distribution.sigma()),
            );
            if let Some(q) = model.distribution.parameter(Parameter::Q) {
                row("q", parameter_text(material, "q", q));
            }
            for node in model.nodes() {
                let at = format!("{} µm", format_plain(node.wavelength_um));
                row(&format!("n ({at})"), format_plain(node.n));
                row(&format!("k ({at})"), format_plain(node.k));
                row(&format!("ρd ({at})"), format_plain(node.rho_d));
            }
        }
    }
    html.push_str("</table>\n");
}

/// A material's section: its heading and model, its parameter and fit tables, and its report
/// figure (linked to the SVG) or how to draw one.
fn material_section(
    html: &mut String,
    reports_dir: &Path,
    path: &Path,
    material: &Material,
    has_report: bool,
) {
    let model = &material.model;
    let wavelengths = model.wavelengths_um();
    let _ = write!(
        html,
        "<section class=\"material\" id=\"{}\">\n<h2>{}</h2>\n<p>{} slopes, {} shadowing, \
         λ = {} µm — <a href=\"{}\">material file</a></p>\n<div class=\"facts\">\n",
        anchor(material),
        escape_html(&material.name),
        model.distribution().name(),
        model.shadowing().name(),
        escape_html(&span(&wavelengths)),
        escape_html(&url_of(&relative_to(reports_dir, path)))
    );
    parameter_table(html, material);
    match material.fit.as_ref() {
        Some(fit) => fit_table(html, path, material, fit),
        None => html.push_str("<p class=\"warn\">Not fitted by irpol: no fit record.</p>\n"),
    }
    html.push_str("</div>\n");
    report_figure(html, path, material, has_report);
    html.push_str("</section>\n");
}

/// The fit-quality table of a section: [`fit_facts`], then the source with its SHA-256 prefix
/// and whether the file still matches.
fn fit_table(html: &mut String, path: &Path, material: &Material, fit: &FitRecord) {
    html.push_str("<table>\n<tr><th>fit quality</th><th></th></tr>\n");
    for (key, value) in fit_facts(material, fit) {
        let _ = writeln!(
            html,
            "<tr><td>{}</td><td>{}</td></tr>",
            escape_html(key),
            escape_html(&value)
        );
    }
    let (status, class) = provenance(path, material);
    let _ = writeln!(
        html,
        "<tr><td>source</td><td><code>{}</code> sha256 <code>{}</code> \
         <span class=\"{class}\">{}</span></td></tr>\n</table>",
        escape_html(&fit.source.display().to_string()),
        escape_html(&sha_prefix(&fit.source_sha256)),
        escape_html(&status)
    );
}

/// The (key, value) rows of the fit-quality table: χ², AIC/BIC, data, optimizer, the competing
/// fit, the preferred distribution and any undetermined parameters (not yet escaped).
fn fit_facts(material: &Material, fit: &FitRecord) -> Vec<(&'static str, String)> {
    let mut rows = vec![
        ("reduced χ²", format_plain(fit.reduced_chi2)),
        ("χ² (cost)", format_plain(fit.cost)),
        (
            "AIC / BIC",
            format!("{} / {}", format_plain(fit.aic), format_plain(fit.bic)),
        ),
        (
            "data",
            format!(
                "{} points × {} elements, {} degrees of freedom",
                fit.points,
                fit.elements.len(),
                fit.degrees_of_freedom
            ),
        ),
        (
            "optimizer",
            format!("{} (seed {}), {}", fit.optimizer, fit.seed, fit.termination),
        ),
        ("fitted by", material.tool_version.clone()),
    ];
    if let Some(alt) = &fit.alternative {
        rows.push((
            "competing fit",
            format!(
                "{}: reduced χ² {}, AIC {}, BIC {}",
                alt.model.distribution.name(),
                format_plain(alt.reduced_chi2),
                format_plain(alt.aic),
                format_plain(alt.bic)
            ),
        ));
    }
    rows.push((
        "preferred",
        preference(material).unwrap_or_else(|| "no competing distribution fitted".into()),
    ));
    if !fit.undetermined.is_empty() {
        rows.push(("not determined", fit.undetermined.join(", ")));
    }
    rows
}

/// The report figure of a section (the PNG, linking to the SVG), or the command that draws it.
fn report_figure(html: &mut String, path: &Path, material: &Material, has_report: bool) {
    let png = format!("{}.png", material.name);
    if has_report {
        let svg = format!("{}.svg", material.name);
        let _ = writeln!(
            html,
            "<a href=\"{}\"><img class=\"report\" src=\"{}\" alt=\"fit report of {}\" \
             loading=\"lazy\"></a>",
            escape_html(&url_of(Path::new(&svg))),
            escape_html(&url_of(Path::new(&png))),
            escape_html(&material.name)
        );
    } else {
        let _ = writeln!(
            html,
            "<p class=\"muted\">No report figure yet: <code>irpol report {}</code>.</p>",
            escape_html(&path.display().to_string())
        );
    }
}
