//! Data-versus-model panels: a measured quantity (m00, a normalized Mueller element or the DoLP)
//! against detector zenith in the plane of incidence, or against relative azimuth on the
//! out-of-plane rings, with the chosen model solid and the competing one dashed.

mod axes;

pub use axes::{flat_floor, linear_axis, log_axis, DegreeAxis, Domain, FLOOR_LABEL};

use super::data::{DrawnPoint, ModelSweep, ReportData};
use super::style::{
    incidence_color, log_tick, report_mesh_style, DrawResult, Marker, YAxis, AXIS_DESC_SIZE,
    CAPTION_SIZE, GREY, LEGEND_SIZE, SMALL_CAPTION_SIZE, SMALL_TICK_SIZE, TICK_SIZE,
};
use crate::measure::MUELLER_ELEMENT_NAMES;
use crate::optics::Mueller;
use crate::plot_style::FONT;
use plotters::coord::ranged1d::{Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// What a profile panel shows on its y axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Quantity {
    M00,
    /// Element r*4 + c divided by m00.
    Ratio(usize),
    /// Degree of linear polarization for unpolarized illumination, √(m10² + m20²)/m00.
    Dolp,
}

impl Quantity {
    pub fn label(&self) -> String {
        match *self {
            Quantity::M00 => "m00".into(),
            Quantity::Ratio(e) => format!("{}/m00", MUELLER_ELEMENT_NAMES[e]),
            Quantity::Dolp => "DoLP".into(),
        }
    }

    pub fn of_model(&self, m: &Mueller) -> Option<f64> {
        let m00 = m[(0, 0)];
        match *self {
            Quantity::M00 => Some(m00),
            Quantity::Ratio(e) => (m00 > 0.0).then(|| m[(e / 4, e % 4)] / m00),
            Quantity::Dolp => (m00 > 0.0).then(|| m[(1, 0)].hypot(m[(2, 0)]) / m00),
        }
    }

    /// The measured value and, where it propagates simply, its 1-σ.
    pub fn of_point(&self, p: &DrawnPoint) -> Option<(f64, Option<f64>)> {
        let m00 = p.readings[0]?;
        match *self {
            Quantity::M00 => Some((m00.value, Some(m00.sigma))),
            Quantity::Ratio(e) => {
                let element = p.readings[e]?;
                (m00.value > 0.0).then(|| {
                    let ratio = element.value / m00.value;
                    let sigma = element.sigma.hypot(ratio * m00.sigma) / m00.value;
                    (ratio, Some(sigma))
                })
            }
            Quantity::Dolp => {
                let (m10, m20) = (p.readings[4]?, p.readings[8]?);
                (m00.value > 0.0).then(|| (m10.value.hypot(m20.value) / m00.value, None))
            }
        }
    }
}

/// A measured point of a profile panel.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProfilePoint {
    pub x: f64,
    pub value: f64,
    pub sigma: Option<f64>,
    /// The chosen model at the point's own geometry.
    pub model: Option<f64>,
}

/// One group of points (an incidence angle in the plane, or a ring) with its model curves.
pub struct ProfileSeries {
    pub color: RGBColor,
    pub marker: Marker,
    pub points: Vec<ProfilePoint>,
    pub chosen: Vec<(f64, f64)>,
    pub alternative: Option<Vec<(f64, f64)>>,
}

fn curve(x: &[f64], matrices: &[Mueller], quantity: Quantity) -> Vec<(f64, f64)> {
    x.iter()
        .zip(matrices)
        .filter_map(|(&x, m)| quantity.of_model(m).map(|y| (x, y)))
        .collect()
}

fn series_of(
    color: RGBColor,
    marker: Marker,
    points: Vec<ProfilePoint>,
    sweep: &ModelSweep,
    quantity: Quantity,
) -> ProfileSeries {
    ProfileSeries {
        color,
        marker,
        points,
        chosen: curve(&sweep.x, &sweep.chosen, quantity),
        alternative: sweep
            .alternative
            .as_ref()
            .map(|m| curve(&sweep.x, m, quantity)),
    }
}

/// Most measured points a profile panel draws one by one (with error bars). Beyond it, each
/// series is binned along x ([`BIN_DEGREES`]) and drawn as the median per bin, so that a panel
/// costs the same for 10⁴ points as for 10⁶.
pub const MAX_PROFILE_POINTS: usize = 4000;
/// Width of a bin of a binned profile series, in degrees of the panel's x axis.
pub const BIN_DEGREES: f64 = 1.0;

/// The series of `quantity` along `domain`: one per incidence angle with curves in the plane, one
/// per drawn ring. The second value is true when the points were binned.
pub fn profile_series(
    data: &ReportData,
    quantity: Quantity,
    domain: Domain,
) -> (Vec<ProfileSeries>, bool) {
    let mut buckets = profile_points(data, quantity, domain);
    let binned = buckets.iter().map(Vec::len).sum::<usize>() > MAX_PROFILE_POINTS;
    if binned {
        for bucket in &mut buckets {
            *bucket = bin_points(std::mem::take(bucket));
        }
    }
    let series = match domain {
        Domain::InPlane => data
            .in_plane
            .iter()
            .zip(buckets)
            .enumerate()
            .filter_map(|(slot, (sweep, points))| {
                sweep.as_ref().map(|sweep| {
                    series_of(
                        incidence_color(slot),
                        Marker::FilledCircle,
                        points,
                        sweep,
                        quantity,
                    )
                })
            })
            .collect(),
        Domain::Rings => data
            .rings
            .iter()
            .zip(buckets)
            .map(|(ring, points)| {
                series_of(
                    incidence_color(data.slot[ring.incidence].unwrap_or(0)),
                    Marker::for_rank(ring.rank),
                    points,
                    &ring.sweep,
                    quantity,
                )
            })
            .collect(),
    };
    (series, binned)
}

/// The measured points of `quantity` along `domain`, one bucket per entry of
/// [`ReportData::in_plane`] or per ring, in one pass over the points (a file may hold as many
/// groups as points).
fn profile_points(data: &ReportData, quantity: Quantity, domain: Domain) -> Vec<Vec<ProfilePoint>> {
    let measured = |p: &DrawnPoint, x: f64| {
        quantity.of_point(p).map(|(value, sigma)| ProfilePoint {
            x,
            value,
            sigma,
            model: quantity.of_model(&p.model),
        })
    };
    let groups = match domain {
        Domain::InPlane => data.in_plane.len(),
        Domain::Rings => data.rings.len(),
    };
    let mut buckets: Vec<Vec<ProfilePoint>> = vec![Vec::new(); groups];
    for p in &data.drawn {
        let place = &p.place;
        let placed = match domain {
            Domain::InPlane => data.slot[place.incidence].zip(place.signed_zenith),
            Domain::Rings => place.ring.map(|ring| (ring, place.relative_azimuth)),
        };
        if let Some(point) = placed.and_then(|(group, x)| Some((group, measured(p, x)?))) {
            buckets[point.0].push(point.1);
        }
    }
    buckets
}

/// The median value (and median model) of the points in each [`BIN_DEGREES`]-wide bin of x,
/// at the bin's mean x, without error bars.
fn bin_points(mut points: Vec<ProfilePoint>) -> Vec<ProfilePoint> {
    let bin = |p: &ProfilePoint| (p.x / BIN_DEGREES).floor() as i64;
    points.sort_by(|a, b| bin(a).cmp(&bin(b)).then(a.value.total_cmp(&b.value)));
    let median = |values: &mut Vec<f64>| -> Option<f64> {
        values.sort_by(f64::total_cmp);
        let n = values.len();
        (n > 0).then(|| {
            if n % 2 == 1 {
                values[n / 2]
            } else {
                0.5 * (values[n / 2 - 1] + values[n / 2])
            }
        })
    };
    points
        .chunk_by(|a, b| bin(a) == bin(b))
        .map(|chunk| {
            let x = chunk.iter().map(|p| p.x).sum::<f64>() / chunk.len() as f64;
            let value = median(&mut chunk.iter().map(|p| p.value).collect()).unwrap_or(f64::NAN);
            let model = median(&mut chunk.iter().filter_map(|p| p.model).collect());
            ProfilePoint {
                x,
                value,
                sigma: None,
                model,
            }
        })
        .collect()
}

/// A data-versus-model panel.
pub struct Profile {
    pub caption: String,
    pub x_desc: String,
    pub y_desc: String,
    pub x_axis: DegreeAxis,
    pub y: YAxis,
    pub series: Vec<ProfileSeries>,
    pub error_bars: bool,
    /// Small sub-panel of the polarization block: smaller text, fewer ticks.
    pub compact: bool,
}

pub fn draw_profile<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    profile: &Profile,
) -> DrawResult<DB> {
    let (caption_size, x_area, y_area) = if profile.compact {
        (SMALL_CAPTION_SIZE, 46, 62)
    } else {
        (CAPTION_SIZE, 58, 86)
    };
    // The floor's label goes under the axis description, where no data can be.
    let floor = (!profile.compact)
        .then(|| flat_floor(&profile.series, profile.y))
        .flatten();
    let (area, strip) = match floor {
        Some(_) => {
            let (chart, strip) = area.split_vertically(area.dim_in_pixel().1 - FLOOR_LABEL_ROW);
            (chart, Some(strip))
        }
        None => (area.clone(), None),
    };
    let x = profile.x_axis.clone();
    let mut builder = ChartBuilder::on(&area);
    builder
        .caption(&profile.caption, (FONT, caption_size))
        .margin(if profile.compact { 6 } else { 12 })
        .margin_right(if profile.compact { 12 } else { 22 })
        .x_label_area_size(x_area)
        .y_label_area_size(y_area);
    match profile.y {
        YAxis::Log { low, high } => {
            let mut chart = builder.build_cartesian_2d(x, (low..high).log_scale())?;
            draw_axes(&mut chart, profile, &log_tick)?;
            draw_series(&mut chart, profile)?;
        }
        YAxis::Linear { low, high } => {
            let mut chart = builder.build_cartesian_2d(x, low..high)?;
            let decimals = if high - low < 0.05 { 3 } else { 2 };
            draw_axes(&mut chart, profile, &|v: &f64| format!("{v:.decimals$}"))?;
            draw_series(&mut chart, profile)?;
        }
    }
    if let Some(strip) = strip {
        let style = (FONT, LEGEND_SIZE)
            .into_font()
            .color(&GREY)
            .pos(Pos::new(HPos::Left, VPos::Top));
        strip.draw_text(FLOOR_LABEL, &style, (y_area, 0))?;
    }
    Ok(())
}

/// Height of the row under a panel's axis description that holds [`FLOOR_LABEL`], pixels.
const FLOOR_LABEL_ROW: u32 = 22;

fn draw_axes<DB: DrawingBackend, Y: Ranged<ValueType = f64> + ValueFormatter<f64>>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<DegreeAxis, Y>>,
    profile: &Profile,
    y_format: &dyn Fn(&f64) -> String,
) -> DrawResult<DB> {
    let (tick, desc) = if profile.compact {
        (SMALL_TICK_SIZE, SMALL_TICK_SIZE)
    } else {
        (TICK_SIZE, AXIS_DESC_SIZE)
    };
    let mesh = &mut chart.configure_mesh();
    mesh.y_labels(if profile.compact { 5 } else { 8 })
        .x_label_formatter(&|v| format!("{v:.0}"))
        .y_label_formatter(y_format)
        .x_desc(profile.x_desc.as_str())
        .y_desc(profile.y_desc.as_str());
    report_mesh_style(mesh, tick, desc).draw()
}

fn draw_series<DB: DrawingBackend, Y: Ranged<ValueType = f64> + ValueFormatter<f64>>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<DegreeAxis, Y>>,
    profile: &Profile,
) -> DrawResult<DB> {
    let axis = profile.y;
    let (low, high) = axis.bounds();
    let width = if profile.compact { 1 } else { 2 };
    for s in &profile.series {
        for piece in s.alternative.iter().flat_map(|line| axis.clip(line)) {
            chart.draw_series(DashedLineSeries::new(
                piece,
                7,
                5,
                s.color.mix(0.85).stroke_width(width),
            ))?;
        }
    }
    for s in &profile.series {
        for piece in axis.clip(&s.chosen) {
            chart.draw_series(LineSeries::new(piece, s.color.stroke_width(width)))?;
        }
    }
    let marker_size = if profile.compact { 2 } else { 3 };
    for s in &profile.series {
        let visible = s.points.iter().filter(|p| axis.contains(p.value));
        if profile.error_bars {
            chart.draw_series(visible.clone().filter_map(|p| {
                let (x, y, sigma) = (p.x, p.value, p.sigma?);
                let bottom = if (y - sigma) > low { y - sigma } else { low };
                Some(ErrorBar::new_vertical(
                    x,
                    bottom,
                    y,
                    (y + sigma).min(high),
                    s.color.mix(0.7).stroke_width(1),
                    4,
                ))
            }))?;
        }
        chart.draw_series(visible.map(|p| s.marker.at((p.x, p.value), marker_size, s.color)))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fit_report::data::{PointView, Reading};

    fn point(readings: &[(usize, f64, f64)]) -> DrawnPoint {
        let mut all = [None; 16];
        for &(e, value, sigma) in readings {
            all[e] = Some(Reading { value, sigma });
        }
        DrawnPoint {
            place: PointView {
                incidence: 0,
                signed_zenith: Some(0.0),
                ring: None,
                relative_azimuth: 180.0,
            },
            readings: all,
            model: Mueller::zeros(),
        }
    }

    #[test]
    fn quantities_of_measurements_and_models() {
        let p = point(&[(0, 0.5, 0.015), (4, 0.15, 0.005), (8, -0.2, 0.005)]);
        assert_eq!(Quantity::M00.of_point(&p), Some((0.5, Some(0.015))));
        let (ratio, sigma) = Quantity::Ratio(4).of_point(&p).unwrap();
        assert!((ratio - 0.3).abs() < 1e-15);
        // σ(m10/m00) = √(σ10² + (ratio σ00)²)/m00 = √(0.005² + 0.0045²)/0.5
        assert!((sigma.unwrap() - 0.0134536240470737).abs() < 1e-12);
        let (dolp, none) = Quantity::Dolp.of_point(&p).unwrap();
        assert!(
            (dolp - 0.5).abs() < 1e-15 && none.is_none(),
            "√(0.15² + 0.2²)/0.5"
        );
        assert_eq!(Quantity::Ratio(5).of_point(&p), None, "m11 not measured");

        let mut m = Mueller::zeros();
        m[(0, 0)] = 2.0;
        m[(1, 0)] = -1.2;
        m[(2, 0)] = 1.6;
        m[(2, 2)] = -1.0;
        assert_eq!(Quantity::Dolp.of_model(&m), Some(1.0));
        assert_eq!(Quantity::Ratio(10).of_model(&m), Some(-0.5));
        assert_eq!(Quantity::Ratio(10).of_model(&Mueller::zeros()), None);
        assert_eq!(Quantity::Ratio(6).label(), "m12/m00");
    }
}
