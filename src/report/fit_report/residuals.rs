//! Panel (g): the normalized residuals (data − model)/σ of every measured element against the
//! signed detector zenith, coloured by the kind of element, as points or, when there are too many,
//! as a density histogram.

use super::data::{ReportData, Residual, ResidualDensity, DENSITY_X_DEG, DENSITY_Y_SIGMA};
use super::diagnostics::Area;
use super::style::{
    draw_legend_top_right, draw_note, panel_chart, report_mesh_style, Chart2d, DrawResult,
    LegendEntry, LineKind, Marker, AXIS_DESC_SIZE, GREY, TICK_SIZE,
};
use plotters::prelude::*;

/// Residual colours by the kind of Mueller element.
const M00_COLOR: RGBColor = RGBColor(20, 20, 20);
const LINEAR_COLOR: RGBColor = RGBColor(230, 97, 1);
const CIRCULAR_COLOR: RGBColor = RGBColor(94, 60, 153);

/// The element classes of the residual panel: m00; the linear block (rows and columns 0–2);
/// the circular row and column (index 3).
fn element_class(element: usize) -> usize {
    match (element / 4, element % 4) {
        (0, 0) => 0,
        (r, c) if r < 3 && c < 3 => 1,
        _ => 2,
    }
}

const CLASS_NAMES: [&str; 3] = ["m00", "m01…m22 (linear)", "m03…m33 (circular)"];
const CLASS_COLORS: [RGBColor; 3] = [M00_COLOR, LINEAR_COLOR, CIRCULAR_COLOR];

/// (data − model)/σ of every measured element against the signed detector zenith.
/// With `raster` (a vector figure), more than [`RASTER_SCATTER_POINTS`] residuals are drawn as
/// one embedded image rather than one element each.
pub fn draw_residuals<DB: DrawingBackend>(
    area: &Area<DB>,
    data: &ReportData,
    raster: bool,
) -> DrawResult<DB> {
    let caption = "(g) Normalized residuals (data − model)/σ, chosen model";
    let residuals = &data.residuals;
    if residuals.count == 0 {
        return draw_note(area, caption, "no residuals");
    }
    let (bound, hidden) = (residuals.bound, residuals.hidden);
    let mut chart =
        panel_chart(area, caption, 22).build_cartesian_2d(-90.0..90.0, -bound..bound)?;
    residual_mesh(&mut chart)?;
    draw_residual_guides(&mut chart)?;
    if let Some(density) = &residuals.density {
        return draw_residual_density(area, &mut chart, density, residuals.count, bound, hidden);
    }
    if raster && residuals.count > RASTER_SCATTER_POINTS {
        draw_scatter_as_image(area, &chart, data, bound)?;
    } else {
        draw_residual_scatter(&mut chart, data, bound)?;
    }
    let mut entries: Vec<LegendEntry> = (0..3)
        .filter(|&class| {
            residuals
                .each
                .iter()
                .any(|r| element_class(r.element) == class)
        })
        .map(|class| {
            LegendEntry::marker(
                CLASS_NAMES[class],
                CLASS_COLORS[class],
                Marker::FilledCircle,
            )
        })
        .collect();
    entries.push(LegendEntry::line("±3σ", GREY, LineKind::Dashed));
    residual_legend(
        area,
        chart.plotting_area().get_pixel_range(),
        entries,
        hidden,
        bound,
    )
}

/// Most residuals a vector figure's panel (g) draws as elements; beyond it, the scatter (with its
/// grid and guides) is one embedded PNG: 10⁴ SVG circles cost ~1 MB, the image ~0.1 MB.
pub const RASTER_SCATTER_POINTS: usize = 2_000;

/// The residuals within ±`bound` as dots, the polarization classes first so that m00 stays
/// visible on top.
fn draw_residual_scatter<DB: DrawingBackend>(
    chart: &mut Chart2d<'_, DB>,
    data: &ReportData,
    bound: f64,
) -> DrawResult<DB> {
    for class in [2, 1, 0] {
        let points: Vec<&Residual> = data
            .residuals
            .each
            .iter()
            .filter(|r| element_class(r.element) == class && r.value.abs() <= bound)
            .collect();
        let color = CLASS_COLORS[class].mix(if class == 0 { 0.8 } else { 0.45 });
        chart.draw_series(
            points
                .iter()
                .map(|r| Circle::new((r.forward_zenith, r.value), 2, color.filled())),
        )?;
    }
    Ok(())
}

/// The plotting area of `chart` redrawn in a bitmap (white, grid, guides, the residual dots) and
/// placed over it as one image.
fn draw_scatter_as_image<DB: DrawingBackend>(
    area: &Area<DB>,
    chart: &Chart2d<'_, DB>,
    data: &ReportData,
    bound: f64,
) -> DrawResult<DB> {
    let (x, y) = chart.plotting_area().get_pixel_range();
    let (base_x, base_y) = area.get_base_pixel();
    let size = ((x.end - x.start) as u32, (y.end - y.start) as u32);
    let mut image = BitMapElement::<(i32, i32)>::new((x.start - base_x, y.start - base_y), size);
    // A bitmap in memory cannot fail to draw; its error type is not the figure's.
    let in_bitmap = |_| DrawingAreaErrorKind::LayoutError;
    {
        let root = image.as_bitmap_backend().into_drawing_area();
        root.fill(&WHITE).map_err(in_bitmap)?;
        let mut inner = ChartBuilder::on(&root)
            .build_cartesian_2d(-90.0..90.0, -bound..bound)
            .map_err(in_bitmap)?;
        residual_mesh(&mut inner).map_err(in_bitmap)?;
        draw_residual_guides(&mut inner).map_err(in_bitmap)?;
        draw_residual_scatter(&mut inner, data, bound).map_err(in_bitmap)?;
    }
    area.draw(&image)
}

/// Cell colour for `count` of at most `most`: light to dark blue on a log scale.
fn density_color(count: usize, most: usize) -> RGBColor {
    let t = if most > 1 {
        (count as f64).ln() / (most as f64).ln()
    } else {
        1.0
    };
    let mix = |a: u8, b: u8| (a as f64 + t * (b as f64 - a as f64)).round() as u8;
    RGBColor(mix(198, 8), mix(219, 48), mix(239, 107))
}

/// A residual panel's legend: `entries`, then a note of the points beyond ±`bound` σ, if any.
fn residual_legend<DB: DrawingBackend>(
    area: &Area<DB>,
    plot: (std::ops::Range<i32>, std::ops::Range<i32>),
    mut entries: Vec<LegendEntry>,
    hidden: usize,
    bound: f64,
) -> DrawResult<DB> {
    if hidden > 0 {
        entries.push(LegendEntry::text(format!(
            "{hidden} beyond ±{bound:.0}σ not shown"
        )));
    }
    draw_legend_top_right(area, plot, &entries, 8)
}

/// The grid, ticks and axis titles of the residual panel (only the grid in a chart without
/// label areas, as the bitmap of [`draw_scatter_as_image`]).
fn residual_mesh<DB: DrawingBackend>(chart: &mut Chart2d<'_, DB>) -> DrawResult<DB> {
    let mesh = &mut chart.configure_mesh();
    mesh.x_labels(13)
        .y_labels(9)
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("detector zenith θr (°): + forward (specular) half, − backward half")
        .y_desc("(data − model)/σ");
    report_mesh_style(mesh, TICK_SIZE, AXIS_DESC_SIZE).draw()
}

/// The zero line and the ±3σ guides of a residual panel (θ_r from −90° to 90°).
fn draw_residual_guides<DB: DrawingBackend>(chart: &mut Chart2d<'_, DB>) -> DrawResult<DB> {
    chart.draw_series(LineSeries::new(
        [(-90.0, 0.0), (90.0, 0.0)],
        GREY.stroke_width(1),
    ))?;
    for level in [-3.0, 3.0] {
        chart.draw_series(DashedLineSeries::new(
            [(-90.0, level), (90.0, level)],
            6,
            5,
            GREY.stroke_width(1),
        ))?;
    }
    Ok(())
}

/// Panel (g) for many residuals (`count`): their density over (detector zenith, residual).
fn draw_residual_density<DB: DrawingBackend>(
    area: &Area<DB>,
    chart: &mut Chart2d<'_, DB>,
    density: &ResidualDensity,
    count: usize,
    bound: f64,
    hidden: usize,
) -> DrawResult<DB> {
    let (counts, rows) = (&density.counts, density.rows);
    let most = counts.iter().copied().max().unwrap_or(0);
    chart.draw_series(counts.iter().enumerate().filter(|(_, &c)| c > 0).map(
        |(cell, &count)| {
            let (column, row) = (cell / rows, cell % rows);
            let x0 = -90.0 + column as f64 * DENSITY_X_DEG;
            let y0 = -bound + row as f64 * DENSITY_Y_SIGMA;
            let top = (y0 + DENSITY_Y_SIGMA).min(bound);
            Rectangle::new(
                [(x0, y0), (x0 + DENSITY_X_DEG, top)],
                density_color(count, most).filled(),
            )
        },
    ))?;
    draw_residual_guides(chart)?;
    let entries = vec![
        LegendEntry::line(
            format!(
                "{count} residuals, all elements: count per {DENSITY_X_DEG}° × {DENSITY_Y_SIGMA}σ cell"
            ),
            density_color(1, most.max(2)),
            LineKind::Patch,
        ),
        LegendEntry::line(
            format!("darkest: {most} (log scale)"),
            density_color(most, most),
            LineKind::Patch,
        ),
        LegendEntry::line("±3σ", GREY, LineKind::Dashed),
    ];
    residual_legend(
        area,
        chart.plotting_area().get_pixel_range(),
        entries,
        hidden,
        bound,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn element_classes_split_intensity_linear_and_circular() {
        let classes: Vec<usize> = (0..16).map(element_class).collect();
        assert_eq!(classes, [0, 1, 1, 2, 1, 1, 1, 2, 1, 1, 1, 2, 2, 2, 2, 2]);
    }
}
