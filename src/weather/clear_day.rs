//! The built-in clear day ([`super::Weather::clear_day`]).
//!
//! **Air temperature: a diurnal cycle of half cosines between extremes.** Each apparent solar day
//! has a minimum `air_min_k` at sunrise and a maximum `air_max_k` at 15:00 local apparent solar
//! time. Sunrise is the standard one (the SPA's upper limb on a sea-level horizon: centre at
//! −0.8333°, geometric); the day's solar transit (hour angle 0, the SPA's, through the
//! `solar-positioning` crate) is 12:00 apparent solar time, so 15:00 is transit + 3 h (the hour
//! angle then differs from 45° by the equation of time's change over 3 h, under 2 s). When the
//! sun does not rise in the 12 h before a transit (polar day or night) the minimum is at 03:00
//! apparent solar time (transit − 9 h). Between consecutive extremes (t₀, T₀) and (t₁, T₁):
//!
//!   T(t) = T₁ + (T₀ − T₁) · (1 + cos(π (t − t₀)/(t₁ − t₀))) / 2,
//!
//! rising from sunrise to 15:00 and falling from 15:00 to the next sunrise (or 03:00). The curve is
//! continuous with a continuous slope (zero at every extreme) and stays within [min, max]; it is a
//! simple stand-in for the shape of measured clear-sky cycles (minimum near sunrise, maximum in the
//! mid-afternoon, cf. Parton & Logan, Agric. Meteorol. 23:205, 1981), not a boundary-layer model.

use super::{
    simplified_solis, swinbank_longwave_w_m2, ClearDay, Site, SolisAtmosphere, Weather,
    WeatherError, WeatherSample, CLEAR_DAY_STEP_S, MAX_CLEAR_DAY_DURATION_S, MAX_WIND_M_S,
};
use crate::emitter::{format_time_utc, sun_position, SunError};
use crate::optics::MAX_TEMPERATURE_K;
use crate::text::number;
use chrono::{DateTime, TimeDelta, Utc};
use solar_positioning::{delta_t, Horizon, Location, SolarEvents};

/// Margin of extremes computed before the start and after the end (s): at least one extreme on
/// either side of the span, whatever the longitude and the season.
const MARGIN_S: f64 = 1.5 * 86_400.0;

/// The rows of a clear day (module documentation of [`super`] and of this module).
pub(super) fn build(day: &ClearDay, site: &Site, duration_s: f64) -> Result<Weather, WeatherError> {
    check(day, duration_s)?;
    let steps = ((duration_s / CLEAR_DAY_STEP_S).ceil() as usize).max(1);
    let curve = DiurnalCurve::new(
        day,
        site,
        -MARGIN_S,
        steps as f64 * CLEAR_DAY_STEP_S + MARGIN_S,
    )?;
    let mut times = Vec::with_capacity(steps + 1);
    let mut samples = Vec::with_capacity(steps + 1);
    for k in 0..=steps {
        let time_s = k as f64 * CLEAR_DAY_STEP_S;
        let instant = site.start_utc + TimeDelta::seconds(k as i64 * CLEAR_DAY_STEP_S as i64);
        let sun = sun_position(site.latitude_deg, site.longitude_deg, &instant)?;
        let irradiance = simplified_solis(sun.elevation_deg, &SolisAtmosphere::DEFAULT);
        let air_k = curve.at(time_s);
        times.push(time_s);
        samples.push(WeatherSample {
            air_k,
            wind_m_s: day.wind_m_s,
            direct_normal_w_m2: irradiance.direct_normal_w_m2,
            diffuse_horizontal_w_m2: irradiance.diffuse_horizontal_w_m2,
            longwave_down_w_m2: swinbank_longwave_w_m2(air_k),
            sun_direction: sun.direction(),
        });
    }
    Ok(Weather::from_rows(site.start_utc, times, samples))
}

/// The clear day's numbers and duration: temperatures within (0, 10⁴] K with min ≤ max, wind
/// finite and ≥ 0, duration within [0, [`MAX_CLEAR_DAY_DURATION_S`]].
fn check(day: &ClearDay, duration_s: f64) -> Result<(), WeatherError> {
    let invalid = |message: String| Err(WeatherError::InvalidClearDay(message));
    for (name, t) in [("air_min_k", day.air_min_k), ("air_max_k", day.air_max_k)] {
        if !(t > 0.0 && t <= MAX_TEMPERATURE_K) {
            return invalid(format!(
                "{name} = {} K is outside (0, {MAX_TEMPERATURE_K}] K",
                number(t)
            ));
        }
    }
    if day.air_min_k > day.air_max_k {
        return invalid(format!(
            "air_min_k = {} K is above air_max_k = {} K",
            number(day.air_min_k),
            number(day.air_max_k)
        ));
    }
    if !(0.0..=MAX_WIND_M_S).contains(&day.wind_m_s) {
        return invalid(format!(
            "wind_m_s = {} is outside 0…{MAX_WIND_M_S} m/s",
            number(day.wind_m_s)
        ));
    }
    if !(0.0..=MAX_CLEAR_DAY_DURATION_S).contains(&duration_s) {
        return invalid(format!(
            "duration {} s is outside [0, {}] s (400 days)",
            number(duration_s),
            number(MAX_CLEAR_DAY_DURATION_S)
        ));
    }
    Ok(())
}

/// Air temperature extremes (s from the start, K), alternately a minimum and a maximum, joined by
/// half cosines.
#[derive(Debug)]
pub(super) struct DiurnalCurve {
    extremes: Vec<(f64, f64)>,
}

impl DiurnalCurve {
    /// The extremes of every solar day whose transit falls in [from_s, to_s] (seconds from the
    /// site's start); the caller widens its span by [`MARGIN_S`] on either side.
    pub(super) fn new(
        day: &ClearDay,
        site: &Site,
        from_s: f64,
        to_s: f64,
    ) -> Result<DiurnalCurve, WeatherError> {
        let instant = |s: f64| site.start_utc + TimeDelta::milliseconds((s * 1e3).round() as i64);
        let seconds = |t: DateTime<Utc>| (t - site.start_utc).num_milliseconds() as f64 / 1e3;
        let events = SpaEvents::new(site, instant(from_s))?;
        let mut extremes = Vec::new();
        let (mut search_from, end) = (instant(from_s), instant(to_s));
        while search_from < end {
            let transit = events.transit_after(search_from)?;
            let rise = events.rise_before(transit)?;
            let minimum = rise.unwrap_or(transit - TimeDelta::hours(9));
            extremes.push((seconds(minimum), day.air_min_k));
            extremes.push((seconds(transit + TimeDelta::hours(3)), day.air_max_k));
            search_from = transit;
        }
        Ok(DiurnalCurve { extremes })
    }

    /// The air temperature `time_s` after the start: the half cosine between the extremes around
    /// it (equation in the module documentation); the nearest extreme beyond the first or last.
    pub(super) fn at(&self, time_s: f64) -> f64 {
        let i = self.extremes.partition_point(|&(t, _)| t <= time_s);
        if i == 0 {
            return self.extremes[0].1;
        }
        if i == self.extremes.len() {
            return self.extremes[i - 1].1;
        }
        let ((t0, v0), (t1, v1)) = (self.extremes[i - 1], self.extremes[i]);
        let phase = std::f64::consts::PI * (time_s - t0) / (t1 - t0);
        v1 + (v0 - v1) * 0.5 * (1.0 + phase.cos())
    }

    #[cfg(test)]
    pub(super) fn extremes(&self) -> &[(f64, f64)] {
        &self.extremes
    }
}

/// Solar transits and sunrises at a site from the SPA (through `solar-positioning`), with ΔT
/// estimated once for the start.
struct SpaEvents {
    events: SolarEvents,
    location: Location,
    delta_t: f64,
}

impl SpaEvents {
    fn new(site: &Site, time: DateTime<Utc>) -> Result<SpaEvents, WeatherError> {
        let failed = |reason: String| SunError::Position {
            latitude_deg: site.latitude_deg,
            longitude_deg: site.longitude_deg,
            time: format_time_utc(&time),
            reason,
        };
        Ok(SpaEvents {
            events: SolarEvents::new(),
            location: Location {
                latitude: site.latitude_deg,
                longitude: site.longitude_deg,
            },
            delta_t: delta_t::estimate_from_date_like(&time).map_err(|e| failed(e.to_string()))?,
        })
    }

    fn failed(&self, time: DateTime<Utc>, reason: String) -> WeatherError {
        WeatherError::Sun(SunError::Position {
            latitude_deg: self.location.latitude,
            longitude_deg: self.location.longitude,
            time: format_time_utc(&time),
            reason,
        })
    }

    /// The first upper transit after `time` (one comes within 24 h 1 min; 26 h searched).
    fn transit_after(&self, time: DateTime<Utc>) -> Result<DateTime<Utc>, WeatherError> {
        let end = time + TimeDelta::hours(26);
        self.events
            .next_transit(&time, &end, self.location.longitude, self.delta_t)
            .map_err(|e| self.failed(time, e.to_string()))?
            .ok_or_else(|| self.failed(time, "no solar transit within 26 h".into()))
    }

    /// The standard sunrise in the 12 h before `transit`, if the sun rises then.
    fn rise_before(&self, transit: DateTime<Utc>) -> Result<Option<DateTime<Utc>>, WeatherError> {
        let start = transit - TimeDelta::hours(12);
        self.events
            .next_rise(
                &start,
                &transit,
                self.location,
                self.delta_t,
                Horizon::SunriseSunset,
            )
            .map_err(|e| self.failed(start, e.to_string()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::emitter::parse_time_utc;

    fn site(latitude_deg: f64, longitude_deg: f64, start: &str) -> Site {
        Site {
            latitude_deg,
            longitude_deg,
            start_utc: parse_time_utc(start).unwrap(),
        }
    }

    const DAY: ClearDay = ClearDay {
        air_min_k: 281.0,
        air_max_k: 293.0,
        wind_m_s: 2.0,
    };

    #[test]
    fn extremes_alternate_and_the_curve_is_smooth_between_them() {
        let munich = site(48.14, 11.58, "2026-06-21T00:00:00Z");
        let curve = DiurnalCurve::new(&DAY, &munich, -MARGIN_S, 2.0 * 86_400.0 + MARGIN_S).unwrap();
        let extremes = curve.extremes();
        assert!(extremes.len() >= 8, "{extremes:?}");
        for (i, pair) in extremes.windows(2).enumerate() {
            assert!(pair[0].0 < pair[1].0, "{extremes:?}");
            let expected = if i % 2 == 0 {
                [281.0, 293.0]
            } else {
                [293.0, 281.0]
            };
            assert_eq!([pair[0].1, pair[1].1], expected);
        }
        for &(t, v) in extremes {
            assert_eq!(curve.at(t), v);
        }
        // Continuous and bounded: no jump larger than the steepest half cosine allows over 1 s.
        let mut last = curve.at(0.0);
        for s in 1..(2 * 86_400) {
            let v = curve.at(s as f64);
            assert!((281.0..=293.0).contains(&v));
            assert!((v - last).abs() < 1e-3, "{s}: {last} → {v}");
            last = v;
        }
    }

    #[test]
    fn munich_sunrise_and_afternoon() {
        // 21 June 2026 in Munich: sunrise 03:12 UTC (05:12 CEST), transit 11:16 UTC (almanac
        // values to the minute), so the maximum is at 14:16 UTC.
        let munich = site(48.14, 11.58, "2026-06-21T00:00:00Z");
        let curve = DiurnalCurve::new(&DAY, &munich, 0.0, 86_400.0).unwrap();
        let (rise, top) = (curve.extremes()[0].0, curve.extremes()[1].0);
        assert!((rise - (3.0 * 3600.0 + 12.0 * 60.0)).abs() < 90.0, "{rise}");
        assert!((top - (14.0 * 3600.0 + 16.0 * 60.0)).abs() < 90.0, "{top}");
    }
}
