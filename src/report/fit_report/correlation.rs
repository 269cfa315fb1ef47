//! Panel (j): the correlation matrix of the fitted parameters (`[fit] correlation`, rows and
//! columns in `free_parameters` order), each cell coloured by ρ on a blue–white–red scale and
//! labelled with its value, the parameter symbols on both axes and a colour bar from −1 to +1.

use super::style::{draw_framed_box, draw_note, DrawResult, CAPTION_SIZE, LEGEND_SIZE, TICK_SIZE};
use super::table::symbol;
use crate::material::FitRecord;
use crate::plot_style::FONT;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

const CAPTION: &str = "(j) Correlation of the fitted parameters";
/// Room for the row labels at the left and the colour bar at the right.
const LABEL_WIDTH: i32 = 60;
const BAR_WIDTH: i32 = 90;

/// Colour of correlation `rho` ∈ [−1, 1]: blue (−1) through white (0) to red (+1).
pub fn correlation_color(rho: f64) -> RGBColor {
    let t = if rho.is_finite() {
        rho.clamp(-1.0, 1.0)
    } else {
        0.0
    };
    let (end, weight) = if t < 0.0 {
        ((33.0, 102.0, 172.0), -t)
    } else {
        ((178.0, 24.0, 43.0), t)
    };
    let mix = |e: f64| (255.0 + weight * (e - 255.0)).round() as u8;
    RGBColor(mix(end.0), mix(end.1), mix(end.2))
}

/// ρ as the cells print it: "+0.84", "−1.00"; a NaN (undetermined) as "?".
pub fn format_rho(rho: f64) -> String {
    if rho.is_finite() {
        format!("{rho:+.2}").replace('-', "−")
    } else {
        "?".to_owned()
    }
}

pub fn draw_correlation<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    fit: Option<&FitRecord>,
) -> DrawResult<DB> {
    let names: Vec<&str> = fit.map_or(Vec::new(), |f| {
        f.free_parameters.iter().map(|n| symbol(n)).collect()
    });
    let Some(fit) = fit.filter(|f| !names.is_empty() && f.correlation.len() >= names.len()) else {
        return draw_note(area, CAPTION, "no correlation matrix recorded");
    };
    let (width, height) = area.dim_in_pixel();
    let text =
        |size: i32, h: HPos, v: VPos| (FONT, size).into_font().color(&BLACK).pos(Pos::new(h, v));
    area.draw_text(
        CAPTION,
        &text(CAPTION_SIZE, HPos::Center, VPos::Top),
        (width as i32 / 2, 12),
    )?;
    let count = names.len() as i32;
    let top = 80;
    let side = (width as i32 - LABEL_WIDTH - BAR_WIDTH - 20)
        .min(height as i32 - top - 30)
        .max(count);
    let cell = side / count;
    let left = LABEL_WIDTH;
    for (i, name) in names.iter().enumerate() {
        let i = i as i32;
        let centre = cell * i + cell / 2;
        area.draw_text(
            name,
            &text(TICK_SIZE + 2, HPos::Center, VPos::Bottom),
            (left + centre, top - 6),
        )?;
        area.draw_text(
            name,
            &text(TICK_SIZE + 2, HPos::Right, VPos::Center),
            (left - 10, top + centre),
        )?;
    }
    for (i, row) in fit.correlation.iter().take(names.len()).enumerate() {
        for (j, &rho) in row.iter().take(names.len()).enumerate() {
            let (x, y) = (left + cell * j as i32, top + cell * i as i32);
            draw_framed_box(
                area,
                [(x, y), (x + cell, y + cell)],
                correlation_color(rho).filled(),
                RGBColor(150, 150, 150),
            )?;
            let ink = if rho.abs() > 0.6 { WHITE } else { BLACK };
            let style = (FONT, LEGEND_SIZE)
                .into_font()
                .color(&ink)
                .pos(Pos::new(HPos::Center, VPos::Center));
            area.draw_text(&format_rho(rho), &style, (x + cell / 2, y + cell / 2))?;
        }
    }
    draw_color_bar(area, (left + side + 24, top), side)
}

/// The vertical colour bar from +1 (top) to −1 (bottom), labelled at −1, 0 and +1.
fn draw_color_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    (x, top): (i32, i32),
    height: i32,
) -> DrawResult<DB> {
    let bar = 18;
    for step in 0..height {
        let rho = 1.0 - 2.0 * step as f64 / (height - 1).max(1) as f64;
        area.draw(&Rectangle::new(
            [(x, top + step), (x + bar, top + step + 1)],
            correlation_color(rho).filled(),
        ))?;
    }
    area.draw(&Rectangle::new(
        [(x, top), (x + bar, top + height)],
        RGBColor(150, 150, 150).stroke_width(1),
    ))?;
    let style = (FONT, TICK_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (label, fraction) in [("+1", 0.0), ("0", 0.5), ("−1", 1.0)] {
        let y = top + (fraction * (height - 1) as f64).round() as i32;
        area.draw_text(label, &style, (x + bar + 6, y))?;
    }
    area.draw_text("ρ", &style, (x + 2, top - 16))
}
