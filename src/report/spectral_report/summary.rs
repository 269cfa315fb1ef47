//! Panel (e): the shared parameters ± 1σ, the dispersion chosen with the AIC of the table and the
//! law, the fit's quality, and n, k, ρd ± 1σ and χ²/obs at each wavelength.

use super::super::fit_report::style::{draw_caption, DrawResult, GREY};
use super::super::fit_report::{format_plain, format_with_uncertainty, sha_prefix};
use crate::fit::SpectralFitOutcome;
use crate::material::{FitRecord, SpectralModel};
use crate::pbrdf::Parameter;
use crate::plot_style::FONT;
use crate::text::{number, shown_at_most};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;

/// One line of the summary.
#[derive(Clone, Debug, PartialEq)]
pub enum Line {
    Heading(String),
    /// Cells at the column stops of the section (`wide`: the per-wavelength table's).
    Cells(Vec<String>, bool),
    Text(String),
    Muted(String),
}

/// Column stops (pixels from the left) of the parameter rows and of the per-wavelength table.
const PARAMETER_STOPS: [i32; 2] = [18, 200];
const WAVELENGTH_STOPS: [i32; 6] = [18, 150, 390, 630, 880, 1040];
/// Font size and line height the summary starts from; shrunk when its lines do not fit.
const FONT_SIZE: i32 = 20;
const LINE_HEIGHT: i32 = 30;
const TOP: i32 = 52;
/// Characters of a free-text line kept (a long source path).
const MAX_TEXT: usize = 100;

/// `value ± error` as the grey table prints it; `value` alone without a usable error.
fn with_error(value: f64, error: Option<f64>) -> String {
    match format_with_uncertainty(value, error) {
        (value, Some(error)) => format!("{value} ± {error}"),
        (value, None) => value,
    }
}

/// The shared parameters: σ, q, and a law's ε∞ and oscillators, with their recorded 1-σ errors.
fn shared_lines(model: &SpectralModel, fit: Option<&FitRecord>) -> Vec<Line> {
    let error = |name: &str| fit.and_then(|f| f.uncertainty.get(name)).copied();
    let row = |symbol: String, value: f64, name: &str| {
        Line::Cells(vec![symbol, with_error(value, error(name))], false)
    };
    let mut lines = vec![
        Line::Heading(format!(
            "Shared by every wavelength ({} slopes, {} shadowing)",
            model.distribution.name(),
            model.shadowing.name()
        )),
        row("σ".into(), model.distribution.sigma(), "sigma"),
    ];
    if let Some(q) = model.distribution.parameter(Parameter::Q) {
        lines.push(row("q".into(), q, "q"));
    }
    if let Some(law) = &model.dispersion {
        lines.push(row("ε∞".into(), law.eps_inf, "eps_inf"));
        for (j, o) in law.oscillators.iter().enumerate() {
            let j = j + 1;
            lines.push(row(
                format!("λ{j} (µm)"),
                o.resonance_um,
                &format!("resonance_um_{j}"),
            ));
            lines.push(row(format!("Δε{j}"), o.strength, &format!("strength_{j}")));
            lines.push(row(
                format!("width{j} (µm)"),
                o.damping_um,
                &format!("damping_um_{j}"),
            ));
        }
    }
    lines
}

/// The dispersion kept, the AIC of the table and of the law, and the fit's quality.
fn quality_lines(outcome: &SpectralFitOutcome, fit: Option<&FitRecord>) -> Vec<Line> {
    let chosen = &outcome.chosen;
    let mut lines = vec![Line::Heading("Dispersion and fit quality".into())];
    match fit.and_then(|f| f.dispersion.as_ref()) {
        Some(d) => match d.law_aic {
            Some(law) => {
                let delta = law - d.table_aic;
                let verdict = if delta.abs() < 2.0 {
                    "|ΔAIC| < 2: the data do not distinguish them"
                } else if delta < 0.0 {
                    "the law is preferred"
                } else {
                    "the table is preferred"
                };
                lines.push(Line::Text(format!(
                    "dispersion {}: AIC law = {}, table = {} (ΔAIC = {delta:.1}; {verdict})",
                    d.chosen,
                    format_plain(law),
                    format_plain(d.table_aic)
                )));
            }
            None => lines.push(Line::Text(format!(
                "dispersion {}: AIC = {} (no law fitted: --dispersion lorentz:N compares one)",
                d.chosen,
                format_plain(d.table_aic)
            ))),
        },
        None => lines.push(Line::Text(format!("dispersion {}", chosen.dispersion))),
    }
    lines.push(Line::Text(format!(
        "reduced χ² = {}, χ² = {} over {} observations, {} dof; AIC = {}, BIC = {}",
        format_plain(chosen.reduced_chi2),
        format_plain(chosen.chi2),
        chosen.observations,
        chosen.degrees_of_freedom,
        format_plain(chosen.aic),
        format_plain(chosen.bic)
    )));
    if let Some(choice) = fit.and_then(|f| f.model_choice.as_ref()) {
        lines.push(Line::Text(choice.clone()));
    }
    lines
}

/// n, k, ρd ± 1σ, χ²/obs and points at each wavelength.
fn wavelength_lines(outcome: &SpectralFitOutcome, model: &SpectralModel) -> Vec<Line> {
    let fit = &outcome.chosen;
    let header = ["λ (µm)", "n ± 1σ", "k ± 1σ", "ρd ± 1σ", "χ²/obs", "points"];
    let mut lines = vec![
        Line::Heading("Per wavelength".into()),
        Line::Cells(header.iter().map(|h| h.to_string()).collect(), true),
    ];
    for (j, &w) in model.wavelength_um.iter().enumerate() {
        let value = |values: &[f64], errors: &[f64]| match values.get(j) {
            Some(&v) => with_error(v, errors.get(j).copied()),
            None => "—".into(),
        };
        let chi2 = fit
            .chi2_per_wavelength
            .get(j)
            .map_or("—".into(), |&(c, n)| format_plain(c / n.max(1) as f64));
        let points = outcome
            .measurements
            .get(j)
            .map_or("—".into(), |s| s.points.len().to_string());
        lines.push(Line::Cells(
            vec![
                number(w),
                value(&model.n, &fit.n_errors),
                value(&model.k, &fit.k_errors),
                value(&model.rho_d, &fit.rho_d_errors),
                chi2,
                points,
            ],
            true,
        ));
    }
    lines
}

/// Every line of the summary.
pub fn summary_lines(outcome: &SpectralFitOutcome, model: &SpectralModel) -> Vec<Line> {
    let fit = outcome.material.fit.as_ref();
    let mut lines = shared_lines(model, fit);
    lines.extend(quality_lines(outcome, fit));
    lines.extend(wavelength_lines(outcome, model));
    if let Some(fit) = fit {
        lines.push(Line::Muted(format!(
            "source {} (sha256 {}); {}",
            fit.source.display(),
            sha_prefix(&fit.source_sha256),
            fit.optimizer
        )));
    }
    lines
}

/// Draws the summary into `area`, its font shrunk when the lines would not fit.
pub fn draw_summary<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    outcome: &SpectralFitOutcome,
    model: &SpectralModel,
) -> DrawResult<DB> {
    let (width, height) = area.dim_in_pixel();
    draw_caption(area, &format!("(e) {} — joint fit", outcome.material.name))?;
    let lines = summary_lines(outcome, model);
    let room = (height as i32 - TOP - 10).max(1);
    let line_height = LINE_HEIGHT.min(room / lines.len().max(1) as i32).max(12);
    let size = (FONT_SIZE * line_height / LINE_HEIGHT).max(10) & !1;
    let anchor = Pos::new(HPos::Left, VPos::Top);
    let normal = (FONT, size).into_font().color(&BLACK).pos(anchor);
    let muted = (FONT, size).into_font().color(&GREY).pos(anchor);
    let bold = (FONT, size, FontStyle::Bold)
        .into_font()
        .color(&BLACK)
        .pos(anchor);
    let right = width as i32 - 18;
    for (i, line) in lines.iter().enumerate() {
        let y = TOP + i as i32 * line_height;
        match line {
            Line::Heading(text) => {
                area.draw_text(text, &bold, (18, y))?;
                let rule = y + line_height - 3;
                area.draw(&PathElement::new(
                    vec![(18, rule), (right, rule)],
                    RGBColor(190, 190, 190).stroke_width(1),
                ))?;
            }
            Line::Cells(cells, wide) => {
                let stops: &[i32] = if *wide {
                    &WAVELENGTH_STOPS
                } else {
                    &PARAMETER_STOPS
                };
                for (cell, &x) in cells.iter().zip(stops) {
                    area.draw_text(cell, &normal, (x, y))?;
                }
            }
            Line::Text(text) => area.draw_text(&shown_at_most(text, MAX_TEXT), &normal, (18, y))?,
            Line::Muted(text) => area.draw_text(&shown_at_most(text, MAX_TEXT), &muted, (18, y))?,
        }
    }
    Ok(())
}
