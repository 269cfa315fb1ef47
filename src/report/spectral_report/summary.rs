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

/// Font size the summary starts from; shrunk when its lines do not fit ([`summary_layout`]).
const FONT_SIZE: i32 = 20;
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
            "Shared by every wavelength ({} slopes, {} shadowing, terms {})",
            model.distribution.name(),
            model.shadowing.name(),
            model.terms()
        )),
        row("σ".into(), model.distribution.sigma(), "sigma"),
    ];
    if let Some(q) = model.distribution.parameter(Parameter::Q) {
        lines.push(row("q".into(), q, "q"));
    }
    // The subsurface parameters the fit shared (one number); per-wavelength ones are in the
    // table below.
    for (parameter, value) in model.volume.lobe_keys.iter() {
        if let crate::material::PerWavelength::Shared(v) = value {
            lines.push(row(parameter.name().to_owned(), *v, parameter.name()));
        }
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
    let rho_s = match model.volume.lobe_keys.get(Parameter::RhoS) {
        Some(crate::material::PerWavelength::Each(values)) => Some(values),
        _ => None,
    };
    let body = if rho_s.is_some() {
        "ρs ± 1σ"
    } else {
        "ρd ± 1σ"
    };
    let header = ["λ (µm)", "n ± 1σ", "k ± 1σ", body, "χ²/obs", "points"];
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
                match rho_s {
                    Some(values) => value(
                        values,
                        fit.volume_errors
                            .get(&Parameter::RhoS)
                            .map_or(&[][..], |e| e.as_slice()),
                    ),
                    None => value(&model.rho_d, &fit.rho_d_errors),
                },
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

/// Draws the summary into `area`: [`summary_layout`]'s lines at its font and column stops.
pub fn draw_summary<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    outcome: &SpectralFitOutcome,
    model: &SpectralModel,
) -> DrawResult<DB> {
    let (width, _) = area.dim_in_pixel();
    draw_caption(area, &format!("(e) {} — joint fit", outcome.material.name))?;
    let note = format!("{}/<λ>um.png", outcome.material.name);
    let layout = summary_layout(area, summary_lines(outcome, model), &note)?;
    let size = layout.size;
    let anchor = Pos::new(HPos::Left, VPos::Top);
    let normal = (FONT, size).into_font().color(&BLACK).pos(anchor);
    let muted = (FONT, size).into_font().color(&GREY).pos(anchor);
    let bold = (FONT, size, FontStyle::Bold)
        .into_font()
        .color(&BLACK)
        .pos(anchor);
    let right = width as i32 - 18;
    for (i, line) in layout.lines.iter().enumerate() {
        let y = TOP + i as i32 * layout.line_height;
        match line {
            Line::Heading(text) => {
                area.draw_text(text, &bold, (18, y))?;
                let rule = y + layout.line_height - 3;
                area.draw(&PathElement::new(
                    vec![(18, rule), (right, rule)],
                    RGBColor(190, 190, 190).stroke_width(1),
                ))?;
            }
            Line::Cells(cells, wide) => {
                let stops = if *wide {
                    &layout.wide_stops
                } else {
                    &layout.stops
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

/// The summary as drawn: font size, line height, the column stops of the parameter rows and of
/// the per-wavelength table, and the lines (the per-wavelength rows cut short when even the
/// smallest font cannot hold them all).
#[derive(Clone, Debug, PartialEq)]
pub struct SummaryLayout {
    pub size: i32,
    pub line_height: i32,
    pub stops: Vec<i32>,
    pub wide_stops: Vec<i32>,
    pub lines: Vec<Line>,
}

/// Smallest font the summary shrinks to; gap between its columns.
const MIN_FONT_SIZE: i32 = 10;
const COLUMN_GAP: i32 = 16;

/// Lays `lines` out in `area`: each column as wide as its widest cell (fixed stops let a long
/// value run into the next column), the font shrunk until every row fits the width and every
/// line the height; at the smallest font, per-wavelength rows that still do not fit give way to
/// one line saying how many more there are and where their fits are (`note`).
pub fn summary_layout<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    mut lines: Vec<Line>,
    note: &str,
) -> Result<SummaryLayout, DrawingAreaErrorKind<DB::ErrorType>> {
    let (width, height) = area.dim_in_pixel();
    let (width, room) = (width as i32 - 18, (height as i32 - TOP - 10).max(1));
    let mut size = FONT_SIZE;
    loop {
        let style = (FONT, size).into_font().color(&BLACK);
        let stops = |wide: bool| -> Result<(Vec<i32>, i32), DrawingAreaErrorKind<DB::ErrorType>> {
            let mut widths: Vec<i32> = Vec::new();
            for cells in lines.iter().filter_map(|l| match l {
                Line::Cells(cells, w) if *w == wide => Some(cells),
                _ => None,
            }) {
                for (i, cell) in cells.iter().enumerate() {
                    let w = area.estimate_text_size(cell, &style)?.0 as i32;
                    match widths.get_mut(i) {
                        Some(widest) => *widest = (*widest).max(w),
                        None => widths.push(w),
                    }
                }
            }
            let mut x = 18;
            let stops = widths
                .iter()
                .map(|w| {
                    let stop = x;
                    x += w + COLUMN_GAP;
                    stop
                })
                .collect();
            Ok((stops, x - COLUMN_GAP))
        };
        let ((stops, narrow_end), (wide_stops, wide_end)) = (stops(false)?, stops(true)?);
        let line_height = size * 3 / 2;
        let fits_width = narrow_end.max(wide_end) <= width;
        let fits_height = lines.len() as i32 * line_height <= room;
        if (fits_width && fits_height) || size <= MIN_FONT_SIZE {
            if !fits_height {
                cut_wavelength_rows(&mut lines, (room / line_height) as usize, note);
            }
            return Ok(SummaryLayout {
                size,
                line_height,
                stops,
                wide_stops,
                lines,
            });
        }
        size -= 1;
    }
}

/// Keeps `lines` within `capacity` by dropping per-wavelength rows from the end of the table
/// (the rows after its header), and says how many were dropped and where they are (`note`).
fn cut_wavelength_rows(lines: &mut Vec<Line>, capacity: usize, note: &str) {
    let rows: Vec<usize> = lines
        .iter()
        .enumerate()
        .filter(|(_, l)| matches!(l, Line::Cells(_, true)))
        .map(|(i, _)| i)
        .skip(1)
        .collect();
    let excess = (lines.len() + 1).saturating_sub(capacity).min(rows.len());
    if excess == 0 {
        return;
    }
    let dropped = &rows[rows.len() - excess..];
    let at = dropped[0];
    lines.drain(at..at + excess);
    lines.insert(
        at,
        Line::Muted(format!(
            "… {excess} more wavelengths: each one's fit in {note}"
        )),
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    fn wavelength_row(j: usize) -> Line {
        let cells = [
            format!("{}", 8.0 + 0.05 * j as f64),
            "2.8725 ± 0.0020".into(),
            "1.3862 ± 0.0014".into(),
            "0.0000019478 ± 0.0000017123".into(),
            "1.003".into(),
            "433".into(),
        ];
        Line::Cells(cells.to_vec(), true)
    }

    fn lines(wavelengths: usize) -> Vec<Line> {
        let mut lines = vec![
            Line::Heading("Shared by every wavelength".into()),
            Line::Cells(vec!["σ".into(), "0.0600032 ± 0.0000071".into()], false),
            Line::Heading("Per wavelength".into()),
            Line::Cells(
                ["λ (µm)", "n ± 1σ", "k ± 1σ", "ρd ± 1σ", "χ²/obs", "points"]
                    .map(String::from)
                    .to_vec(),
                true,
            ),
        ];
        lines.extend((0..wavelengths).map(wavelength_row));
        lines.push(Line::Muted("source x.csv".into()));
        lines
    }

    /// The layout of `lines` in the report's (e) panel, 1200 × 800 pixels.
    fn layout(lines: Vec<Line>) -> SummaryLayout {
        crate::plot_style::register_fonts();
        let mut buffer = vec![0u8; 1200 * 800 * 3];
        let area = BitMapBackend::with_buffer(&mut buffer, (1200, 800)).into_drawing_area();
        let layout = summary_layout(&area, lines, "glass/<λ>um.png").unwrap();
        // Every cell ends before the next column starts and within the panel.
        let style = (FONT, layout.size).into_font().color(&BLACK);
        for line in &layout.lines {
            if let Line::Cells(cells, wide) = line {
                let stops = if *wide {
                    &layout.wide_stops
                } else {
                    &layout.stops
                };
                for (i, cell) in cells.iter().enumerate() {
                    let end = stops[i] + area.estimate_text_size(cell, &style).unwrap().0 as i32;
                    let next = stops.get(i + 1).copied().unwrap_or(1200 - 18);
                    assert!(end <= next, "{cell} runs into the next column");
                }
            }
        }
        layout
    }

    #[test]
    fn the_summary_stays_inside_its_panel() {
        // Nine wavelengths fit at full size, every row kept.
        let few = layout(lines(9));
        assert_eq!((few.size, few.lines.len()), (FONT_SIZE, lines(9).len()));
        // Forty shrink the font and still fit.
        let many = layout(lines(40));
        assert!(
            many.size < FONT_SIZE && many.lines == lines(40),
            "{}",
            many.size
        );
        assert!(TOP + many.lines.len() as i32 * many.line_height <= 800 - 10);
        // Two hundred cannot: the table ends with how many more there are and where.
        let too_many = layout(lines(200));
        assert_eq!(too_many.size, MIN_FONT_SIZE);
        assert!(TOP + too_many.lines.len() as i32 * too_many.line_height <= 800 - 10);
        let cut = too_many
            .lines
            .iter()
            .find_map(|l| match l {
                Line::Muted(text) if text.starts_with('…') => Some(text.clone()),
                _ => None,
            })
            .expect("a line saying what was cut");
        let kept = too_many
            .lines
            .iter()
            .filter(|l| matches!(l, Line::Cells(_, true)))
            .count()
            - 1;
        assert_eq!(
            cut,
            format!(
                "… {} more wavelengths: each one's fit in glass/<λ>um.png",
                200 - kept
            )
        );
        assert_eq!(
            too_many.lines.last(),
            Some(&Line::Muted("source x.csv".into()))
        );
    }
}
