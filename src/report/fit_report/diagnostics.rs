//! The fit's diagnostic panels: the histogram of the normalized residuals (the residuals
//! themselves are [`super::residuals`]), the optimizer's convergence, and the polarized emissivity the fit implies (docs/design.md §1.4).

use super::data::{EmissivityCurves, ReportData, ResidualSummary, BIN_WIDTH, HISTOGRAM_LIMIT};
use super::style::{
    draw_legend_column, draw_legend_top_right, draw_note, log_tick, panel_chart, report_mesh_style,
    sane_log_range, DrawResult, LegendEntry, LineKind, AXIS_DESC_SIZE, GREY, LEGEND_SIZE,
    TICK_SIZE,
};
use crate::material::FitRecord;
use crate::plot_style::FONT;
use plotters::coord::combinators::LogCoord;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub(super) type Area<DB> = DrawingArea<DB, Shift>;

/// Histogram of the normalized residuals against the standard normal they should follow.
pub fn draw_histogram<DB: DrawingBackend>(area: &Area<DB>, data: &ReportData) -> DrawResult<DB> {
    let caption = "(h) Residual distribution";
    let residuals = &data.residuals;
    let count = residuals.finite;
    if count == 0 {
        return draw_note(area, caption, "no residuals");
    }
    let counts = &residuals.histogram.counts;
    let n = count as f64;
    let top = counts.iter().copied().max().unwrap_or(0) as f64;
    // At least a few counts high, so that the integer tick labels stay distinct.
    let high = (top.max(expected_count(n, 0.0)) * 1.3).max(5.0);
    let mut chart = panel_chart(area, caption, 22)
        .build_cartesian_2d(-HISTOGRAM_LIMIT..HISTOGRAM_LIMIT, 0.0..high)?;
    chart
        .configure_mesh()
        .x_labels(11)
        .y_labels(6)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("(data − model)/σ")
        .y_desc(format!("count per {BIN_WIDTH}σ bin"))
        .label_style((FONT, TICK_SIZE))
        .axis_desc_style((FONT, AXIS_DESC_SIZE))
        .light_line_style(RGBColor(240, 240, 240))
        .bold_line_style(RGBColor(220, 220, 220))
        .draw()?;
    chart.draw_series(counts.iter().enumerate().map(|(i, &count)| {
        let x0 = -HISTOGRAM_LIMIT + i as f64 * BIN_WIDTH;
        Rectangle::new(
            [(x0, 0.0), (x0 + BIN_WIDTH, count as f64)],
            HISTOGRAM_BAR.mix(0.55).filled(),
        )
    }))?;
    let curve: Vec<(f64, f64)> = (0..=200)
        .map(|i| {
            let x = -HISTOGRAM_LIMIT + i as f64 * 0.05;
            (x, expected_count(n, x))
        })
        .collect();
    chart.draw_series(LineSeries::new(curve, BLACK.stroke_width(2)))?;
    let (x, y) = chart.plotting_area().get_pixel_range();
    draw_legend_column(
        area,
        &histogram_legend(residuals),
        (
            x.start - area.get_base_pixel().0 + 8,
            y.start - area.get_base_pixel().1 + 6,
        ),
    )?;
    Ok(())
}

/// Colour of the histogram's bars.
const HISTOGRAM_BAR: RGBColor = RGBColor(31, 119, 180);

/// Residuals of `n` expected in the bin at `x` if they follow the standard normal.
fn expected_count(n: f64, x: f64) -> f64 {
    n * BIN_WIDTH * (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt()
}

/// The histogram's key: the bars, the normal curve, the finite residuals' mean and standard
/// deviation, and how many fell outside the bins.
fn histogram_legend(residuals: &ResidualSummary) -> Vec<LegendEntry> {
    let (count, outside) = (residuals.finite, residuals.histogram.outside);
    // Printed to two decimals: keep a tiny negative mean from showing as "-0.00".
    let mean = if residuals.mean.abs() < 0.005 {
        0.0
    } else {
        residuals.mean
    };
    let sd = residuals.standard_deviation;
    let mut entries = vec![
        LegendEntry::line(
            format!("residuals, N = {count}"),
            HISTOGRAM_BAR,
            LineKind::Patch,
        ),
        LegendEntry::line("N(0, 1) expected", BLACK, LineKind::Solid),
        LegendEntry::text(format!("mean {mean:+.2}, s.d. {sd:.2}")),
    ];
    if outside > 0 {
        entries.push(LegendEntry::text(format!(
            "{outside} beyond ±{HISTOGRAM_LIMIT:.0}σ"
        )));
    }
    entries
}

type LogChart<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, LogCoord<f64>>>;

/// Best cost per GA generation, then per local-stage iteration, on a log axis.
pub fn draw_convergence<DB: DrawingBackend>(
    area: &Area<DB>,
    fit: Option<&FitRecord>,
) -> DrawResult<DB> {
    let caption = "(i) Optimizer convergence";
    let Some(fit) = fit else {
        return draw_note(area, caption, "no fit record");
    };
    let costs: Vec<(f64, f64)> = fit
        .convergence
        .iter()
        .enumerate()
        .filter(|(_, c)| c.is_finite() && **c > 0.0)
        .map(|(i, &c)| (i as f64, c))
        .collect();
    if costs.len() < 2 {
        return draw_note(area, caption, "no convergence history recorded");
    }
    let global = fit.global_iterations.min(fit.convergence.len());
    let dof = fit.degrees_of_freedom as f64;
    let low = costs.iter().map(|c| c.1).fold(f64::INFINITY, f64::min);
    let high = costs.iter().map(|c| c.1).fold(0.0, f64::max);
    // χ² ≈ degrees of freedom marks a fit at the noise level; a robust cost Σρ(r) has no such mark.
    let robust = super::table::robust_loss(fit);
    let show_dof = robust.is_none() && dof > 0.0 && dof > low / 100.0;
    let (low, high) = sane_log_range(low.min(if show_dof { dof } else { low }) / 1.6, high * 1.6);
    let last = (fit.convergence.len() - 1) as f64;
    let mut chart = panel_chart(area, caption, 22)
        .build_cartesian_2d(0.0..last.max(1.0), (low..high).log_scale())?;
    let mesh = &mut chart.configure_mesh();
    mesh.x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&log_tick)
        .x_desc("step: GA generation, then local-stage iteration")
        .y_desc(match robust {
            Some(loss) => format!("best cost Σρ(r), {loss} loss, r = (data − model)/σ"),
            None => "best cost χ² = Σ ((data − model)/σ)²".to_owned(),
        });
    report_mesh_style(mesh, TICK_SIZE, AXIS_DESC_SIZE).draw()?;
    let mut entries = draw_stages(&mut chart, &costs, global)?;
    if global > 0 && global < fit.convergence.len() {
        draw_polish_start(area, &mut chart, global as f64 - 0.5, (low, high))?;
    }
    if show_dof {
        chart.draw_series(DashedLineSeries::new(
            [(0.0, dof), (last, dof)],
            3,
            4,
            GREY.stroke_width(1),
        ))?;
        entries.push(LegendEntry::line(
            format!("degrees of freedom {dof:.0} (χ²red = 1)"),
            GREY,
            LineKind::Dashed,
        ));
    }
    entries.push(LegendEntry::text(format!(
        "final {} = {}",
        if robust.is_some() { "cost" } else { "χ²" },
        super::table::format_plain(fit.cost)
    )));
    draw_legend_top_right(area, chart.plotting_area().get_pixel_range(), &entries, 40)
}

/// The best costs of the global stage (the first `global` steps) and of the local stage, one
/// line each; returns their legend entries.
fn draw_stages<DB: DrawingBackend>(
    chart: &mut LogChart<'_, DB>,
    costs: &[(f64, f64)],
    global: usize,
) -> Result<Vec<LegendEntry>, DrawingAreaErrorKind<DB::ErrorType>> {
    let global_color = RGBColor(31, 119, 180);
    let local_color = RGBColor(214, 39, 40);
    let split = global.min(costs.len());
    let (global_costs, local_costs) = costs.split_at(split);
    let mut entries = Vec::new();
    if !global_costs.is_empty() {
        chart.draw_series(LineSeries::new(
            global_costs.to_vec(),
            global_color.stroke_width(2),
        ))?;
        entries.push(LegendEntry::line(
            format!("global stage ({} generations)", global_costs.len()),
            global_color,
            LineKind::Solid,
        ));
    }
    if !local_costs.is_empty() {
        // Start the local line at the global stage's last best so that the two connect.
        let local: Vec<(f64, f64)> = global_costs
            .last()
            .into_iter()
            .chain(local_costs)
            .copied()
            .collect();
        chart.draw_series(LineSeries::new(local, local_color.stroke_width(2)))?;
        entries.push(LegendEntry::line(
            format!("local stage ({} iterations)", local_costs.len()),
            local_color,
            LineKind::Solid,
        ));
    }
    Ok(entries)
}

/// A dashed vertical line at step `x` where the local stage takes over, labelled at its top.
fn draw_polish_start<DB: DrawingBackend>(
    area: &Area<DB>,
    chart: &mut LogChart<'_, DB>,
    x: f64,
    (low, high): (f64, f64),
) -> DrawResult<DB> {
    chart.draw_series(DashedLineSeries::new(
        [(x, low), (x, high)],
        6,
        5,
        BLACK.stroke_width(1),
    ))?;
    let at = chart.backend_coord(&(x, high));
    let base = area.get_base_pixel();
    area.draw_text(
        "polish starts",
        &(FONT, LEGEND_SIZE)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Right, VPos::Top)),
        (at.0 - base.0 - 6, at.1 - base.1 + 6),
    )
}

/// Colour of −ε1 and its right axis in panel (f).
const E1_COLOR: RGBColor = RGBColor(214, 39, 40);

/// ε0 (left axis) and −ε1 (right axis) against emission angle for both models.
pub fn draw_emissivity<DB: DrawingBackend>(area: &Area<DB>, data: &ReportData) -> DrawResult<DB> {
    let caption = "(f) Polarized emissivity implied by the fit";
    let (e0, e1) = emissivity_lines(&data.emissivity);
    let e0_low = e0.iter().flatten().map(|p| p.1).fold(1.0, f64::min);
    let e1_high = e1.iter().flatten().map(|p| p.1).fold(0.0, f64::max);
    let e0_range = floor_to((e0_low - 0.05).min(0.9), 0.05)..1.0;
    let e1_range = 0.0..(e1_high * 1.15).max(0.01);
    let mut chart = panel_chart(area, caption, 12)
        .right_y_label_area_size(78)
        .build_cartesian_2d(0.0..90.0, e0_range.clone())?
        .set_secondary_coord(0.0..90.0, e1_range);
    let mesh = &mut chart.configure_mesh();
    mesh.x_labels(10)
        .y_labels(8)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.2}"))
        .x_desc("emission angle θe (°)")
        .y_desc("ε0 (black, left axis)");
    report_mesh_style(mesh, TICK_SIZE, AXIS_DESC_SIZE).draw()?;
    chart
        .configure_secondary_axes()
        .y_labels(8)
        .y_label_formatter(&|v| format!("{v:.3}"))
        .y_desc("−ε1 (red, right axis)")
        .label_style((FONT, TICK_SIZE).into_font().color(&E1_COLOR))
        .axis_desc_style((FONT, AXIS_DESC_SIZE).into_font().color(&E1_COLOR))
        .draw()?;
    // The chosen model solid, the competing one dashed; ε0 only within its axis.
    for (i, line) in e0.into_iter().enumerate() {
        let inside: Vec<(f64, f64)> = line
            .into_iter()
            .filter(|p| e0_range.contains(&p.1))
            .collect();
        if i == 0 {
            chart.draw_series(LineSeries::new(inside, BLACK.stroke_width(2)))?;
        } else {
            chart.draw_series(DashedLineSeries::new(inside, 7, 5, BLACK.stroke_width(2)))?;
        }
    }
    for (i, line) in e1.into_iter().enumerate() {
        if i == 0 {
            chart.draw_secondary_series(LineSeries::new(line, E1_COLOR.stroke_width(2)))?;
        } else {
            chart.draw_secondary_series(DashedLineSeries::new(
                line,
                7,
                5,
                E1_COLOR.stroke_width(2),
            ))?;
        }
    }
    let (x, y) = chart.plotting_area().get_pixel_range();
    let base = area.get_base_pixel();
    draw_legend_column(
        area,
        &emissivity_legend(data, e0_low),
        (x.start - base.0 + 8, y.end - base.1 - 150),
    )?;
    Ok(())
}

/// Lines of (θe, ε0) and of (θe, −ε1), the chosen model's first, then the competing one's.
type EmissivityLines = (Vec<Vec<(f64, f64)>>, Vec<Vec<(f64, f64)>>);

/// ε0 and −ε1 of each model against emission angle.
fn emissivity_lines(curves: &EmissivityCurves) -> EmissivityLines {
    let series = |values: &[crate::optics::Stokes], j: usize, sign: f64| -> Vec<(f64, f64)> {
        curves
            .theta_deg
            .iter()
            .zip(values)
            .map(|(&t, e)| (t, sign * e[j]))
            .collect()
    };
    let mut e0 = vec![series(&curves.chosen, 0, 1.0)];
    let mut e1 = vec![series(&curves.chosen, 1, -1.0)];
    if let Some(alt) = &curves.alternative {
        e0.push(series(alt, 0, 1.0));
        e1.push(series(alt, 1, -1.0));
    }
    (e0, e1)
}

/// The emissivity panel's key: ε0 and −ε1 of each model, and a warning when ε0 goes negative
/// (lowest value `e0_low`).
fn emissivity_legend(data: &ReportData, e0_low: f64) -> Vec<LegendEntry> {
    let mut entries = vec![
        LegendEntry::line(format!("ε0, {}", data.chosen_label), BLACK, LineKind::Solid),
        LegendEntry::line(
            format!("−ε1, {}", data.chosen_label),
            E1_COLOR,
            LineKind::Solid,
        ),
    ];
    if let Some(alt) = &data.alternative_label {
        entries.push(LegendEntry::line(
            format!("ε0, {alt}"),
            BLACK,
            LineKind::Dashed,
        ));
        entries.push(LegendEntry::line(
            format!("−ε1, {alt}"),
            E1_COLOR,
            LineKind::Dashed,
        ));
    }
    if e0_low < 0.0 {
        entries.push(LegendEntry::line(
            "ε0 < 0: reflectance > 1 (not energy conserving)",
            E1_COLOR,
            LineKind::Dashed,
        ));
    }
    entries
}

/// `value` rounded down to a multiple of `step`.
fn floor_to(value: f64, step: f64) -> f64 {
    (value / step).floor() * step
}
