//! The report's parameter table: fitted values with 1-σ uncertainties beside the competing
//! distribution's best fit, fit quality (reduced χ², AIC, BIC), the preferred model, the data
//! and optimizer, and the provenance of the measurement (docs/design.md §2.2).

mod layout;

pub use layout::draw_table;

use crate::material::{ConfidenceBound, FitRecord, Material, ModelSpec};
use crate::pbrdf::Parameter;

/// Characters of the SHA-256 shown in the table and the index.
pub const SHA_PREFIX: usize = 16;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tone {
    Normal,
    Muted,
    Warning,
}

/// One line of the table.
#[derive(Clone, Debug, PartialEq)]
pub enum Row {
    Heading(String),
    /// Cells placed at the table's column stops.
    Cells(Vec<String>, Tone),
    /// Free text across the width, wrapped.
    Text(String, Tone),
}

/// `value ± sigma` rounded to the uncertainty's second significant digit; without a usable
/// uncertainty, four significant digits. An exact zero (a parameter on its bound) stays "0".
pub fn format_with_uncertainty(value: f64, sigma: Option<f64>) -> (String, Option<String>) {
    match sigma.filter(|s| s.is_finite() && *s > 0.0) {
        Some(sigma) => {
            let decimals = (1 - sigma.log10().floor() as i32).clamp(0, 10) as usize;
            let value = if value == 0.0 {
                "0".to_owned()
            } else {
                format!("{value:.decimals$}")
            };
            (value, Some(format!("{sigma:.decimals$}")))
        }
        None => (format_plain(value), None),
    }
}

/// The ± cell of a parameter with a profile bound: "< 3.722e-6 ‡", "> 1.215 ‡", "0.8000 … 2.100 ‡",
/// "unbounded ‡" (short enough for the column; the ‡ note below the table says what it is).
fn bound_cell(bound: &ConfidenceBound) -> String {
    match (bound.lower, bound.upper) {
        (None, Some(upper)) => format!("< {} ‡", format_plain(upper)),
        (Some(lower), None) => format!("> {} ‡", format_plain(lower)),
        (Some(lower), Some(upper)) => {
            format!("{} … {} ‡", format_plain(lower), format_plain(upper))
        }
        (None, None) => "unbounded ‡".into(),
    }
}

/// Four significant digits, in scientific form outside 1e-3…1e4.
pub fn format_plain(value: f64) -> String {
    if value == 0.0 {
        "0".into()
    } else if (1e-3..1e4).contains(&value.abs()) {
        let decimals = (3 - value.abs().log10().floor() as i32).max(0) as usize;
        format!("{value:.decimals$}")
    } else {
        format!("{value:.3e}")
    }
}

/// An angle in degrees with at most two decimals and no trailing zeros ("20", "62.5").
pub fn format_angle(degrees: f64) -> String {
    let text = format!("{degrees:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_owned()
}

/// The parameters of the model's terms: (symbol, name in `FitRecord` maps, value).
pub fn parameters(model: &ModelSpec) -> Vec<(&'static str, &'static str, Option<f64>)> {
    let terms = model.terms();
    Parameter::ALL
        .into_iter()
        .filter(|p| terms.has(*p))
        .map(|p| (p.label(), p.name(), model.parameter(p)))
        .collect()
}

/// A fit map entry under the parameter's name, accepting `rho` for `rho_d` (docs/design.md §4 spelling).
pub fn lookup<'a, T>(map: impl Fn(&str) -> Option<&'a T>, name: &str) -> Option<&'a T> {
    map(name).or_else(|| (name == "rho_d").then(|| map("rho")).flatten())
}

/// Whether the fit left parameter `name` on a bound of its search interval.
pub fn at_bound(fit: &FitRecord, name: &str) -> bool {
    fit.at_bound
        .iter()
        .any(|p| p == name || (name == "rho_d" && p == "rho"))
}

/// Whether the fit varied parameter `name` (rather than holding it fixed).
pub fn is_free(fit: &FitRecord, name: &str) -> bool {
    fit.free_parameters
        .iter()
        .any(|p| p == name || (name == "rho_d" && p == "rho"))
}

/// Which distribution the information criteria prefer, and by how much (Burnham & Anderson:
/// ΔAIC < 2 does not distinguish the models).
pub fn preference(material: &Material) -> Option<String> {
    let fit = material.fit.as_ref()?;
    let alt = fit.alternative.as_ref()?;
    let chosen = material.model.distribution().name();
    let other = alt.model.distribution.name();
    let delta_aic = alt.aic - fit.aic;
    let delta_bic = alt.bic - fit.bic;
    let winner = if delta_aic >= 0.0 { chosen } else { other };
    Some(if delta_aic.abs() < 2.0 {
        format!(
            "{chosen} ≈ {other}: |ΔAIC| = {:.1} < 2 does not distinguish them",
            delta_aic.abs()
        )
    } else {
        format!(
            "{winner} preferred: ΔAIC = {:.1}, ΔBIC = {:.1} ({other} − {chosen})",
            delta_aic, delta_bic
        )
    })
}

/// The robust loss the fit minimized, if not plain least squares (`settings.robust_loss`, as the
/// fit engine records it); then its cost is Σρ(r), not χ².
pub fn robust_loss(fit: &FitRecord) -> Option<&str> {
    fit.settings
        .get("robust_loss")
        .map(String::as_str)
        .filter(|loss| *loss != "none")
}

/// The first [`SHA_PREFIX`] characters of a SHA-256, with "…" when it is longer.
pub fn sha_prefix(sha: &str) -> String {
    let prefix: String = sha.chars().take(SHA_PREFIX).collect();
    if sha.chars().count() > SHA_PREFIX {
        format!("{prefix}…")
    } else {
        prefix
    }
}

/// The rows of the table: the parameters, then (for a fitted material) the fit quality, its
/// caveats and where the data and the fit came from.
pub fn table_rows(material: &Material) -> Vec<Row> {
    // A spectral material has its own report; ReportData::new refuses it before this.
    let Some(model) = material.model.grey() else {
        return Vec::new();
    };
    let fit = material.fit.as_ref();
    let mut rows = parameter_rows(model, fit);
    let Some(fit) = fit else {
        rows.push(Row::Text(
            "No fit record: the model was not fitted by irpol.".into(),
            Tone::Warning,
        ));
        return rows;
    };
    rows.extend(quality_rows(material, fit));
    rows.extend(caveat_rows(fit));
    rows.extend(provenance_rows(fit));
    rows
}

/// The parameter heading, the column header and one row per parameter: the chosen model's
/// value with its ± cell, beside the competing distribution's value when there is one.
fn parameter_rows(model: &ModelSpec, fit: Option<&FitRecord>) -> Vec<Row> {
    let alternative = fit.and_then(|f| f.alternative.as_ref());
    let mut rows = vec![Row::Heading(format!(
        "Parameters ({} slopes, {} shadowing)",
        model.distribution.name(),
        model.shadowing.name()
    ))];
    let mut header = vec![
        String::new(),
        format!("{} (chosen)", model.distribution.name()),
        "± 1σ".into(),
    ];
    if let Some(alt) = alternative {
        header.push(format!("{} (alt.)", alt.model.distribution.name()));
    }
    rows.push(Row::Cells(header, Tone::Muted));
    let alternative_values = alternative.map(|a| parameters(&a.model));
    for (i, (symbol, name, value)) in parameters(model).into_iter().enumerate() {
        let alt_value = alternative_values
            .as_ref()
            .and_then(|values| values[i].2)
            .map(format_plain)
            .unwrap_or_else(|| "—".into());
        let Some(value) = value else {
            if alternative.is_some() {
                rows.push(Row::Cells(
                    vec![symbol.into(), "—".into(), String::new(), alt_value],
                    Tone::Normal,
                ));
            }
            continue;
        };
        let (text, sigma_text, tone) = match fit {
            Some(fit) if is_free(fit, name) => fitted_cells(fit, name, value),
            Some(_) => (format_plain(value), "fixed".into(), Tone::Muted),
            None => (format_plain(value), String::new(), Tone::Normal),
        };
        let mut cells = vec![symbol.to_owned(), text, sigma_text];
        if alternative.is_some() {
            cells.push(alt_value);
        }
        rows.push(Row::Cells(cells, tone));
    }
    rows
}

/// The value and ± cells of free parameter `name` and their tone: the value marked † on a bound
/// of its search interval; an undetermined parameter's ± means nothing, so it is flagged, or
/// replaced by its profile bound when the fit has one. The report's table and the library index
/// both show these, so a parameter reads the same in both.
pub fn fitted_cells(fit: &FitRecord, name: &str, value: f64) -> (String, String, Tone) {
    let sigma = lookup(|k| fit.uncertainty.get(k), name).copied();
    let (text, sigma_text) = format_with_uncertainty(value, sigma);
    let undetermined = fit.undetermined.iter().any(|u| u == name);
    let bound = lookup(|k| fit.profile_bounds.get(k), name);
    let sigma_text = match (bound, sigma_text, undetermined) {
        (Some(bound), _, _) => bound_cell(bound),
        (None, Some(s), false) => format!("± {s}"),
        (None, Some(s), true) => format!("± {s} undetermined"),
        (None, None, _) => "± ? undetermined".into(),
    };
    let tone = if undetermined {
        Tone::Warning
    } else {
        Tone::Normal
    };
    let text = if at_bound(fit, name) {
        format!("{text} †")
    } else {
        text
    };
    (text, sigma_text, tone)
}

/// "Fit quality": reduced χ², cost, AIC and BIC of both fits, which distribution they prefer and
/// the strongest correlation.
fn quality_rows(material: &Material, fit: &FitRecord) -> Vec<Row> {
    let alternative = fit.alternative.as_ref();
    let mut rows = vec![Row::Heading("Fit quality".into())];
    let cost_label = match robust_loss(fit) {
        Some(loss) => format!("cost, {loss}"),
        None => "cost χ²".to_owned(),
    };
    let quality: [(&str, f64, Option<f64>); 4] = [
        (
            "reduced χ²",
            fit.reduced_chi2,
            alternative.map(|a| a.reduced_chi2),
        ),
        (cost_label.as_str(), fit.cost, alternative.map(|a| a.cost)),
        ("AIC", fit.aic, alternative.map(|a| a.aic)),
        ("BIC", fit.bic, alternative.map(|a| a.bic)),
    ];
    for (name, chosen, alt) in quality {
        let mut cells = vec![name.to_owned(), format_plain(chosen), String::new()];
        if let Some(alt) = alt {
            cells.push(format_plain(alt));
        }
        rows.push(Row::Cells(cells, Tone::Normal));
    }
    match preference(material) {
        Some(text) => rows.push(Row::Text(text, Tone::Normal)),
        None => rows.push(Row::Text(
            "no competing distribution was fitted".into(),
            Tone::Muted,
        )),
    }
    if let Some(text) = strongest_correlation(fit) {
        rows.push(Row::Text(text, Tone::Normal));
    }
    rows
}

/// The note on a value marked †.
pub const FOOTNOTE_BOUND: &str = "† at a bound of its search interval";
/// The note on a ± cell marked ‡.
pub const FOOTNOTE_PROFILE: &str = "‡ one-sided 95 % profile-likelihood bounds";

/// What the fit could not pin down: undetermined parameters, parameters on a bound (the † of
/// their value) and one-sided profile bounds (the ‡ of their ± cell).
fn caveat_rows(fit: &FitRecord) -> Vec<Row> {
    let mut rows = Vec::new();
    if !fit.undetermined.is_empty() {
        rows.push(Row::Text(
            format!(
                "not determined by these data: {} (relative σ > 50 % or |ρ| > 0.999)",
                fit.undetermined.join(", ")
            ),
            Tone::Warning,
        ));
    }
    if !fit.at_bound.is_empty() {
        let names: Vec<&str> = fit.at_bound.iter().map(|n| symbol(n)).collect();
        rows.push(Row::Text(
            format!("{FOOTNOTE_BOUND}: {}", names.join(", ")),
            Tone::Muted,
        ));
    }
    let correlated: Vec<String> = fit
        .identification()
        .into_iter()
        .filter(|(_, why)| why.starts_with("correlated"))
        .map(|(name, why)| format!("{} {why}", symbol(&name)))
        .collect();
    if !correlated.is_empty() {
        rows.push(Row::Text(
            format!(
                "determined only in combination (|ρ| > {}): {}",
                crate::material::STRONG_CORRELATION,
                correlated.join("; ")
            ),
            Tone::Warning,
        ));
    }
    if !fit.profile_bounds.is_empty() {
        let names: Vec<&str> = fit.profile_bounds.keys().map(|n| symbol(n)).collect();
        rows.push(Row::Text(
            format!(
                "{FOOTNOTE_PROFILE} (the data bound {} from one side at most; a ± would mislead)",
                names.join(", ")
            ),
            Tone::Warning,
        ));
    }
    rows
}

/// Where the search ran on a subsample of a large set (`fit::COARSE_POINTS`): which, so
/// that the convergence panel's early costs (scaled to the whole set) are read as estimates.
fn subsample_note(fit: &FitRecord) -> String {
    let stride = crate::fit::coarse_stride(fit.points);
    let local = fit.optimizer.split('+').any(|stage| stage != "ga");
    if stride > 1 && local {
        format!(" (search on 1 point in {stride}, then on all)")
    } else {
        String::new()
    }
}

/// "Data and optimizer": what was fitted, how, and the source files with their SHA-256 prefixes.
fn provenance_rows(fit: &FitRecord) -> Vec<Row> {
    let rmse = fit
        .rmse
        .get("m00")
        .map(|r| format!(", RMSE m00 = {} sr⁻¹", format_plain(*r)))
        .unwrap_or_default();
    let local = fit.convergence.len().saturating_sub(fit.global_iterations);
    let sources = fit
        .merged_sources
        .iter()
        .map(|m| {
            format!(
                " + {} ({})",
                m.source.display(),
                sha_prefix(&m.source_sha256)
            )
        })
        .collect::<String>();
    vec![
        Row::Heading("Data and optimizer".into()),
        Row::Text(
            format!(
                "{} points × {} elements ({}), {} dof{rmse}",
                fit.points,
                fit.elements.len(),
                element_span(&fit.elements),
                fit.degrees_of_freedom,
            ),
            Tone::Normal,
        ),
        Row::Text(
            format!(
                "{}, seed {}: {} generations + {} local iterations, {} evaluations{}; {}",
                fit.optimizer,
                fit.seed,
                fit.global_iterations,
                local,
                fit.evaluations,
                subsample_note(fit),
                fit.termination
            ),
            Tone::Normal,
        ),
        Row::Text(
            format!(
                "source {} (sha256 {}){sources}",
                fit.source.display(),
                sha_prefix(&fit.source_sha256),
            ),
            Tone::Muted,
        ),
    ]
}

/// The table's symbol of a parameter name ("sigma" → "σ").
pub fn symbol(name: &str) -> &str {
    Parameter::parse(name).map_or(name, |p| p.label())
}

fn element_span(elements: &[String]) -> String {
    match elements {
        [] => "none".into(),
        [one] => one.clone(),
        [first, .., last] => format!("{first}…{last}"),
    }
}

/// The largest off-diagonal |correlation| of the free parameters, named.
fn strongest_correlation(fit: &FitRecord) -> Option<String> {
    let names = &fit.free_parameters;
    let mut best: Option<(f64, usize, usize)> = None;
    for (i, row) in fit.correlation.iter().enumerate().take(names.len()) {
        for (j, &rho) in row.iter().enumerate().take(i) {
            if rho.is_finite() && best.is_none_or(|(b, _, _)| rho.abs() > b.abs()) {
                best = Some((rho, i, j));
            }
        }
    }
    best.map(|(rho, i, j)| {
        format!(
            "strongest correlation ρ({}, {}) = {rho:+.3}",
            symbol(&names[j]),
            symbol(&names[i])
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::AlternativeFit;
    use crate::pbrdf::{Shadowing, SlopeDistribution};
    use crate::report::fit_report::test_records::fit_record;
    use serde_json::json;

    #[test]
    fn values_are_rounded_to_their_uncertainty() {
        let cases = [
            ((0.100_34, Some(0.0012)), ("0.1003", Some("0.0012"))),
            ((1.812_3, Some(0.034)), ("1.812", Some("0.034"))),
            ((123.4, Some(12.0)), ("123", Some("12"))),
            ((0.02, Some(0.0)), ("0.02000", None)),
            ((2.5e-5, None), ("2.500e-5", None)),
        ];
        for ((value, sigma), (text, sigma_text)) in cases {
            let (got, got_sigma) = format_with_uncertainty(value, sigma);
            assert_eq!((got.as_str(), got_sigma.as_deref()), (text, sigma_text));
        }
        assert_eq!(format_plain(0.0), "0");
        assert_eq!(format_plain(9.925), "9.925");
        assert_eq!(format_angle(20.0), "20");
        assert_eq!(format_angle(62.5), "62.5");
        assert_eq!(sha_prefix(&"ab".repeat(32)), format!("{}…", "ab".repeat(8)));
    }

    pub(super) fn material(aic: f64, alternative_aic: f64) -> Material {
        let model = ModelSpec {
            distribution: SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
            shadowing: Shadowing::Smith,
            n: 1.2,
            k: 0.2,
            rho_d: 0.0,
            facet: Default::default(),
            lobe_keys: Default::default(),
            wavelength_um: 9.925,
        };
        Material {
            name: "m".into(),
            tool_version: "t".into(),
            fit: Some(fit_record(json!({
                "source": "m.csv",
                "source_sha256": "0".repeat(64),
                "points": 10,
                "elements": ["m00", "m10"],
                "free_parameters": ["sigma", "q", "rho"],
                "optimizer": "ga+nm",
                "cost": 18.0,
                "reduced_chi2": 1.06,
                "degrees_of_freedom": 17,
                "aic": aic,
                "bic": aic + 3.0,
                "uncertainty": { "sigma": 0.0012, "rho": 0.001 },
                "correlation": [[1.0, -0.95, 0.1], [-0.95, 1.0, 0.2], [0.1, 0.2, 1.0]],
                "undetermined": ["q", "rho_d"],
                "profile_bounds": { "rho_d": { "upper": 0.00312, "confidence": 0.95 } },
                "at_bound": ["rho_d"],
                "alternative": AlternativeFit {
                    model: ModelSpec {
                        distribution: SlopeDistribution::Gaussian { sigma: 0.09 },
                        ..model.clone()
                    },
                    cost: 30.0,
                    reduced_chi2: 1.6,
                    aic: alternative_aic,
                    bic: alternative_aic + 3.0,
                },
            }))),
            model: crate::material::MaterialModel::Grey(model),
        }
    }

    #[test]
    fn the_lower_aic_is_preferred_unless_within_two() {
        assert_eq!(
            preference(&material(24.0, 36.5)).unwrap(),
            "cauchy preferred: ΔAIC = 12.5, ΔBIC = 12.5 (gaussian − cauchy)"
        );
        assert!(preference(&material(40.0, 36.0))
            .unwrap()
            .starts_with("gaussian preferred: ΔAIC = -4.0"));
        assert!(preference(&material(24.0, 25.0))
            .unwrap()
            .contains("|ΔAIC| = 1.0 < 2 does not distinguish"));
    }

    #[test]
    fn table_rows_show_uncertainties_fixed_and_undetermined_parameters() {
        let rows = table_rows(&material(24.0, 36.5));
        let cells = |symbol: &str| {
            rows.iter()
                .find_map(|row| match row {
                    Row::Cells(cells, tone) if cells[0] == symbol => Some((cells.clone(), *tone)),
                    _ => None,
                })
                .unwrap()
        };
        assert_eq!(cells("σ").0, ["σ", "0.1000", "± 0.0012", "0.09000"]);
        assert_eq!(cells("q").1, Tone::Warning, "q is undetermined");
        assert_eq!(cells("q").0[2], "± ? undetermined");
        assert_eq!(cells("n").0[1..3], ["1.200", "fixed"]);
        assert_eq!(
            cells("ρd").0[1..3],
            ["0 †", "< 0.003120 ‡"],
            "an undetermined parameter shows its profile bound, not ±"
        );
        assert!(rows.contains(&Row::Text(
            "† at a bound of its search interval: ρd".into(),
            Tone::Muted
        )));
        assert!(rows.contains(&Row::Text(
            "strongest correlation ρ(σ, q) = -0.950".into(),
            Tone::Normal
        )));
        assert_eq!(cells("cost χ²").0[1], "18.00");
    }

    #[test]
    fn a_robust_cost_is_not_called_chi_squared() {
        let mut m = material(24.0, 36.5);
        let fit = m.fit.as_mut().unwrap();
        fit.settings.insert("robust_loss".into(), "none".into());
        assert_eq!(robust_loss(fit), None);
        fit.settings
            .insert("robust_loss".into(), "huber(1.5)".into());
        assert_eq!(robust_loss(fit), Some("huber(1.5)"));
        let rows = table_rows(&m);
        assert!(rows.iter().any(|row| matches!(row,
            Row::Cells(cells, _) if cells[0] == "cost, huber(1.5)" && cells[1] == "18.00")));
    }
}
