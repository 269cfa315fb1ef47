//! Colours, markers, legends and line clipping shared by the report's panels. Every text uses the
//! embedded font ([`FONT`]) so that the figure renders without system fonts.

use crate::plot_style::FONT;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::element::Drawable;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

pub type DrawResult<DB> = Result<(), DrawingAreaErrorKind<<DB as DrawingBackend>::ErrorType>>;

/// A chart with linear x and y axes, as most panels draw.
pub type Chart2d<'a, DB> = ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>;

/// Font sizes in pixels for the 2400 × 1800 figure. All even: plotters places each glyph at
/// size/2 + its top, truncated, so odd sizes put some letters (the z of "zenith") a pixel high.
pub const TITLE_SIZE: i32 = 30;
pub const CAPTION_SIZE: i32 = 22;
pub const AXIS_DESC_SIZE: i32 = 18;
pub const TICK_SIZE: i32 = 16;
pub const LEGEND_SIZE: i32 = 16;
pub const SMALL_CAPTION_SIZE: i32 = 18;
pub const SMALL_TICK_SIZE: i32 = 14;

/// Colour of incidence angle number `index` (Tableau 10, readable on white and in grey print).
pub fn incidence_color(index: usize) -> RGBColor {
    crate::plot_style::TABLEAU20[index % 10]
}

pub const GREY: RGBColor = RGBColor(110, 110, 110);

/// The shape of a measured point; rings of one incidence angle differ by shape.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Marker {
    FilledCircle,
    FilledTriangle,
    HollowCircle,
    HollowTriangle,
}

impl Marker {
    pub fn for_rank(rank: usize) -> Marker {
        [
            Marker::FilledCircle,
            Marker::FilledTriangle,
            Marker::HollowCircle,
            Marker::HollowTriangle,
        ][rank % 4]
    }

    fn style(self, color: RGBColor) -> ShapeStyle {
        match self {
            Marker::FilledCircle | Marker::FilledTriangle => color.filled(),
            Marker::HollowCircle | Marker::HollowTriangle => color.stroke_width(2),
        }
    }

    /// The marker as a drawable element at `at`: a data coordinate in a chart, or a backend
    /// (pixel) position in a drawing area.
    pub fn at<DB, C>(self, at: C, size: i32, color: RGBColor) -> DynElement<'static, DB, C>
    where
        DB: DrawingBackend,
        C: Clone + 'static,
        Circle<C, i32>: Drawable<DB>,
        TriangleMarker<C, i32>: Drawable<DB>,
    {
        match self {
            Marker::FilledCircle | Marker::HollowCircle => {
                Circle::new(at, size, self.style(color)).into_dyn()
            }
            Marker::FilledTriangle | Marker::HollowTriangle => {
                TriangleMarker::new(at, size + 1, self.style(color)).into_dyn()
            }
        }
    }
}

/// How a legend entry is drawn: a line sample, a marker, or both.
#[derive(Clone, Debug)]
pub struct LegendEntry {
    pub label: String,
    pub color: RGBColor,
    pub line: Option<LineKind>,
    pub marker: Option<Marker>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineKind {
    Solid,
    Dashed,
    /// A filled patch, for bars.
    Patch,
}

impl LegendEntry {
    pub fn line(label: impl Into<String>, color: RGBColor, kind: LineKind) -> LegendEntry {
        LegendEntry {
            label: label.into(),
            color,
            line: Some(kind),
            marker: None,
        }
    }
    pub fn marker(label: impl Into<String>, color: RGBColor, marker: Marker) -> LegendEntry {
        LegendEntry {
            label: label.into(),
            color,
            line: None,
            marker: Some(marker),
        }
    }
    /// A line of text among the entries (a count, a remark): its sample is a white line, which
    /// does not show on the legend's white box.
    pub fn text(label: impl Into<String>) -> LegendEntry {
        LegendEntry::line(label, WHITE, LineKind::Solid)
    }
}

const SAMPLE_WIDTH: i32 = 34;

fn draw_sample<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entry: &LegendEntry,
    x: i32,
    y: i32,
) -> DrawResult<DB> {
    match entry.line {
        Some(LineKind::Solid) => area.draw(&PathElement::new(
            vec![(x, y), (x + SAMPLE_WIDTH, y)],
            entry.color.stroke_width(2),
        ))?,
        Some(LineKind::Dashed) => {
            for start in [0, 13, 26] {
                area.draw(&PathElement::new(
                    vec![(x + start, y), (x + (start + 8).min(SAMPLE_WIDTH), y)],
                    entry.color.stroke_width(2),
                ))?;
            }
        }
        Some(LineKind::Patch) => area.draw(&Rectangle::new(
            [(x + 6, y - 6), (x + SAMPLE_WIDTH - 6, y + 6)],
            entry.color.mix(0.55).filled(),
        ))?,
        None => {}
    }
    if let Some(marker) = entry.marker {
        area.draw(&marker.at((x + SAMPLE_WIDTH / 2, y), 4, entry.color))?;
    }
    Ok(())
}

const LEGEND_ROW: i32 = LEGEND_SIZE + 7;

/// Pixel size of the framed box [`draw_legend_column`] draws for `entries`.
pub fn legend_size<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
) -> Result<(i32, i32), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = (FONT, LEGEND_SIZE).into_font().into_text_style(area);
    let mut text_width = 0;
    for entry in entries {
        text_width = text_width.max(area.estimate_text_size(&entry.label, &font)?.0 as i32);
    }
    Ok((
        SAMPLE_WIDTH + text_width + 22,
        LEGEND_ROW * entries.len() as i32 + 8,
    ))
}

/// Draws `entries` one per row with the top-left corner at `(x, y)` of `area` on a framed white
/// box.
pub fn draw_legend_column<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    (x, y): (i32, i32),
) -> DrawResult<DB> {
    let (width, height) = legend_size(area, entries)?;
    draw_framed_box(
        area,
        [(x, y), (x + width, y + height)],
        WHITE.mix(0.9).filled(),
        RGBColor(170, 170, 170),
    )?;
    let style = (FONT, LEGEND_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    for (i, entry) in entries.iter().enumerate() {
        let cy = y + 4 + LEGEND_ROW * i as i32 + LEGEND_ROW / 2;
        draw_sample(area, entry, x + 6, cy)?;
        area.draw_text(&entry.label, &style, (x + SAMPLE_WIDTH + 14, cy))?;
    }
    Ok(())
}

/// Draws the legend inside the top-right corner of a chart's plotting area.
pub fn draw_legend_top_right<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    plot: (std::ops::Range<i32>, std::ops::Range<i32>),
    entries: &[LegendEntry],
    below_top: i32,
) -> DrawResult<DB> {
    let (width, _) = legend_size(area, entries)?;
    let (base_x, base_y) = area.get_base_pixel();
    let (x, y) = plot;
    draw_legend_column(
        area,
        entries,
        (x.end - base_x - width - 8, y.start - base_y + below_top),
    )
}

/// Draws `entries` in one row starting at `(x, y)` (vertical centre), without a frame.
pub fn draw_legend_row<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
    (mut x, y): (i32, i32),
) -> DrawResult<DB> {
    let font = (FONT, LEGEND_SIZE + 2).into_font();
    let style = font.color(&BLACK).pos(Pos::new(HPos::Left, VPos::Center));
    for entry in entries {
        draw_sample(area, entry, x, y)?;
        area.draw_text(&entry.label, &style, (x + SAMPLE_WIDTH + 8, y))?;
        x += SAMPLE_WIDTH
            + 8
            + area
                .estimate_text_size(&entry.label, &font.clone().into_text_style(area))?
                .0 as i32
            + 26;
    }
    Ok(())
}

/// A chart builder with the report's caption font, 12-pixel margins (`margin_right` at the right)
/// and label areas of 58 pixels under the x axis and 78 beside the y axis: the frame of every
/// single-chart panel.
pub fn panel_chart<'a, 'b, DB: DrawingBackend>(
    area: &'a DrawingArea<DB, Shift>,
    caption: &str,
    margin_right: u32,
) -> ChartBuilder<'a, 'b, DB> {
    let mut builder = ChartBuilder::on(area);
    builder
        .caption(caption, (FONT, CAPTION_SIZE))
        .margin(12)
        .margin_right(margin_right)
        .x_label_area_size(58)
        .y_label_area_size(78);
    builder
}

/// A panel's caption centred at the top of `area`, for panels that are not one chart (which
/// draws its own caption).
pub fn draw_caption<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
) -> DrawResult<DB> {
    let (width, _) = area.dim_in_pixel();
    let style = (FONT, CAPTION_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    area.draw_text(caption, &style, (width as i32 / 2, 12))
}

/// A message in the middle of an empty panel, so a missing quantity is said rather than blank.
pub fn draw_note<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    caption: &str,
    note: &str,
) -> DrawResult<DB> {
    let (w, h) = area.dim_in_pixel();
    let caption_style = (FONT, CAPTION_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Center, VPos::Top));
    area.draw_text(caption, &caption_style, (w as i32 / 2, 8))?;
    let style = (FONT, AXIS_DESC_SIZE)
        .into_font()
        .color(&GREY)
        .pos(Pos::new(HPos::Center, VPos::Center));
    area.draw_text(note, &style, (w as i32 / 2, h as i32 / 2))?;
    area.draw(&Rectangle::new(
        [(20, 45), (w as i32 - 20, h as i32 - 20)],
        RGBColor(200, 200, 200).stroke_width(1),
    ))?;
    Ok(())
}

/// The report's axis look on a mesh: tick and axis-title fonts of `tick` and `desc` points, light
/// and bold grid lines in two greys (one place for every panel's grid).
pub fn report_mesh_style<'m, 'a, 'b, X, Y, DB>(
    mesh: &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>,
    tick: i32,
    desc: i32,
) -> &'m mut plotters::chart::MeshStyle<'a, 'b, X, Y, DB>
where
    X: plotters::coord::ranged1d::Ranged<ValueType: std::fmt::Debug>,
    Y: plotters::coord::ranged1d::Ranged<ValueType: std::fmt::Debug>,
    DB: DrawingBackend,
{
    mesh.label_style((FONT, tick))
        .axis_desc_style((FONT, desc))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(215, 215, 215))
}

/// A rectangle filled with `fill` and outlined one pixel wide in `outline`.
pub fn draw_framed_box<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    corners: [(i32, i32); 2],
    fill: ShapeStyle,
    outline: RGBColor,
) -> DrawResult<DB> {
    area.draw(&Rectangle::new(corners, fill))?;
    area.draw(&Rectangle::new(corners, outline.stroke_width(1)))
}

/// The y axis of a profile panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum YAxis {
    Log { low: f64, high: f64 },
    Linear { low: f64, high: f64 },
}

impl YAxis {
    pub fn bounds(&self) -> (f64, f64) {
        match *self {
            YAxis::Log { low, high } | YAxis::Linear { low, high } => (low, high),
        }
    }
    pub fn contains(&self, y: f64) -> bool {
        let (low, high) = self.bounds();
        y.is_finite() && y >= low && y <= high
    }

    /// The axis' own scale: ln y on a log axis (−∞ for y ≤ 0), y on a linear one.
    fn scaled(&self, y: f64) -> f64 {
        match self {
            YAxis::Log { .. } if y > 0.0 => y.ln(),
            YAxis::Log { .. } => f64::NEG_INFINITY,
            YAxis::Linear { .. } => y,
        }
    }

    /// Splits a polyline into the pieces inside the axis range, ending each piece on the
    /// boundary where it leaves (interpolated in the axis' own scale). Plotters would otherwise
    /// squash out-of-range points onto the frame.
    pub fn clip(&self, line: &[(f64, f64)]) -> Vec<Vec<(f64, f64)>> {
        let (low, high) = self.bounds();
        let (t_low, t_high) = (self.scaled(low), self.scaled(high));
        // Where the segment a→b, one end inside and one outside, meets the boundary.
        let crossing = |a: (f64, f64), b: (f64, f64)| -> (f64, f64) {
            let (ta, tb) = (self.scaled(a.1), self.scaled(b.1));
            let a_inside = self.contains(a.1);
            let outside = if a_inside { tb } else { ta };
            let (edge, t_edge) = if outside > t_high {
                (high, t_high)
            } else {
                (low, t_low)
            };
            let fraction = if ta.is_finite() && tb.is_finite() && ta != tb {
                ((t_edge - ta) / (tb - ta)).clamp(0.0, 1.0)
            } else if a_inside {
                0.0
            } else {
                1.0
            };
            (a.0 + fraction * (b.0 - a.0), edge)
        };
        let mut pieces = Vec::new();
        let mut current: Vec<(f64, f64)> = Vec::new();
        for (i, &p) in line.iter().enumerate() {
            let previous = i.checked_sub(1).map(|j| line[j]);
            match (previous, self.contains(p.1)) {
                (Some(q), true) if !self.contains(q.1) => {
                    current.push(crossing(q, p));
                    current.push(p);
                }
                (_, true) => current.push(p),
                (Some(q), false) if self.contains(q.1) => {
                    current.push(crossing(q, p));
                    pieces.push(std::mem::take(&mut current));
                }
                (_, false) => {}
            }
        }
        if !current.is_empty() {
            pieces.push(current);
        }
        pieces.retain(|piece| piece.len() > 1);
        pieces
    }
}

/// Widest log axis, in decades: a reader cannot use more, and plotters lays out one bold line
/// per decade.
pub const MAX_LOG_DECADES: f64 = 30.0;
/// Ends of any log axis: normal, finite numbers, with room for the 1.5× margins.
const LOG_AXIS_FLOOR: f64 = 1e-300;
const LOG_AXIS_CEILING: f64 = 1e300;

/// A log-axis range that plotters can lay out: finite, positive, normal ends, low < high, at most
/// [`MAX_LOG_DECADES`] decades. Plotters counts the decades into an integer and walks them, so
/// an infinite end (a measured m00 of 1e308 times the 1.5 margin) or a subnormal one (1e-320)
/// made it loop for ever. Data outside the range are left out of the panel as any other
/// out-of-range point; when the range must be cut, its top is kept (a BRDF's peak, the start of
/// a convergence history).
pub fn sane_log_range(low: f64, high: f64) -> (f64, f64) {
    // NaN or ≤ 0 has no place on a log axis: fall back to a unit top.
    let high = if high > 0.0 {
        high.min(LOG_AXIS_CEILING)
    } else {
        1.0
    };
    let high = high.max(LOG_AXIS_FLOOR * 100.0);
    let floor = (high / 10f64.powf(MAX_LOG_DECADES)).max(LOG_AXIS_FLOOR);
    let low = if low > 0.0 && low < high {
        low.max(floor)
    } else {
        // Degenerate (low ≥ high, NaN, ≤ 0): two decades below the top.
        high / 100.0
    };
    (low, high)
}

/// A linear-axis range with finite ends and low < high, else `fallback`.
pub fn sane_linear_range(low: f64, high: f64, fallback: (f64, f64)) -> (f64, f64) {
    if low.is_finite() && high.is_finite() && low < high {
        (low, high)
    } else {
        fallback
    }
}

/// Tick labels of a log axis: decimals from 0.001 to 1000 ("0.01", "10"), else "1e-4".
pub fn log_tick(value: &f64) -> String {
    if (1e-3..1e4).contains(value) {
        let decimals = (-value.log10().floor()).max(0.0) as usize;
        format!("{value:.decimals$}")
    } else {
        format!("{value:.0e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_are_cut_at_the_axis_range_not_squashed_onto_it() {
        let linear = YAxis::Linear {
            low: 0.0,
            high: 1.0,
        };
        let pieces = linear.clip(&[(0.0, 0.5), (1.0, 1.5), (2.0, 2.5), (3.0, 0.5), (4.0, 0.25)]);
        // Leaves at y = 1 halfway to x = 1; re-enters 3/4 of the way from x = 2 (2.5 → 0.5).
        assert_eq!(
            pieces,
            vec![
                vec![(0.0, 0.5), (0.5, 1.0)],
                vec![(2.75, 1.0), (3.0, 0.5), (4.0, 0.25)]
            ]
        );
        // A log axis interpolates geometrically; zero (log −∞) ends a piece at its last point.
        let log = YAxis::Log {
            low: 1e-3,
            high: 1.0,
        };
        let pieces = log.clip(&[
            (0.0, 1e-2),
            (1.0, 1e-4),
            (2.0, 0.0),
            (3.0, 1e-2),
            (4.0, 0.1),
        ]);
        assert_eq!(pieces.len(), 2);
        let (x, y) = pieces[0][1];
        assert!(
            (x - 0.5).abs() < 1e-12 && (y - 1e-3).abs() < 1e-15,
            "{pieces:?}"
        );
        assert_eq!(pieces[1], vec![(3.0, 1e-3), (3.0, 1e-2), (4.0, 0.1)]);
        assert!(log.clip(&[(0.0, 5.0), (1.0, 7.0)]).is_empty());
    }

    #[test]
    fn absurd_log_ranges_fall_back_to_ones_plotters_can_lay_out() {
        let ok = |(low, high): (f64, f64)| {
            low.is_normal()
                && high.is_finite()
                && low > 0.0
                && low < high
                && (high / low).log10() <= MAX_LOG_DECADES + 1e-9
        };
        for (low, high) in [
            (1e-3, f64::INFINITY),
            (1e-320, 1.0),
            (0.0, 0.0),
            (f64::NAN, f64::NAN),
            (5.0, 5.0),
            (2.0, 1.0),
            (1e-300, 1e300),
            (-1.0, 1e-310),
        ] {
            let range = sane_log_range(low, high);
            assert!(ok(range), "({low}, {high}) → {range:?}");
        }
        assert_eq!(
            sane_log_range(1e-3, 10.0),
            (1e-3, 10.0),
            "sane ranges are kept"
        );
        assert_eq!(sane_linear_range(2.0, 1.0, (-1.0, 1.0)), (-1.0, 1.0));
        assert_eq!(sane_linear_range(0.0, 0.5, (-1.0, 1.0)), (0.0, 0.5));
    }

    #[test]
    fn log_ticks_are_decimals_within_reason() {
        let labels: Vec<String> = [1e-4, 1e-3, 0.01, 1.0, 100.0, 1e4]
            .iter()
            .map(log_tick)
            .collect();
        assert_eq!(labels, ["1e-4", "0.001", "0.01", "1", "100", "1e4"]);
    }
}
