//! The axes of the profile panels: the x axis in degrees (detector zenith in the plane of
//! incidence, or relative azimuth on the rings) labelled at round multiples, and the y axis, log
//! over the decades that hold the data or linear, with the competing fit's flat diffuse floor
//! found for its label.

use super::super::style::{sane_linear_range, sane_log_range, YAxis, MAX_LOG_DECADES};
use super::ProfileSeries;
use plotters::coord::ranged1d::{DefaultFormatting, KeyPointHint, Ranged};

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
    use super::super::super::style::Marker;
    use super::super::{ProfilePoint, ProfileSeries};
    use super::*;
    use plotters::prelude::BLACK;

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
