//! The sun (docs/design.md §1.7): where it is, which way its light comes from, and how bright its disc is in
//! a sensor band.
//!
//! **Position.** NREL's Solar Position Algorithm (Reda & Andreas, Solar Energy 76:577, 2004; ±0.0003°
//! for years −2000…6000) through the `solar-positioning` crate, not a hand-written ephemeris.
//! [`sun_position`] returns the **apparent** (refraction-corrected) topocentric position for a
//! standard atmosphere (1013.25 hPa, 15 °C) at sea level, because that is where a camera, a shadow ray
//! or a glint sees the disc: refraction lifts it by ~0.017° at 45° elevation and by ~0.48° (about
//! its own diameter) at the horizon. The correction is SPA's (eq. 42), applied only while the true
//! centre elevation exceeds −0.83337° (−(solar radius 0.26667° + horizon refraction 0.5667°), SPA's
//! and pvlib's cutoff): below that the sun has set and the elevation is geometric, so the apparent
//! elevation jumps from −0.83° to about −0.22° there, the centre below the horizon either way.
//! [`sun_position_with`] takes the observer height, another atmosphere, or no refraction (the true
//! topocentric position).
//!
//! **Time.** An instant in UTC, given as RFC 3339 ([`parse_time_utc`]). SPA wants UT1; UTC stands in
//! for it (|UT1 − UTC| < 0.9 s, ≤ 0.004° of hour angle). ΔT = TT − UT1 is the crate's estimate for the
//! month (Espenak & Meeus with a fit to IERS data: 69.1 s in 2026). It only moves the ephemeris
//! time, against which the sun's geocentric position moves ~1.1e-5° per second (0.9856°/day), so a
//! ΔT off by seconds moves the position by ~1e-4° (more in azimuth near the zenith).
//!
//! **Frame and angles** (docs/design.md §1.7, and SPA's own convention): azimuth clockwise from north (+y)
//! toward east (+x), 0…360°; elevation above the horizontal xy-plane; z up.
//!
//! **Radiance.** A uniform unpolarized disc of angular diameter 0.533°, solid angle
//! Ω = 2π(1 − cos 0.2665°); L_sun = E_sun / Ω with E_sun its band irradiance on a surface facing it,
//! by default τ Ω L_bb(5772 K) over the sensor band and response ([`default_band_irradiance`]).

use crate::optics::Band;
use chrono::{DateTime, SecondsFormat, Utc};
use nalgebra::Vector3;
use solar_positioning::{delta_t, Location, RefractionCorrection, SolarPositions};

/// Mean angular diameter of the solar disc seen from Earth (degrees): docs/design.md §1.7.
pub const SUN_ANGULAR_DIAMETER_DEG: f64 = 0.533;
/// Angular radius of the disc (degrees), half of [`SUN_ANGULAR_DIAMETER_DEG`].
pub const SUN_HALF_ANGLE_DEG: f64 = 0.5 * SUN_ANGULAR_DIAMETER_DEG;
/// Solid angle of the disc, Ω = 2π(1 − cos 0.2665°) = 4π sin²(0.2665°/2) sr. A literal because
/// `cos` is not `const`; the test `solid_angle_is_the_cone_of_the_half_angle` recomputes it.
pub const SUN_SOLID_ANGLE_SR: f64 = 6.796_702_357_296_812e-5;
/// Effective temperature of the sun (K): IAU 2015 Resolution B3 nominal value. The default band
/// irradiance treats the disc as a blackbody at this temperature.
pub const SUN_TEMPERATURE_K: f64 = 5772.0;

/// Everything that can be wrong with a sun given in a scene, a weather file or on the command line.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum SunError {
    #[error("time '{text}' is not an RFC 3339 instant such as 2026-06-21T10:00:00Z: {reason}")]
    InvalidTime { text: String, reason: String },
    #[error(
        "sun elevation {}° is invalid: it must be finite and within [-90°, 90°]",
        crate::text::number(*.0)
    )]
    InvalidElevation(f64),
    #[error(
        "sun azimuth {}° is invalid: it must be finite (degrees clockwise from north)",
        crate::text::number(*.0)
    )]
    InvalidAzimuth(f64),
    #[error(
        "sun transmittance {} is invalid: it must be finite and within [0, 1]",
        crate::text::number(*.0)
    )]
    InvalidTransmittance(f64),
    #[error(
        "sun irradiance {} W·m⁻² is invalid: it must be finite and ≥ 0",
        crate::text::number(*.0)
    )]
    InvalidIrradiance(f64),
    #[error(
        "no sun position at latitude {}°, longitude {}°, {time}: {reason}",
        crate::text::number(*latitude_deg),
        crate::text::number(*longitude_deg)
    )]
    Position {
        latitude_deg: f64,
        longitude_deg: f64,
        time: String,
        reason: String,
    },
}

/// Where the sun is: elevation above the horizon and azimuth clockwise from north, in degrees, in
/// the world frame of docs/design.md §1.7.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SunPosition {
    pub elevation_deg: f64,
    pub azimuth_deg: f64,
}

impl SunPosition {
    /// A position given directly (a scene's `elevation_deg`, `azimuth_deg`), checked by
    /// [`validate_sun_angles`].
    pub fn new(elevation_deg: f64, azimuth_deg: f64) -> Result<SunPosition, SunError> {
        validate_sun_angles(elevation_deg, azimuth_deg)?;
        Ok(SunPosition {
            elevation_deg,
            azimuth_deg,
        })
    }

    /// Unit vector toward the sun's centre in the world frame ([`sun_direction`]).
    pub fn direction(&self) -> Vector3<f64> {
        sun_direction(self.elevation_deg, self.azimuth_deg)
    }
}

/// Atmosphere for SPA's refraction correction (eq. 42 of Reda & Andreas).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Atmosphere {
    /// Annual mean local pressure (hPa = mbar).
    pub pressure_hpa: f64,
    /// Annual mean local temperature (°C).
    pub temperature_c: f64,
}

impl Atmosphere {
    /// The standard atmosphere at sea level, 1013.25 hPa and 15 °C (ISA; the crate's
    /// `RefractionCorrection::standard()`).
    pub const STANDARD: Atmosphere = Atmosphere {
        pressure_hpa: 1013.25,
        temperature_c: 15.0,
    };
}

/// Observer and atmosphere for [`sun_position_with`]. `Default` is what [`sun_position`] uses: sea
/// level, the standard atmosphere (apparent position), ΔT estimated for the month.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpaOptions {
    /// Observer height above sea level (m); it changes the parallax (≤ 8.8″ in all), not the horizon.
    pub height_m: f64,
    /// `Some`: apparent position refracted by this atmosphere; `None`: true topocentric position.
    pub refraction: Option<Atmosphere>,
    /// ΔT = TT − UT1 (s); `None`: the crate's estimate for the instant's month.
    pub delta_t_s: Option<f64>,
}

impl Default for SpaOptions {
    fn default() -> SpaOptions {
        SpaOptions {
            height_m: 0.0,
            refraction: Some(Atmosphere::STANDARD),
            delta_t_s: None,
        }
    }
}

/// Parses an RFC 3339 instant ("2026-06-21T10:00:00Z"; an explicit offset such as "+02:00" is the
/// same instant and is converted to UTC). A time without an offset is refused: it names no instant.
pub fn parse_time_utc(text: &str) -> Result<DateTime<Utc>, SunError> {
    DateTime::parse_from_rfc3339(text.trim())
        .map(|time| time.with_timezone(&Utc))
        .map_err(|error| SunError::InvalidTime {
            text: crate::text::shown(text),
            reason: error.to_string(),
        })
}

/// An instant as RFC 3339 in UTC with a `Z` ("2026-06-21T10:00:00Z"), fractional seconds only when
/// there are some; [`parse_time_utc`] reads it back exactly.
pub fn format_time_utc(time: &DateTime<Utc>) -> String {
    time.to_rfc3339_opts(SecondsFormat::AutoSi, true)
}

/// The apparent topocentric sun position (SPA; standard atmosphere, sea level) seen from latitude
/// (° north) and longitude (° east) at `time`. See the module documentation for why apparent.
pub fn sun_position(
    latitude_deg: f64,
    longitude_deg: f64,
    time: &DateTime<Utc>,
) -> Result<SunPosition, SunError> {
    sun_position_with(latitude_deg, longitude_deg, time, &SpaOptions::default())
}

/// [`sun_position`] with another observer height, atmosphere (or none: the true position) or ΔT.
pub fn sun_position_with(
    latitude_deg: f64,
    longitude_deg: f64,
    time: &DateTime<Utc>,
    options: &SpaOptions,
) -> Result<SunPosition, SunError> {
    let failed = |reason: String| SunError::Position {
        latitude_deg,
        longitude_deg,
        time: format_time_utc(time),
        // The crate's message echoes the value whole (309 digits for 1e308).
        reason: crate::text::parser_message(&reason, 200),
    };
    let delta_t = match options.delta_t_s {
        Some(value) => value,
        None => delta_t::estimate_from_date_like(time).map_err(|e| failed(e.to_string()))?,
    };
    let refraction = options
        .refraction
        .map(|a| RefractionCorrection::new(a.pressure_hpa, a.temperature_c))
        .transpose()
        .map_err(|e| failed(e.to_string()))?;
    let location = Location {
        latitude: latitude_deg,
        longitude: longitude_deg,
    };
    let position = SolarPositions::new()
        .at(time, location, options.height_m, delta_t, refraction)
        .map_err(|e| failed(e.to_string()))?;
    Ok(SunPosition {
        elevation_deg: position.elevation_angle(),
        azimuth_deg: position.azimuth(),
    })
}

/// Unit vector toward the sun in the world frame (docs/design.md §1.7: z up, north +y, east +x, azimuth
/// clockwise from north toward east): d = (cos e sin a, cos e cos a, sin e).
pub fn sun_direction(elevation_deg: f64, azimuth_deg: f64) -> Vector3<f64> {
    let (sin_e, cos_e) = elevation_deg.to_radians().sin_cos();
    let (sin_a, cos_a) = azimuth_deg.to_radians().sin_cos();
    Vector3::new(cos_e * sin_a, cos_e * cos_a, sin_e)
}

/// Checks angles given directly: elevation finite and within [−90°, 90°] (beyond that the direction
/// would silently wrap over the zenith), azimuth finite (any value; it is periodic).
pub fn validate_sun_angles(elevation_deg: f64, azimuth_deg: f64) -> Result<(), SunError> {
    if !(elevation_deg.is_finite() && (-90.0..=90.0).contains(&elevation_deg)) {
        return Err(SunError::InvalidElevation(elevation_deg));
    }
    if !azimuth_deg.is_finite() {
        return Err(SunError::InvalidAzimuth(azimuth_deg));
    }
    Ok(())
}

/// Checks the `transmittance` τ of the default irradiance: a fraction, finite, within [0, 1].
pub fn validate_transmittance(transmittance: f64) -> Result<(), SunError> {
    if transmittance.is_finite() && (0.0..=1.0).contains(&transmittance) {
        Ok(())
    } else {
        Err(SunError::InvalidTransmittance(transmittance))
    }
}

/// Checks a given band irradiance E_sun (W·m⁻²): finite and ≥ 0.
pub fn validate_irradiance(irradiance_w_m2: f64) -> Result<(), SunError> {
    if irradiance_w_m2.is_finite() && irradiance_w_m2 >= 0.0 {
        Ok(())
    } else {
        Err(SunError::InvalidIrradiance(irradiance_w_m2))
    }
}

/// Default band irradiance of the sun on a surface facing it (W·m⁻², docs/design.md §1.7):
/// E_sun = τ Ω L_bb(5772 K), L_bb the band radiance over the band and its spectral response. The
/// band's Gauss–Legendre panels (≤ 0.5 µm) integrate Planck's law at 5772 K as well as at 300 K
/// (tested against a direct integral to 1e-6 for 3–5 and 8–14 µm). τ is taken as given: check it
/// with [`validate_transmittance`].
pub fn default_band_irradiance(band: &Band, transmittance: f64) -> f64 {
    transmittance * SUN_SOLID_ANGLE_SR * band.radiance(SUN_TEMPERATURE_K)
}

/// Uniform radiance of the disc, L_sun = E_sun / Ω (W·m⁻²·sr⁻¹), for a band irradiance E_sun.
pub fn disc_radiance(irradiance_w_m2: f64) -> f64 {
    irradiance_w_m2 / SUN_SOLID_ANGLE_SR
}

#[cfg(test)]
mod tests {
    use super::*;

    fn utc(text: &str) -> DateTime<Utc> {
        parse_time_utc(text).unwrap()
    }

    fn assert_close(actual: Vector3<f64>, expected: [f64; 3]) {
        let expected = Vector3::from(expected);
        assert!((actual - expected).norm() < 1e-15, "{actual} ≠ {expected}");
    }

    #[test]
    fn direction_follows_the_world_frame() {
        // docs/design.md §1.7: azimuth 0° is north (+y), 90° east (+x), clockwise seen from above (+z).
        assert_close(sun_direction(0.0, 0.0), [0.0, 1.0, 0.0]);
        assert_close(sun_direction(0.0, 90.0), [1.0, 0.0, 0.0]);
        assert_close(sun_direction(0.0, 180.0), [0.0, -1.0, 0.0]);
        assert_close(sun_direction(0.0, 270.0), [-1.0, 0.0, 0.0]);
        assert_close(sun_direction(90.0, 123.0), [0.0, 0.0, 1.0]);
        assert_close(sun_direction(-90.0, 0.0), [0.0, 0.0, -1.0]);
        // Elevation is the angle above the xy-plane, azimuth periodic.
        let d = sun_direction(30.0, 45.0);
        assert!((d.norm() - 1.0).abs() < 1e-15);
        assert!((d.z.asin().to_degrees() - 30.0).abs() < 1e-12);
        assert!((d.x.atan2(d.y).to_degrees() - 45.0).abs() < 1e-12);
        assert!((sun_direction(30.0, -90.0) - sun_direction(30.0, 270.0)).norm() < 1e-15);
        let p = SunPosition::new(30.0, 45.0).unwrap();
        assert_eq!(p.direction(), d);
    }

    #[test]
    fn solid_angle_is_the_cone_of_the_half_angle() {
        let half = SUN_HALF_ANGLE_DEG.to_radians();
        assert_eq!(SUN_HALF_ANGLE_DEG, 0.2665);
        // 2π(1 − cos θ) as written in docs/design.md §1.7 (cancellation costs ~1e-12 here) …
        let cone = 2.0 * std::f64::consts::PI * (1.0 - half.cos());
        assert!((SUN_SOLID_ANGLE_SR / cone - 1.0).abs() < 1e-6);
        // … and without cancellation, 4π sin²(θ/2), and the small-cap series πθ²(1 − θ²/12 + θ⁴/360).
        let exact = 4.0 * std::f64::consts::PI * (0.5 * half).sin().powi(2);
        assert!((SUN_SOLID_ANGLE_SR / exact - 1.0).abs() < 1e-14);
        let series =
            std::f64::consts::PI * half * half * (1.0 - half * half / 12.0 + half.powi(4) / 360.0);
        assert!((SUN_SOLID_ANGLE_SR / series - 1.0).abs() < 1e-14);
        // The 6.80e-5 sr quoted in docs/design.md §1.7.
        assert!((SUN_SOLID_ANGLE_SR - 6.80e-5).abs() < 0.005e-5);
        assert_eq!(disc_radiance(SUN_SOLID_ANGLE_SR), 1.0);
    }

    /// B_λ(T) (W·m⁻²·sr⁻¹·m⁻¹), written out here independently of src/optics/planck.rs.
    fn planck(lambda_m: f64, t: f64) -> f64 {
        let (h, c, k) = (6.626_070_15e-34, 299_792_458.0, 1.380_649e-23);
        2.0 * h * c * c / lambda_m.powi(5) / ((h * c / (lambda_m * k * t)).exp() - 1.0)
    }

    /// Composite Simpson over [lo, hi] µm with n (even) intervals: error ~(h⁴/180) max|f⁗|, ~1e-13
    /// relative here.
    fn simpson_band_radiance(lo_um: f64, hi_um: f64, t: f64, n: usize) -> f64 {
        let h = (hi_um - lo_um) * 1e-6 / n as f64;
        let f = |i: usize| planck(lo_um * 1e-6 + i as f64 * h, t);
        let inner: f64 = (1..n)
            .map(|i| if i % 2 == 1 { 4.0 * f(i) } else { 2.0 * f(i) })
            .sum();
        (f(0) + inner + f(n)) * h / 3.0
    }

    #[test]
    fn band_irradiance_integrates_planck_at_the_sun_temperature() {
        for (lo, hi) in [(8.0, 14.0), (3.0, 5.0)] {
            let band = Band::new(lo, hi, None).unwrap();
            let direct = simpson_band_radiance(lo, hi, SUN_TEMPERATURE_K, 20_000);
            let quadrature = band.radiance(SUN_TEMPERATURE_K);
            assert!(
                (quadrature / direct - 1.0).abs() < 1e-6,
                "{lo}–{hi} µm: band {quadrature} vs direct {direct}"
            );
            let e = default_band_irradiance(&band, 0.8);
            assert!((e / (0.8 * SUN_SOLID_ANGLE_SR * direct) - 1.0).abs() < 1e-6);
        }
        // Magnitudes: 1.50872 W·m⁻² in 8–14 µm and 21.8252 W·m⁻² in 3–5 µm at τ = 1 (a separate
        // Simpson integral in Python with the same constants); docs/design.md §2.4's example gives 1.6.
        let lwir = default_band_irradiance(&Band::lwir(), 1.0);
        assert!((lwir / 1.508_720 - 1.0).abs() < 1e-6, "{lwir}");
        let mwir = default_band_irradiance(&Band::new(3.0, 5.0, None).unwrap(), 1.0);
        assert!((mwir / 21.825_231 - 1.0).abs() < 1e-6, "{mwir}");
        assert_eq!(default_band_irradiance(&Band::lwir(), 0.0), 0.0);
    }

    #[test]
    fn nrel_spa_paper_example() {
        // Reda & Andreas (2004), Table A5.1: 2003-10-17 12:30:30 at UTC−7 (= 19:30:30Z), ΔT = 67 s,
        // 39.742476° N, 105.1786° W, 1830.14 m, 820 mbar, 11 °C → topocentric (refracted) zenith
        // 50.11162°, azimuth (eastward from north) 194.34024°.
        let time = utc("2003-10-17T12:30:30-07:00");
        assert_eq!(format_time_utc(&time), "2003-10-17T19:30:30Z");
        let options = SpaOptions {
            height_m: 1830.14,
            refraction: Some(Atmosphere {
                pressure_hpa: 820.0,
                temperature_c: 11.0,
            }),
            delta_t_s: Some(67.0),
        };
        let p = sun_position_with(39.742476, -105.1786, &time, &options).unwrap();
        assert!((90.0 - p.elevation_deg - 50.11162).abs() < 1e-5, "{p:?}");
        assert!((p.azimuth_deg - 194.34024).abs() < 1e-5, "{p:?}");
        // Refraction only lifts the sun, by the size SPA's eq. 42 gives at ~40° (~1′ at 820 mbar).
        let true_position = sun_position_with(
            39.742476,
            -105.1786,
            &time,
            &SpaOptions {
                refraction: None,
                ..options
            },
        )
        .unwrap();
        let lift = p.elevation_deg - true_position.elevation_deg;
        assert!(lift > 0.012 && lift < 0.017, "{lift}");
        assert_eq!(p.azimuth_deg, true_position.azimuth_deg);
    }

    #[test]
    fn default_position_is_apparent_for_the_standard_atmosphere() {
        // Munich on 21 June: high in the morning (~61°) and just after sunrise (~3°). Refraction
        // lifts the sun by SPA's eq. 42 scaled to the standard atmosphere, (P/1010)(283/(273 + T))
        // = 0.986 of its reference: ~33″ at 61°, a quarter of a degree near the horizon.
        for (text, low, high) in [
            ("2026-06-21T10:00:00Z", 0.008, 0.011),
            ("2026-06-21T03:30:00Z", 0.15, 0.35),
        ] {
            let time = utc(text);
            let apparent = sun_position(48.14, 11.58, &time).unwrap();
            let explicit = sun_position_with(48.14, 11.58, &time, &SpaOptions::default()).unwrap();
            assert_eq!(apparent, explicit);
            let geometric = sun_position_with(
                48.14,
                11.58,
                &time,
                &SpaOptions {
                    refraction: None,
                    ..SpaOptions::default()
                },
            )
            .unwrap();
            let e = geometric.elevation_deg;
            let eq42 = 1.02 / (60.0 * (e + 10.3 / (e + 5.11)).to_radians().tan());
            let lift = apparent.elevation_deg - e;
            assert!((lift / eq42 - 1013.25 / 1010.0 * 283.0 / 288.0).abs() < 1e-9);
            assert!(lift > low && lift < high, "{text}: e = {e}, lift {lift}");
            assert_eq!(apparent.azimuth_deg, geometric.azimuth_deg);
        }
    }

    #[test]
    fn solstice_noon_is_where_the_declination_puts_it() {
        // At the June solstice (declination +23.44°) the sun culminates due south at 90° − (φ − δ)
        // in Munich (48.14° N), due north at 90° − (δ − φ) in Sydney (33.87° S, φ = −33.87°). Search
        // the day minute by minute for the highest sun.
        let day = utc("2026-06-21T00:00:00Z");
        for (latitude, longitude, culmination, azimuth) in [
            (48.14, 11.58, 90.0 - (48.14 - 23.44), 180.0),
            (-33.87, 151.21, 90.0 - (23.44 + 33.87), 0.0),
        ] {
            let highest = (0..24 * 60)
                .map(|m| {
                    let t = day + chrono::Duration::minutes(m);
                    sun_position(latitude, longitude, &t).unwrap()
                })
                .max_by(|a, b| a.elevation_deg.total_cmp(&b.elevation_deg))
                .unwrap();
            // 0.05° allows for the refraction lift (≤ 0.03° above 30°), the declination's change
            // within the day and the minute grid.
            assert!(
                (highest.elevation_deg - culmination).abs() < 0.05,
                "{latitude}: {highest:?} vs {culmination}"
            );
            let off = (highest.azimuth_deg - azimuth + 180.0).rem_euclid(360.0) - 180.0;
            assert!(off.abs() < 1.0, "{latitude}: {highest:?}");
            // The direction of the noon sun leans toward the equator: −y (south) or +y (north).
            assert!(highest.direction().y * (azimuth - 90.0).signum() < 0.0);
        }
        // And rises north of east in the northern summer (azimuth < 90°).
        let morning = sun_position(48.14, 11.58, &utc("2026-06-21T04:00:00Z")).unwrap();
        assert!(
            morning.elevation_deg > 0.0 && morning.azimuth_deg < 90.0,
            "{morning:?}"
        );
    }

    #[test]
    fn times_are_rfc3339_instants() {
        assert_eq!(
            utc("2026-06-21T10:00:00Z"),
            utc("2026-06-21T12:00:00+02:00")
        );
        assert_eq!(
            format_time_utc(&utc("2026-06-21T12:00:00+02:00")),
            "2026-06-21T10:00:00Z"
        );
        let fraction = utc("2026-06-21T10:00:00.25Z");
        assert_eq!(format_time_utc(&fraction), "2026-06-21T10:00:00.250Z");
        assert_eq!(utc(&format_time_utc(&fraction)), fraction);
        for bad in [
            "",
            "yesterday",
            "2026-06-21",
            "2026-06-21T10:00:00",
            "2026-06-21T10:00Z",
            "2026-13-01T00:00:00Z",
            "2026-02-30T00:00:00Z",
            "2026-06-21T25:00:00Z",
        ] {
            let error = parse_time_utc(bad).unwrap_err();
            assert!(
                error.to_string().contains("RFC 3339") && error.to_string().contains(bad),
                "{bad}: {error}"
            );
        }
    }

    #[test]
    fn bad_inputs_are_refused_with_a_reason() {
        let time = utc("2026-06-21T10:00:00Z");
        for (lat, lon) in [
            (91.0, 0.0),
            (f64::NAN, 0.0),
            (0.0, 181.0),
            (0.0, f64::INFINITY),
        ] {
            let error = sun_position(lat, lon, &time).unwrap_err();
            assert!(matches!(error, SunError::Position { .. }), "{error}");
            assert!(error.to_string().contains("invalid l"), "{error}");
        }
        // SPA's ΔT estimate and the algorithm itself have ranges.
        assert!(sun_position(0.0, 0.0, &utc("9999-01-01T00:00:00Z")).is_err());
        assert!(validate_sun_angles(35.0, 200.0).is_ok());
        assert!(validate_sun_angles(-90.0, -720.0).is_ok());
        assert!(matches!(
            validate_sun_angles(f64::NAN, 0.0),
            Err(SunError::InvalidElevation(_))
        ));
        assert!(validate_sun_angles(90.5, 0.0).is_err());
        assert!(validate_sun_angles(f64::INFINITY, 0.0).is_err());
        assert!(matches!(
            validate_sun_angles(10.0, f64::NEG_INFINITY),
            Err(SunError::InvalidAzimuth(_))
        ));
        assert!(SunPosition::new(10.0, f64::NAN).is_err());
        assert!(validate_transmittance(0.8).is_ok() && validate_transmittance(1.0).is_ok());
        for bad in [-0.1, 1.1, f64::NAN] {
            assert!(validate_transmittance(bad).is_err());
        }
        assert!(validate_irradiance(0.0).is_ok() && validate_irradiance(1.6).is_ok());
        for bad in [-1.0, f64::INFINITY, f64::NAN] {
            assert!(validate_irradiance(bad).is_err());
        }
    }
}
