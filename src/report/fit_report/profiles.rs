//! Data-versus-model panels: a measured quantity (m00, a normalized Mueller element or the DoLP)
//! against detector zenith in the plane of incidence, or against relative azimuth on the
//! out-of-plane rings, with the chosen model solid and the competing one dashed.

use super::data::{ModelSweep, PointView, ReportData};
use super::style::{
    incidence_color, log_tick, report_mesh_style, sane_linear_range, sane_log_range, DrawResult,
    Marker, YAxis, AXIS_DESC_SIZE, CAPTION_SIZE, GREY, LEGEND_SIZE, MAX_LOG_DECADES,
    SMALL_CAPTION_SIZE, SMALL_TICK_SIZE, TICK_SIZE,
};
use crate::measure::MUELLER_ELEMENT_NAMES;
use crate::optics::Mueller;
use crate::plot_style::FONT;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged, ValueFormatter};
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
    pub fn of_point(&self, p: &PointView) -> Option<(f64, Option<f64>)> {
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

/// The geometry a profile panel runs along.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// Signed detector zenith in the plane of incidence, −90…90°.
    InPlane,
    /// φ_r − φ_i on the out-of-plane rings, 0…360°.
    Rings,
}

impl Domain {
    pub fn x_range(&self) -> (f64, f64) {
        match self {
            Domain::InPlane => (-90.0, 90.0),
            Domain::Rings => (0.0, 360.0),
        }
    }

    /// The x axis for a panel `width` pixels wide: labels at the finest of 15°, 30°, 45° or 90°
    /// that leaves room for them, light grid lines at a third of that.
    pub fn axis(&self, width: u32) -> DegreeAxis {
        let (low, high) = self.x_range();
        // About 100 px of a panel go to the y labels and margins.
        let pixels_per_degree = f64::from(width.saturating_sub(100)) / (high - low);
        let bold = [15.0, 30.0, 45.0, 90.0]
            .into_iter()
            .find(|step| step * pixels_per_degree >= MIN_LABEL_SPACING)
            .unwrap_or(90.0);
        DegreeAxis {
            low,
            high,
            bold,
            light: bold / 3.0,
        }
    }

    pub fn x_desc(&self, compact: bool) -> &'static str {
        match (self, compact) {
            (Domain::InPlane, false) => {
                "detector zenith θr (°) in the plane of incidence: + specular side, − toward the source"
            }
            (Domain::InPlane, true) => "detector zenith θr (°), in plane",
            (Domain::Rings, false) => "detector azimuth φr − φi (°), 180 = specular side",
            (Domain::Rings, true) => "φr − φi (°) on the rings",
        }
    }
}

/// Pixels between x labels so that "−135" and its neighbours do not touch.
const MIN_LABEL_SPACING: f64 = 48.0;

/// A linear axis in degrees whose ticks are multiples of chosen steps (plotters' own f64 axis
/// only knows 1–2–5 steps, which do not fit angles).
#[derive(Clone, Debug, PartialEq)]
pub struct DegreeAxis {
    low: f64,
    high: f64,
    bold: f64,
    light: f64,
}

impl DegreeAxis {
    fn multiples(&self, step: f64) -> Vec<f64> {
        let first = (self.low / step).ceil() as i64;
        let last = (self.high / step).floor() as i64;
        (first..=last).map(|i| i as f64 * step).collect()
    }
}

impl Ranged for DegreeAxis {
    type FormatOption = DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        let fraction = (value - self.low) / (self.high - self.low);
        limit.0 + (fraction * (limit.1 - limit.0) as f64).round() as i32
    }

    fn key_points<Hint: KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        if hint.weight().allow_light_points() {
            self.multiples(self.light)
        } else {
            self.multiples(self.bold)
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.low..self.high
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
    let measured = |p: &PointView, x: f64| {
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
    for p in &data.points {
        let placed = match domain {
            Domain::InPlane => data.slot[p.incidence].zip(p.signed_zenith),
            Domain::Rings => p.ring.map(|ring| (ring, p.relative_azimuth)),
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

/// Decades a log axis spans at least, so that it carries two labelled powers of ten.
const MIN_LOG_DECADES: f64 = 2.0;

/// A log axis spanning the measured values with their error bars and the chosen model at the
/// measured geometries (so a poor fit shows both); `None` when nothing positive is measured. When
/// they span more than a readable number of decades (an m00 of 1e308 among values of 0.1), the
/// axis covers the decades that hold most of them instead.
pub fn log_axis(series: &[ProfileSeries]) -> Option<YAxis> {
    let mut values = Vec::new();
    for p in series.iter().flat_map(|s| &s.points) {
        let sigma = p.sigma.unwrap_or(0.0);
        for (bottom, top) in [(p.value - sigma, p.value + sigma), (p.value, p.value)]
            .into_iter()
            .chain(p.model.map(|m| (m, m)))
        {
            if top > 0.0 {
                values.push(top);
                values.push(if bottom > 0.0 { bottom } else { top });
            }
        }
    }
    let (low, high) = densest_decades(&mut values, MAX_LOG_DECADES - MIN_LOG_DECADES)?;
    let (mut low, mut high) = (low / 1.5, high * 1.5);
    let shortfall = MIN_LOG_DECADES - (high / low).log10();
    if shortfall > 0.0 {
        let widen = 10f64.powf(shortfall / 2.0);
        low /= widen;
        high *= widen;
    }
    let (low, high) = sane_log_range(low, high);
    Some(YAxis::Log { low, high })
}

/// The smallest and largest of the positive `values` (which it sorts), or, when they span more
/// than `decades`, of those in the `decades`-wide window that holds the most of them.
fn densest_decades(values: &mut [f64], decades: f64) -> Option<(f64, f64)> {
    values.sort_by(f64::total_cmp);
    let (&low, &high) = (values.first()?, values.last()?);
    let ratio = 10f64.powf(decades);
    if high / low <= ratio {
        return Some((low, high));
    }
    let (mut best, mut start) = ((0, 0), 0);
    for end in 0..values.len() {
        while values[end] / values[start] > ratio {
            start += 1;
        }
        if end - start > best.1 - best.0 {
            best = (start, end);
        }
    }
    Some((values[best.0], values[best.1]))
}

/// A linear axis spanning data, error bars and both models, padded by 8 %, within ±`limit`.
pub fn linear_axis(series: &[ProfileSeries], limit: f64) -> YAxis {
    let (mut low, mut high) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut include = |y: f64| {
        if y.is_finite() {
            low = low.min(y);
            high = high.max(y);
        }
    };
    for s in series {
        for p in &s.points {
            include(p.value - p.sigma.unwrap_or(0.0));
            include(p.value + p.sigma.unwrap_or(0.0));
        }
        for &(_, y) in s.chosen.iter().chain(s.alternative.iter().flatten()) {
            include(y);
        }
    }
    if !low.is_finite() {
        return YAxis::Linear {
            low: -0.1,
            high: 0.1,
        };
    }
    let pad = ((high - low) * 0.08).max(0.01);
    // Data all beyond ±limit would clamp to a reversed range.
    let (low, high) = sane_linear_range(
        (low - pad).max(-limit),
        (high + pad).min(limit),
        (-limit, limit),
    );
    YAxis::Linear { low, high }
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

/// The label on a dashed curve running flat along the bottom of a log axis.
pub const FLOOR_LABEL: &str = "dashed level at the bottom: the competing fit's diffuse floor ρd/π";
/// A stretch of a dashed curve within 1 % of its first value counts as flat when it covers this
/// share of the points, in the lowest [`FLOOR_BOTTOM_SHARE`] of the log axis' decades.
const FLOOR_MIN_SHARE: f64 = 0.15;
const FLOOR_BOTTOM_SHARE: f64 = 0.25;

/// Where the competing fit's curves run flat near the bottom of a log axis: where its facet lobe
/// has died away and its diffuse term ρd/π is all that is left, a level line that reads as a
/// threshold unless it is labelled. The left end (x, y) of the longest such stretch.
pub fn flat_floor(series: &[ProfileSeries], axis: YAxis) -> Option<(f64, f64)> {
    let YAxis::Log { low, high } = axis else {
        return None;
    };
    let bottom = low * (high / low).powf(FLOOR_BOTTOM_SHARE);
    let mut best: Option<(usize, (f64, f64))> = None;
    for line in series.iter().filter_map(|s| s.alternative.as_ref()) {
        let mut start = 0;
        for i in 1..=line.len() {
            let level = line[start].1;
            if i < line.len() && (line[i].1 / level - 1.0).abs() < 0.01 {
                continue;
            }
            let length = i - start;
            let long = length as f64 >= FLOOR_MIN_SHARE * line.len() as f64 && length > 2;
            if long && (low..=bottom).contains(&level) && best.is_none_or(|(b, _)| length > b) {
                best = Some((length, line[start]));
            }
            start = i;
        }
    }
    best.map(|(_, at)| at)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::report::fit_report::data::Reading;

    /// A dashed curve over x = −90…90°: a lobe falling to a level `floor` on the left third.
    fn floor_series(floor: f64) -> ProfileSeries {
        let line = (0..=180)
            .map(|i| {
                let x = f64::from(i) - 90.0;
                (
                    x,
                    floor
                        + if x < -30.0 {
                            0.0
                        } else {
                            0.1 * ((x + 30.0) / 20.0).exp()
                        },
                )
            })
            .collect();
        ProfileSeries {
            color: BLACK,
            marker: Marker::FilledCircle,
            points: Vec::new(),
            chosen: Vec::new(),
            alternative: Some(line),
        }
    }

    #[test]
    fn a_competing_curve_flat_along_the_bottom_of_a_log_axis_is_labelled() {
        let axis = YAxis::Log {
            low: 1e-4,
            high: 100.0,
        };
        // Flat at 2e-4 over −90…−30°: labelled at its left end.
        assert_eq!(flat_floor(&[floor_series(2e-4)], axis), Some((-90.0, 2e-4)));
        // A level high on the axis is not a floor; one below the axis is not drawn at all; a
        // linear axis has none; no competing fit, no label.
        assert_eq!(flat_floor(&[floor_series(0.5)], axis), None);
        assert_eq!(flat_floor(&[floor_series(1e-6)], axis), None);
        let linear = YAxis::Linear {
            low: 0.0,
            high: 1.0,
        };
        assert_eq!(flat_floor(&[floor_series(2e-4)], linear), None);
        let chosen_only = ProfileSeries {
            alternative: None,
            ..floor_series(2e-4)
        };
        assert_eq!(flat_floor(&[chosen_only], axis), None);
    }

    fn point(readings: &[(usize, f64, f64)]) -> PointView {
        let mut all = [None; 16];
        for &(e, value, sigma) in readings {
            all[e] = Some(Reading { value, sigma });
        }
        PointView {
            incidence: 0,
            signed_zenith: Some(10.0),
            ring: None,
            relative_azimuth: 180.0,
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

    #[test]
    fn log_axis_holds_data_error_bars_and_model_over_two_decades() {
        let series = ProfileSeries {
            color: BLACK,
            marker: Marker::FilledCircle,
            points: vec![
                ProfilePoint {
                    x: 0.0,
                    value: 0.2,
                    sigma: Some(0.3),
                    model: Some(0.25),
                },
                ProfilePoint {
                    x: 5.0,
                    value: 0.1,
                    sigma: Some(0.01),
                    model: Some(0.01),
                },
            ],
            chosen: vec![(0.0, 1e-12), (5.0, 100.0)],
            alternative: None,
        };
        let YAxis::Log { low, high } = log_axis(std::slice::from_ref(&series)).unwrap() else {
            panic!("log axis expected")
        };
        // Data top 0.5, model bottom 0.01 (the error bar below 0 is ignored), 1.5× margins;
        // curves outside the measured geometry do not stretch the axis.
        assert!((high - 0.75).abs() < 1e-12 && (low - 0.01 / 1.5).abs() < 1e-15);
        let narrow = ProfileSeries {
            points: vec![series.points[1]],
            ..series
        };
        let YAxis::Log { low, high } = log_axis(&[narrow]).unwrap() else {
            panic!("log axis expected")
        };
        assert!(((high / low).log10() - 2.0).abs() < 1e-12);
    }

    #[test]
    fn an_absurd_value_does_not_empty_the_log_axis() {
        let at = |x: f64, value: f64| ProfilePoint {
            x,
            value,
            sigma: None,
            model: Some(0.1),
        };
        let series = |points| ProfileSeries {
            color: BLACK,
            marker: Marker::FilledCircle,
            points,
            chosen: vec![],
            alternative: None,
        };
        for outlier in [1e308, 1e-320] {
            let points = vec![at(0.0, 0.2), at(1.0, 0.05), at(2.0, outlier)];
            let YAxis::Log { low, high } = log_axis(&[series(points)]).unwrap() else {
                panic!("log axis expected")
            };
            assert!(low <= 0.05 && high >= 0.2 && high.is_finite() && low.is_normal());
        }
    }

    #[test]
    fn degree_axes_label_angles_at_multiples_that_fit() {
        use plotters::coord::ranged1d::BoldPoints;
        let wide = Domain::InPlane.axis(1200);
        assert_eq!(wide.key_points(BoldPoints(20)).len(), 13, "every 15°");
        let narrow = Domain::Rings.axis(300);
        assert_eq!(
            narrow.key_points(BoldPoints(20)),
            [0.0, 90.0, 180.0, 270.0, 360.0]
        );
        assert_eq!(
            narrow.key_points(100usize).len(),
            13,
            "light lines every 30°"
        );
        assert_eq!(wide.map(&0.0, (100, 300)), 200);
    }
}
