//! The data-versus-model panels of the report: (a) m00 in the plane of incidence, (b) m00 on
//! the out-of-plane rings with their key, (d) the linear-polarization block normalized by m00 and
//! (e) the DoLP for unpolarized illumination.

use super::data::ReportData;
use super::profiles::{
    self, draw_profile, linear_axis, log_axis, profile_series, Domain, Profile, Quantity,
    BIN_DEGREES,
};
use super::style::{
    self, draw_caption, draw_legend_column, draw_note, incidence_color, DrawResult, LegendEntry,
    Marker, YAxis,
};
use super::table::format_angle;
use crate::plot_style::FONT;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// The linear-polarization elements of panel (d), in reading order.
const LINEAR_BLOCK: [usize; 8] = [1, 2, 4, 5, 6, 8, 9, 10];

/// Elements that vanish in the plane of incidence by mirror symmetry (m02, m12, m20, m21): drawn
/// on the rings, where they carry information.
const ZERO_IN_PLANE: [usize; 4] = [2, 6, 8, 9];

/// Panel (a): m00 against the signed detector zenith in the plane of incidence.
pub(super) fn draw_in_plane_m00<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let caption = "(a) m00 in the plane of incidence";
    let (series, binned) = profile_series(data, Quantity::M00, Domain::InPlane);
    let Some(y) = log_axis(&series) else {
        return draw_note(area, caption, "no measurements in the plane of incidence");
    };
    draw_m00_profile(
        area,
        Domain::InPlane,
        &with_binning(caption, binned),
        "m00 = f00, BRDF (sr⁻¹)",
        y,
        series,
        binned,
    )
}

/// An m00 profile along `domain` on the log axis `y`: full-size text, error bars unless the
/// points are medians per bin.
fn draw_m00_profile<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    domain: Domain,
    caption: &str,
    y_desc: &str,
    y: YAxis,
    series: Vec<profiles::ProfileSeries>,
    binned: bool,
) -> DrawResult<DB> {
    draw_profile(
        area,
        &Profile {
            caption: caption.to_owned(),
            x_desc: domain.x_desc(false).into(),
            y_desc: y_desc.into(),
            x_axis: domain.axis(area.dim_in_pixel().0),
            y,
            series,
            error_bars: !binned,
            compact: false,
        },
    )
}

/// A profile panel's caption, saying when its points are medians per bin.
fn with_binning(caption: &str, binned: bool) -> String {
    if binned {
        format!("{caption} (median per {BIN_DEGREES}° bin)")
    } else {
        caption.to_owned()
    }
}

/// Width of the ring legend strip at the right of panel (b).
const RING_LEGEND_WIDTH: i32 = 150;

/// Rings listed in the legend before "+ N more".
const RING_LEGEND_ROWS: usize = 18;

/// The rings' key: incidence angle → detector zenith of each ring listed (in its colour and
/// marker), then counts of the off-plane points the panel does not show.
fn ring_legend(data: &ReportData) -> Vec<LegendEntry> {
    let mut entries: Vec<LegendEntry> = data
        .rings
        .iter()
        .take(RING_LEGEND_ROWS)
        .map(|ring| {
            LegendEntry::marker(
                format!(
                    "{}° → {}°",
                    format_angle(data.incidences[ring.incidence]),
                    format_angle(ring.theta_r_deg)
                ),
                incidence_color(data.slot[ring.incidence].unwrap_or(0)),
                Marker::for_rank(ring.rank),
            )
        })
        .collect();
    if data.rings.len() > RING_LEGEND_ROWS {
        entries.push(LegendEntry::text(format!(
            "+ {} more",
            data.rings.len() - RING_LEGEND_ROWS
        )));
    }
    let off_ring = data.off_ring_points();
    if off_ring > 0 {
        // A raster around specular is not a ring; its points are among the residuals only.
        entries.push(LegendEntry::text(format!("{off_ring} raster pts")));
        entries.push(LegendEntry::text("only in (g)"));
    }
    if data.unshown_ring_points > 0 {
        // Rings beyond the drawn ones (other incidence angles, or more than MAX_RINGS).
        for line in [
            format!("{} pts on", data.unshown_ring_points),
            "other rings".to_owned(),
            "only in (g)".to_owned(),
        ] {
            entries.push(LegendEntry::text(line));
        }
    }
    entries
}

/// Panel (b): m00 against φr − φi on each drawn ring, with the rings' key in a strip at the right.
pub(super) fn draw_rings_m00<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let caption = "(b) m00 on out-of-plane rings";
    let (series, binned) = profile_series(data, Quantity::M00, Domain::Rings);
    let Some(y) = log_axis(&series) else {
        let note = match data.off_ring_points() {
            0 => "no out-of-plane measurements".to_owned(),
            1 => "no rings; the 1 off-plane point is in (g)".to_owned(),
            n => format!("no rings; {n} off-plane points (a raster) are in (g)"),
        };
        return draw_note(area, caption, &note);
    };
    let (width, _) = area.dim_in_pixel();
    let (chart_area, legend_area) = area.split_horizontally(width as i32 - RING_LEGEND_WIDTH);
    draw_m00_profile(
        &chart_area,
        Domain::Rings,
        &with_binning(caption, binned),
        "m00 (sr⁻¹)",
        y,
        series,
        binned,
    )?;
    draw_ring_legend(&legend_area, &ring_legend(data))
}

/// The ring key in its strip under a heading, moved up when it is too long for the panel.
fn draw_ring_legend<DB: DrawingBackend>(
    legend_area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
) -> DrawResult<DB> {
    let (_, height) = legend_area.dim_in_pixel();
    let heading = (FONT, style::LEGEND_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Top));
    legend_area.draw_text("ring θi → θr", &heading, (4, 48))?;
    let rows = entries.len() as i32;
    let top = (48 + 24).min(height as i32 - rows * (style::LEGEND_SIZE + 7) - 10);
    draw_legend_column(legend_area, entries, (4, top))
}

/// Said by the profile panels when the geometry has neither an in-plane sweep nor a ring.
const NO_PROFILE_NOTE: &str = "no in-plane sweep or ring to draw along: see the residuals (g)";

/// Panel (d): m_ij/m00 for the linear-polarization elements present, as a grid of small plots.
pub(super) fn draw_linear_block<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let caption = "(d) Linear-polarization block normalized by m00: data vs model";
    let elements: Vec<usize> = LINEAR_BLOCK
        .into_iter()
        .filter(|&e| data.has_element(e))
        .collect();
    if elements.is_empty() {
        return draw_note(
            area,
            caption,
            "only m00 was measured: no polarization elements to compare",
        );
    }
    let has_in_plane = data.in_plane.iter().any(Option::is_some);
    if !has_in_plane && data.rings.is_empty() {
        return draw_note(area, caption, NO_PROFILE_NOTE);
    }
    draw_caption(area, caption)?;
    let (width, _) = area.dim_in_pixel();
    let grid = area
        .clone()
        .shrink((0, 40), (width, area.dim_in_pixel().1 - 40));
    let columns = elements.len().min(4);
    let rows = elements.len().div_ceil(4);
    let cells = grid.split_evenly((rows, columns));
    for (cell, &element) in cells.iter().zip(&elements) {
        draw_ratio(cell, data, element, has_in_plane)?;
    }
    Ok(())
}

/// One small plot of panel (d): m_ij/m00 of `element` in the plane of incidence, or on the rings
/// when it vanishes in the plane by symmetry or the measurement has no in-plane sweep.
fn draw_ratio<DB: DrawingBackend>(
    cell: &DrawingArea<DB, Shift>,
    data: &ReportData,
    element: usize,
    has_in_plane: bool,
) -> DrawResult<DB> {
    let on_rings = !data.rings.is_empty() && (ZERO_IN_PLANE.contains(&element) || !has_in_plane);
    let domain = if on_rings {
        Domain::Rings
    } else {
        Domain::InPlane
    };
    let quantity = Quantity::Ratio(element);
    let (series, binned) = profile_series(data, quantity, domain);
    draw_profile(
        cell,
        &Profile {
            caption: format!(
                "{}{}{}",
                quantity.label(),
                if on_rings { " (rings)" } else { "" },
                if binned { ", medians" } else { "" }
            ),
            x_desc: domain.x_desc(true).into(),
            y_desc: String::new(),
            x_axis: domain.axis(cell.dim_in_pixel().0),
            y: linear_axis(&series, 1.5),
            series,
            error_bars: false,
            compact: true,
        },
    )
}

/// Panel (e): DoLP for unpolarized illumination, √(m10² + m20²)/m00 (docs/design.md §1.6).
pub(super) fn draw_dolp<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let measured = data.has_element(4) && data.has_element(8);
    let caption = if measured {
        "(e) DoLP, unpolarized illumination".to_owned()
    } else {
        "(e) DoLP, model only (m10, m20 not both measured)".to_owned()
    };
    let domain = if data.in_plane.iter().any(Option::is_some) {
        Domain::InPlane
    } else if !data.rings.is_empty() {
        Domain::Rings
    } else {
        return draw_note(area, &caption, NO_PROFILE_NOTE);
    };
    let (series, binned) = profile_series(data, Quantity::Dolp, domain);
    let caption = with_binning(&caption, binned);
    let y = match linear_axis(&series, 1.0) {
        YAxis::Linear { high, .. } => YAxis::Linear { low: 0.0, high },
        other => other,
    };
    draw_profile(
        area,
        &Profile {
            caption,
            x_desc: domain.x_desc(true).into(),
            y_desc: "DoLP = √(m10² + m20²)/m00".into(),
            x_axis: domain.axis(area.dim_in_pixel().0),
            y,
            series,
            error_bars: false,
            compact: false,
        },
    )
}
