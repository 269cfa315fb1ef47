//! Panels (a) n(λ), (b) k(λ) and (d) χ² per observation over wavelength.

use super::super::fit_report::format_plain;
use super::super::fit_report::style::{
    draw_legend_top_right, panel_chart, report_mesh_style, sane_linear_range, Chart2d, DrawResult,
    LegendEntry, LineKind, Marker, AXIS_DESC_SIZE, GREY, TICK_SIZE,
};
use crate::fit::SpectralFitOutcome;
use crate::material::SpectralModel;
use crate::plot_style::{FONT, TABLEAU20};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

type Area<DB> = DrawingArea<DB, Shift>;

/// Points of the dense law curves.
const LAW_SAMPLES: usize = 400;

/// One index (n or k) over wavelength.
pub struct IndexPanel {
    pub caption: &'static str,
    pub y_desc: &'static str,
    /// (λ, value, 1-σ error) at the measured wavelengths.
    pub points: Vec<(f64, f64, f64)>,
    pub points_label: String,
    /// Whether the points are the model itself (a table, linear between them: joined).
    pub joined: bool,
    /// The law the model follows, densely, and its legend label.
    pub law: Option<(Vec<(f64, f64)>, String)>,
}

/// Panels (a) and (b). A table fit shows its n, k ± 1σ; a law fit shows the law, with the table
/// fit's free n, k ± 1σ (when recorded) as the points it is judged against.
pub fn index_panels(outcome: &SpectralFitOutcome, model: &SpectralModel) -> [IndexPanel; 2] {
    let (free, free_label) = match &outcome.table {
        Some(table) if model.dispersion.is_some() => (table, "n, k free per λ (table fit) ± 1σ"),
        _ => (&outcome.chosen, "fitted ± 1σ (linear between wavelengths)"),
    };
    let joined = model.dispersion.is_none();
    let law = model.dispersion.as_ref().map(|law| {
        let (first, last) = model.range_um();
        (0..=LAW_SAMPLES)
            .map(|i| {
                let w = first + (last - first) * i as f64 / LAW_SAMPLES as f64;
                (w, law.index(w))
            })
            .collect::<Vec<_>>()
    });
    let law_label = format!("Lorentz law (chosen, {})", outcome.chosen.dispersion);
    let points = |values: &[f64], errors: &[f64]| {
        model
            .wavelength_um
            .iter()
            .zip(values)
            .zip(errors)
            .map(|((&w, &v), &e)| (w, v, e))
            .collect()
    };
    let curve = |pick: fn(&crate::optics::RefractiveIndex) -> f64| {
        law.as_ref().map(|samples| {
            let line = samples.iter().map(|(w, index)| (*w, pick(index))).collect();
            (line, law_label.clone())
        })
    };
    [
        IndexPanel {
            caption: "(a) Refractive index n(λ)",
            y_desc: "n",
            points: points(&free.model.n, &free.n_errors),
            points_label: free_label.into(),
            joined,
            law: curve(|index| index.n),
        },
        IndexPanel {
            caption: "(b) Extinction coefficient k(λ)",
            y_desc: "k",
            points: points(&free.model.k, &free.k_errors),
            points_label: free_label.into(),
            joined,
            law: curve(|index| index.k),
        },
    ]
}

/// The y range of an index panel: every point with its error bar and the law, with a margin.
fn index_range(panel: &IndexPanel) -> (f64, f64) {
    let bars = panel.points.iter().flat_map(|&(_, v, e)| {
        let e = if e.is_finite() { e } else { 0.0 };
        [v - e, v + e]
    });
    let law = panel
        .law
        .iter()
        .flat_map(|(line, _)| line.iter().map(|p| p.1));
    let (low, high) = bars
        .chain(law)
        .filter(|v| v.is_finite())
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(v), h.max(v))
        });
    let pad = 0.08 * (high - low).max(0.02);
    // Room above for the legend.
    sane_linear_range(low - pad, high + 2.5 * pad, (0.0, 1.0))
}

pub fn draw_index<DB: DrawingBackend>(
    area: &Area<DB>,
    panel: &IndexPanel,
    (x0, x1): (f64, f64),
) -> DrawResult<DB> {
    let mut chart = wavelength_chart(
        area,
        panel.caption,
        (x0, x1),
        index_range(panel),
        panel.y_desc,
    )?;
    let color = TABLEAU20[0];
    let mut entries = Vec::new();
    if let Some((line, label)) = &panel.law {
        chart.draw_series(LineSeries::new(line.clone(), BLACK.stroke_width(2)))?;
        entries.push(LegendEntry::line(label.clone(), BLACK, LineKind::Solid));
    }
    let finite: Vec<(f64, f64, f64)> = panel
        .points
        .iter()
        .copied()
        .filter(|p| p.0.is_finite() && p.1.is_finite())
        .collect();
    if panel.joined {
        let line = finite.iter().map(|&(x, v, _)| (x, v));
        chart.draw_series(LineSeries::new(line, color.mix(0.7).stroke_width(1)))?;
    }
    chart.draw_series(
        finite
            .iter()
            .filter(|p| p.2.is_finite() && p.2 > 0.0)
            .map(|&(x, v, e)| {
                ErrorBar::new_vertical(x, v - e, v, v + e, color.stroke_width(2), 12)
            }),
    )?;
    chart.draw_series(
        finite
            .iter()
            .map(|&(x, v, _)| Circle::new((x, v), 5, color.filled())),
    )?;
    entries.push(LegendEntry {
        label: panel.points_label.clone(),
        color,
        line: panel.joined.then_some(LineKind::Solid),
        marker: Some(Marker::FilledCircle),
    });
    draw_legend_top_right(area, chart.plotting_area().get_pixel_range(), &entries, 10)
}

/// A chart over wavelength `x0`…`x1` (µm) and `low`…`high`, its grid, ticks and axis titles
/// drawn: the frame of panels (a), (b) and (d).
fn wavelength_chart<'a, DB: DrawingBackend>(
    area: &'a Area<DB>,
    caption: &str,
    (x0, x1): (f64, f64),
    (low, high): (f64, f64),
    y_desc: &str,
) -> Result<Chart2d<'a, DB>, DrawingAreaErrorKind<DB::ErrorType>> {
    let mut chart = panel_chart(area, caption, 24).build_cartesian_2d(x0..x1, low..high)?;
    let mesh = &mut chart.configure_mesh();
    mesh.x_labels(10)
        .y_labels(8)
        .x_label_formatter(&|v| format!("{v:.1}"))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .x_desc("wavelength λ (µm)")
        .y_desc(y_desc);
    report_mesh_style(mesh, TICK_SIZE, AXIS_DESC_SIZE).draw()?;
    Ok(chart)
}

/// (λ, χ²/observation) of `fit` at each measured wavelength of `outcome` (finite values only).
fn chi2_per_observation(
    outcome: &SpectralFitOutcome,
    fit: &crate::fit::SpectralFit,
) -> Vec<(f64, f64)> {
    outcome
        .measurements
        .iter()
        .zip(&fit.chi2_per_wavelength)
        .map(|(set, &(chi2, n))| (set.wavelength_um, chi2 / n.max(1) as f64))
        .filter(|p| p.1.is_finite())
        .collect()
}

/// Panel (d): χ²/observation at each wavelength as bars (the kept fit), the table fit's as hollow
/// circles when a law was kept, and the line χ²/obs = 1 of a fit at the noise level.
pub fn draw_chi2<DB: DrawingBackend>(
    area: &Area<DB>,
    outcome: &SpectralFitOutcome,
    (x0, x1): (f64, f64),
) -> DrawResult<DB> {
    let bars = chi2_per_observation(outcome, &outcome.chosen);
    let table = outcome
        .table
        .as_ref()
        .map(|fit| chi2_per_observation(outcome, fit));
    let top = bars
        .iter()
        .chain(table.iter().flatten())
        .map(|p| p.1)
        .fold(1.0, f64::max);
    let mut chart = wavelength_chart(
        area,
        "(d) χ² per observation at each wavelength",
        (x0, x1),
        (0.0, top * 1.35),
        "χ² / observation",
    )?;
    let color = TABLEAU20[0];
    draw_chi2_bars(&mut chart, &bars, x1 - x0, color)?;
    chart.draw_series(DashedLineSeries::new(
        vec![(x0, 1.0), (x1, 1.0)],
        7,
        5,
        GREY.stroke_width(2),
    ))?;
    let mut entries = vec![LegendEntry::line(
        format!(
            "kept fit ({}), χ²red = {}",
            outcome.chosen.dispersion,
            format_plain(outcome.chosen.reduced_chi2)
        ),
        color,
        LineKind::Patch,
    )];
    if let (Some(points), Some(fit)) = (&table, &outcome.table) {
        let hollow = color.stroke_width(2);
        chart.draw_series(points.iter().map(|&p| Circle::new(p, 6, hollow)))?;
        entries.push(LegendEntry::marker(
            format!("table fit, χ²red = {}", format_plain(fit.reduced_chi2)),
            color,
            Marker::HollowCircle,
        ));
    }
    entries.push(LegendEntry::line(
        "χ²/obs = 1 (fit at the noise level)",
        GREY,
        LineKind::Dashed,
    ));
    draw_legend_top_right(area, chart.plotting_area().get_pixel_range(), &entries, 10)
}

/// The bars of `bars` (λ, value), 0.6 of their closest spacing wide (at most 0.6 of `span`), each
/// labelled with its value.
fn draw_chi2_bars<DB: DrawingBackend>(
    chart: &mut Chart2d<'_, DB>,
    bars: &[(f64, f64)],
    span: f64,
    color: RGBColor,
) -> DrawResult<DB> {
    let spacing = bars
        .windows(2)
        .map(|p| p[1].0 - p[0].0)
        .fold(span, f64::min);
    let half = 0.3 * spacing;
    chart.draw_series(bars.iter().map(|&(x, v)| {
        Rectangle::new([(x - half, 0.0), (x + half, v)], color.mix(0.55).filled())
    }))?;
    // Inside the bar's top, clear of the line at 1 that most bars reach.
    let label = (FONT, TICK_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    chart.draw_series(bars.iter().map(|&(x, v)| {
        EmptyElement::at((x, v)) + Text::new(format!("{v:.2}"), (0, 14), label.clone())
    }))?;
    Ok(())
}
