//! Panel (c): the directional emissivity ε0 of the fitted model over wavelength and emission angle,
//! as a heat map with a colour bar (docs/design.md §1.4, §1.9).

use super::super::fit_report::style::{
    draw_caption, report_mesh_style, DrawResult, AXIS_DESC_SIZE, TICK_SIZE,
};
use super::super::ReportError;
use crate::material::Material;
use crate::pbrdf::HemisphereQuadrature;
use plotters::coord::Shift;
use plotters::prelude::*;
use rayon::prelude::*;

/// The largest emission angle of the map, degrees (the quadrature is accurate to 1e-5 below 88°).
pub const MAX_ANGLE_DEG: f64 = 85.0;

/// ε0 on a grid of wavelengths and emission angles.
#[derive(Clone, Debug, PartialEq)]
pub struct EmissivityGrid {
    /// Ascending, µm: evenly spread over the table, with every table node among them.
    pub wavelength_um: Vec<f64>,
    /// Ascending, degrees, 0…`MAX_ANGLE_DEG`.
    pub theta_deg: Vec<f64>,
    /// ε0 at `[wavelength][angle]`.
    pub e0: Vec<Vec<f64>>,
}

/// ε0 of `material` (its model at each wavelength, [`Material::at`]) at `wavelengths` points spread
/// evenly over its table, plus the table's nodes, and `angles` emission angles from 0 to 85°.
pub fn emissivity_grid(
    material: &Material,
    wavelengths: usize,
    angles: usize,
) -> Result<EmissivityGrid, ReportError> {
    let nodes = material.model.wavelengths_um();
    let (Some(&first), Some(&last)) = (nodes.first(), nodes.last()) else {
        return Ok(EmissivityGrid {
            wavelength_um: Vec::new(),
            theta_deg: Vec::new(),
            e0: Vec::new(),
        });
    };
    let steps = wavelengths.max(2) - 1;
    let mut wavelength_um: Vec<f64> = (0..=steps)
        .map(|i| first + (last - first) * i as f64 / steps as f64)
        .filter(|w| nodes.iter().all(|n| (n - w).abs() > 1e-9))
        .chain(nodes.iter().copied())
        .collect();
    wavelength_um.sort_by(f64::total_cmp);
    wavelength_um.dedup();
    let rows = angles.max(2) - 1;
    let theta_deg: Vec<f64> = (0..=rows)
        .map(|j| MAX_ANGLE_DEG * j as f64 / rows as f64)
        .collect();
    let radians: Vec<f64> = theta_deg.iter().map(|t| t.to_radians()).collect();
    let quadrature = HemisphereQuadrature::default();
    let e0 = wavelength_um
        .par_iter()
        .map(|&w| {
            let pbrdf = material.at(w)?.pbrdf()?;
            let table = pbrdf.emissivity_table(&radians, &quadrature);
            Ok(table.iter().map(|e| e[0]).collect())
        })
        .collect::<Result<Vec<Vec<f64>>, ReportError>>()?;
    Ok(EmissivityGrid {
        wavelength_um,
        theta_deg,
        e0,
    })
}

/// Viridis (matplotlib's perceptually uniform map) at nine stops, dark purple to yellow.
const VIRIDIS: [(f64, f64, f64); 9] = [
    (68.0, 1.0, 84.0),
    (71.0, 44.0, 122.0),
    (59.0, 81.0, 139.0),
    (44.0, 113.0, 142.0),
    (33.0, 145.0, 140.0),
    (39.0, 173.0, 129.0),
    (92.0, 200.0, 99.0),
    (170.0, 220.0, 50.0),
    (253.0, 231.0, 37.0),
];

/// The colour of `t` ∈ [0, 1] (clamped; NaN is the low end).
pub fn viridis(t: f64) -> RGBColor {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let at = t * (VIRIDIS.len() - 1) as f64;
    let i = (at.floor() as usize).min(VIRIDIS.len() - 2);
    let f = at - i as f64;
    let (a, b) = (VIRIDIS[i], VIRIDIS[i + 1]);
    let mix = |x: f64, y: f64| (x + f * (y - x)).round() as u8;
    RGBColor(mix(a.0, b.0), mix(a.1, b.1), mix(a.2, b.2))
}

/// The colour scale's ends: the grid's ε0 range widened to multiples of 0.05.
fn scale(grid: &EmissivityGrid) -> (f64, f64) {
    let values = grid.e0.iter().flatten().copied().filter(|v| v.is_finite());
    let (low, high) = values.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
        (l.min(v), h.max(v))
    });
    let low = (low / 0.05).floor() * 0.05;
    let high = (high / 0.05).ceil() * 0.05;
    if low.is_finite() && high.is_finite() && low < high {
        (low, high)
    } else {
        (0.0, 1.0)
    }
}

/// Cell edges of ascending `centres`: midway between neighbours, the ends at the first and last.
fn edges(centres: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(centres.len() + 1);
    out.extend(centres.first().copied());
    out.extend(centres.windows(2).map(|p| 0.5 * (p[0] + p[1])));
    out.extend(centres.last().copied());
    out
}

/// Width of the colour bar strip at the right of the panel.
const BAR_STRIP: i32 = 190;
/// Room for the caption above the map and the bar.
const CAPTION_ROOM: i32 = 48;

/// The map, white ticks at the measured wavelengths `nodes`, and its colour bar.
pub fn draw_map<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    grid: &EmissivityGrid,
    nodes: &[f64],
) -> DrawResult<DB> {
    let (width, height) = area.dim_in_pixel();
    draw_caption(
        area,
        "(c) Directional emissivity ε0(λ, θe) of the material (n, k, ρd linear between the measured λ, white ticks)",
    )?;
    let body = area.clone().shrink(
        (0, CAPTION_ROOM),
        (width, height.saturating_sub(CAPTION_ROOM as u32)),
    );
    let (map_area, bar_area) = body.split_horizontally(width as i32 - BAR_STRIP);
    let (low, high) = scale(grid);
    let (Some(&first), Some(&last)) = (grid.wavelength_um.first(), grid.wavelength_um.last())
    else {
        return Ok(());
    };
    let mut chart = ChartBuilder::on(&map_area)
        .margin(12)
        .x_label_area_size(58)
        .y_label_area_size(78)
        .build_cartesian_2d(first..last.max(first + 1e-6), 0.0..MAX_ANGLE_DEG)?;
    let mesh = &mut chart.configure_mesh();
    mesh.disable_mesh()
        .x_labels(14)
        .y_labels(10)
        .x_label_formatter(&|v| format!("{v:.1}"))
        .y_label_formatter(&|v| format!("{v:.0}"))
        .x_desc("wavelength λ (µm)")
        .y_desc("emission angle θe (°)");
    report_mesh_style(mesh, TICK_SIZE, AXIS_DESC_SIZE).draw()?;
    let (x_edges, y_edges) = (edges(&grid.wavelength_um), edges(&grid.theta_deg));
    let cells = grid.e0.iter().enumerate().flat_map(|(i, column)| {
        let (x0, x1) = (x_edges[i], x_edges[i + 1]);
        let y_edges = &y_edges;
        column.iter().enumerate().map(move |(j, &e)| {
            let color = viridis((e - low) / (high - low));
            Rectangle::new([(x0, y_edges[j]), (x1, y_edges[j + 1])], color.filled())
        })
    });
    chart.draw_series(cells)?;
    let tick = MAX_ANGLE_DEG * 0.04;
    chart.draw_series(nodes.iter().map(|&w| {
        PathElement::new(
            vec![(w, MAX_ANGLE_DEG), (w, MAX_ANGLE_DEG - tick)],
            WHITE.stroke_width(3),
        )
    }))?;
    draw_colour_bar(&bar_area, (low, high))
}

/// The colour bar: the scale from `low` to `high` with its ticks, aligned with the map's plot.
fn draw_colour_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (low, high): (f64, f64),
) -> DrawResult<DB> {
    let mut chart = ChartBuilder::on(area)
        .margin(12)
        .margin_left(20)
        .margin_right(40)
        .x_label_area_size(58)
        .y_label_area_size(100)
        .build_cartesian_2d(0.0..1.0, low..high)?;
    let mesh = &mut chart.configure_mesh();
    mesh.disable_mesh()
        .disable_x_axis()
        .y_labels(10)
        .y_label_formatter(&|v| format!("{v:.2}"))
        .y_desc("ε0");
    report_mesh_style(mesh, TICK_SIZE, AXIS_DESC_SIZE).draw()?;
    const STEPS: usize = 120;
    chart.draw_series((0..STEPS).map(|i| {
        let (a, b) = (i as f64 / STEPS as f64, (i + 1) as f64 / STEPS as f64);
        let y = |t: f64| low + t * (high - low);
        Rectangle::new([(0.0, y(a)), (1.0, y(b))], viridis(0.5 * (a + b)).filled())
    }))?;
    chart.draw_series(std::iter::once(Rectangle::new(
        [(0.0, low), (1.0, high)],
        RGBColor(120, 120, 120).stroke_width(1),
    )))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::{MaterialModel, SpectralModel};
    use crate::pbrdf::{Shadowing, SlopeDistribution};

    fn glass() -> Material {
        Material {
            name: "glass".into(),
            tool_version: String::new(),
            model: MaterialModel::Spectral(SpectralModel {
                distribution: SlopeDistribution::Cauchy {
                    sigma: 0.06,
                    q: 2.8,
                },
                shadowing: Shadowing::Smith,
                wavelength_um: vec![8.0, 9.0, 11.5],
                n: vec![0.5, 1.4, 2.1],
                k: vec![0.5, 2.1, 0.1],
                rho_d: vec![0.0, 0.01, 0.02],
                volume: Default::default(),
                dispersion: None,
            }),
            fit: None,
        }
    }

    #[test]
    fn the_grid_holds_the_nodes_and_the_models_own_emissivity() {
        let material = glass();
        let grid = emissivity_grid(&material, 6, 5).unwrap();
        // 6 even points, 0.7 µm apart (8 and 11.5 among them), plus the node at 9.
        assert_eq!(grid.wavelength_um.len(), 7);
        assert!(grid.wavelength_um.windows(2).all(|p| p[0] < p[1]));
        assert_eq!(grid.theta_deg, [0.0, 21.25, 42.5, 63.75, 85.0]);
        let column = grid.wavelength_um.iter().position(|&w| w == 9.0).unwrap();
        let pbrdf = material.at(9.0).unwrap().pbrdf().unwrap();
        let e = pbrdf.emissivity(42.5f64.to_radians(), &HemisphereQuadrature::default());
        assert!((grid.e0[column][2] - e[0]).abs() < 1e-12);
    }

    #[test]
    fn colours_run_from_purple_to_yellow_and_cells_tile_the_range() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), viridis(-3.0));
        assert_eq!(edges(&[1.0, 2.0, 4.0]), [1.0, 1.5, 3.0, 4.0]);
    }
}
