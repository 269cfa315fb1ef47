//! The temperature plot of a thermal run: every part's surface temperature over time (mean line,
//! min–max band over its vertices), the air temperature dashed, sunrise and sunset marked.

use crate::plot_style::{encode_png, register_fonts, FONT, TABLEAU20};
use crate::scene::Scene;
use crate::thermal_scene::{PartSeries, ThermalSolution};
use plotters::prelude::*;
use std::io;

const WIDTH: u32 = 1400;
const HEIGHT: u32 = 800;

/// Part `i`'s colour and dash pattern (dash and gap in pixels; `None` solid): the ten Tableau 10
/// colours solid, then dashed, then dotted, so 30 parts are told apart (Tableau 20's light
/// colours read as their dark companions, so the car's 17 parts seemed to repeat colours).
fn part_style(i: usize) -> (RGBColor, Option<(u32, u32)>) {
    let color = TABLEAU20[i % 10];
    let dash = [None, Some((12, 6)), Some((3, 4))][(i / 10) % 3];
    (color, dash)
}

/// Times (h) where the sun's centre crosses the horizon, linear between recorded instants, with
/// whether it rises there.
pub fn horizon_crossings(solution: &ThermalSolution) -> Vec<(f64, bool)> {
    let z: Vec<f64> = solution.weather.iter().map(|w| w.sun_direction.z).collect();
    let t = &solution.times_s;
    (1..z.len())
        .filter(|&i| (z[i - 1] > 0.0) != (z[i] > 0.0))
        .map(|i| {
            let s = z[i - 1] / (z[i - 1] - z[i]);
            ((t[i - 1] + s * (t[i] - t[i - 1])) / 3600.0, z[i] > 0.0)
        })
        .collect()
}

/// The plot as PNG bytes.
pub fn temperature_plot_png(
    scene: &Scene,
    solution: &ThermalSolution,
    parts: &[PartSeries],
) -> io::Result<Vec<u8>> {
    let mut rgb = vec![0u8; (WIDTH * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (WIDTH, HEIGHT)).into_drawing_area();
        draw(&root, scene, solution, parts).map_err(|e| io::Error::other(e.to_string()))?;
    }
    encode_png(&rgb, WIDTH, HEIGHT).map_err(io::Error::other)
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, plotters::coord::Shift>,
    scene: &Scene,
    solution: &ThermalSolution,
    parts: &[PartSeries],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    register_fonts();
    root.fill(&WHITE)?;
    let hours: Vec<f64> = solution.times_s.iter().map(|t| t / 3600.0).collect();
    let air: Vec<f64> = solution.weather.iter().map(|w| w.air_k).collect();
    let all = parts
        .iter()
        .flat_map(|p| p.surface_k.iter().flat_map(|v| [v[0], v[2]]))
        .chain(air.iter().copied());
    let (lo, hi) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
        (a.min(v), b.max(v))
    });
    let pad = ((hi - lo) * 0.05).max(0.5);
    let end = hours.last().copied().unwrap_or(1.0).max(1e-3);
    let (plot, legend) = root.split_horizontally(WIDTH - 260);
    let title = format!("Surface temperatures: {}", scene.path.display());
    let mut chart = ChartBuilder::on(&plot)
        .caption(title, (FONT, 22))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(0.0..end, (lo - pad)..(hi + pad))?;
    chart
        .configure_mesh()
        .x_desc("time from start_utc (h)")
        .y_desc("surface temperature (K)")
        .label_style((FONT, 16))
        .axis_desc_style((FONT, 18))
        .draw()?;
    for (hour, rises) in horizon_crossings(solution) {
        let color = if rises {
            RGBColor(230, 160, 0)
        } else {
            RGBColor(90, 90, 160)
        };
        chart.draw_series(LineSeries::new(
            [(hour, lo - pad), (hour, hi + pad)],
            color.stroke_width(1),
        ))?;
        let label = if rises { "sunrise" } else { "sunset" };
        chart.draw_series([Text::new(label, (hour, hi + pad * 0.5), (FONT, 14))])?;
    }
    for (i, part) in parts.iter().enumerate() {
        let (color, dash) = part_style(i);
        let band: Vec<(f64, f64)> = hours
            .iter()
            .zip(&part.surface_k)
            .map(|(&h, v)| (h, v[2]))
            .chain(
                hours
                    .iter()
                    .zip(&part.surface_k)
                    .rev()
                    .map(|(&h, v)| (h, v[0])),
            )
            .collect();
        chart.draw_series([Polygon::new(band, color.mix(0.15).filled())])?;
        let mean = hours.iter().zip(&part.surface_k).map(|(&h, v)| (h, v[1]));
        match dash {
            None => chart.draw_series(LineSeries::new(mean, color.stroke_width(2)))?,
            Some((size, gap)) => chart.draw_series(DashedLineSeries::new(
                mean,
                size,
                gap,
                color.stroke_width(2),
            ))?,
        };
    }
    let dashes = DashedLineSeries::new(hours.iter().copied().zip(air), 8, 5, BLACK.stroke_width(2));
    chart.draw_series(dashes)?;
    draw_legend(&legend, parts)?;
    root.present()
}

/// Part names with their colours, and the air line, in a column beside the plot.
fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    parts: &[PartSeries],
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let style = (FONT, 15).into_font().color(&BLACK);
    let row = 22;
    let mut y = 60;
    area.draw(&Text::new(
        "mean (line), min–max (band)",
        (8, y - 30),
        style.clone(),
    ))?;
    for (i, part) in parts.iter().enumerate() {
        let (color, dash) = part_style(i);
        let (size, gap) = dash.map_or((28, 0), |(d, g)| (d as i32, g as i32));
        legend_line(area, y + 8, (size, gap), color.stroke_width(3))?;
        area.draw(&Text::new(part.name.clone(), (44, y), style.clone()))?;
        y += row;
    }
    // The air's dashes as the plot draws them (8 on, 5 off).
    legend_line(area, y + 8, (8, 5), BLACK.stroke_width(2))?;
    area.draw(&Text::new("air (dashed)", (44, y), style))?;
    Ok(())
}

/// A legend's sample line from x = 8 to 36 at height `y`: dashes of `size` pixels `gap` apart
/// (solid when `gap` is 0).
fn legend_line<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    y: i32,
    (size, gap): (i32, i32),
    style: ShapeStyle,
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let mut x = 8;
    while x < 36 {
        let end = (x + size).min(36);
        area.draw(&PathElement::new(vec![(x, y), (end, y)], style))?;
        x = end + gap;
    }
    Ok(())
}
