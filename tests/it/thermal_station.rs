//! EPW and TMY3 weather (docs/design.md §2.5): the shipped samples read, hour-ending labels placed,
//! TMY3 equal to the same data as EPW, the cloud laws where fields are missing, refusals by file
//! and line, and a cloudy day cooling a sunlit plate by what its energy balance predicts.

use crate::common;

use common::{thermal_plate_scene, write_scene};
use irpol::optics::STEFAN_BOLTZMANN;
use irpol::progress::Silent;
use irpol::scene::load_scene;
use irpol::thermal_scene::solve_scene;
use irpol::weather::epw;
use irpol::weather::station::{clark_allen_longwave_w_m2, Field};
use irpol::weather::{Site, StationFormat, StationWeather, Weather};
use std::path::{Path, PathBuf};

fn sample(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("data/weather")
        .join(name)
}

fn epw_sample() -> StationWeather {
    StationWeather::read(&sample("munich_3days.epw"), StationFormat::Epw, None).unwrap()
}

fn at_file_site(file: &StationWeather) -> Site {
    Site {
        latitude_deg: file.station.latitude_deg,
        longitude_deg: file.station.longitude_deg,
        start_utc: file.first_utc(),
    }
}

/// The sample's text with `edit` applied to the fields (0-based) of data rows.
fn edited_epw(edit: impl Fn(usize, &mut Vec<String>)) -> String {
    let text = std::fs::read_to_string(sample("munich_3days.epw")).unwrap();
    let mut out = String::new();
    for (i, line) in text.lines().enumerate() {
        if i < 8 {
            out.push_str(line);
        } else {
            let mut fields: Vec<String> = line.split(',').map(str::to_owned).collect();
            edit(i - 8, &mut fields);
            out.push_str(&fields.join(","));
        }
        out.push('\n');
    }
    out
}

fn parse_epw(text: &str) -> Result<StationWeather, irpol::weather::WeatherError> {
    StationWeather::parse(
        Path::new("w.epw"),
        text.as_bytes(),
        StationFormat::Epw,
        None,
    )
}

#[test]
fn the_sample_epw_is_read_with_its_site_and_hour_ending_labels() {
    let file = epw_sample();
    assert_eq!(file.records.len(), 72);
    let s = file.station;
    assert_eq!(
        (
            s.latitude_deg,
            s.longitude_deg,
            s.time_zone_h,
            s.elevation_m
        ),
        (48.14, 11.58, 1.0, 519.0)
    );
    // Line 9 is 2026-06-20 hour 1 local standard time (UTC+1): 00:00 UTC.
    let first = &file.records[0];
    assert_eq!(first.line, 9);
    assert_eq!(first.end_utc.to_rfc3339(), "2026-06-20T00:00:00+00:00");
    assert_eq!(first.values[Field::DryBulb as usize], Some(14.6));
    assert_eq!(first.values[Field::Pressure as usize], Some(95500.0));
    assert_eq!(first.values[Field::Infrared as usize], Some(320.0));
    // Line 21: hour 13 of 20 June (12:00–13:00 local, 11:00–12:00 UTC), DNI 938, DHI 124.
    let r = &file.records[12];
    assert_eq!(r.end_utc.to_rfc3339(), "2026-06-20T12:00:00+00:00");
    assert_eq!(r.values[Field::DirectNormal as usize], Some(938.0));
    let last = &file.records[71];
    assert_eq!(last.end_utc.to_rfc3339(), "2026-06-22T23:00:00+00:00");
    assert_eq!(file.last_utc().to_rfc3339(), "2026-06-22T22:30:00+00:00");
}

#[test]
fn state_sits_at_the_label_and_radiation_at_the_half_hour_linear_between() {
    let file = epw_sample();
    let weather = file.to_weather(&at_file_site(&file), None).unwrap();
    let (first, last) = weather.span_s();
    assert!(
        first == 0.0 && (last - 70.5 * 3600.0).abs() < 1e-6,
        "{last}"
    );
    let value = |i: usize, f: Field| file.records[i].values[f as usize].unwrap();
    // Air at the label of row 12 (12 h after the first label) is the file's.
    let noon = weather.at(12.0 * 3600.0).unwrap();
    assert!((noon.air_k - (value(12, Field::DryBulb) + 273.15)).abs() < 1e-12);
    // DNI of row 12 sits 30 min before its label; between knots it is linear.
    let mid = weather.at(11.5 * 3600.0).unwrap();
    assert_eq!(mid.direct_normal_w_m2, value(12, Field::DirectNormal));
    assert_eq!(mid.longwave_down_w_m2, value(12, Field::Infrared));
    let quarter = weather.at(11.75 * 3600.0).unwrap();
    let expected = 0.75 * value(12, Field::DirectNormal) + 0.25 * value(13, Field::DirectNormal);
    assert!((quarter.direct_normal_w_m2 - expected).abs() < 1e-9);
    let air = 0.25 * value(11, Field::DryBulb) + 0.75 * value(12, Field::DryBulb) + 273.15;
    assert!(
        (quarter.air_k - air).abs() < 1e-9,
        "{} {air}",
        quarter.air_k
    );
    assert_eq!(noon.wind_m_s, 2.0);
}

#[test]
fn tmy3_reads_as_the_same_data_written_as_epw() {
    let tmy3 =
        StationWeather::read(&sample("munich_3days_tmy3.csv"), StationFormat::Tmy3, None).unwrap();
    let epw_file = epw_sample();
    assert_eq!(tmy3.station, epw_file.station);
    assert_eq!(tmy3.records.len(), epw_file.records.len());
    for (a, b) in tmy3.records.iter().zip(&epw_file.records) {
        assert_eq!(a.end_utc, b.end_utc);
        for field in Field::ALL {
            if field != Field::Infrared {
                assert_eq!(
                    a.values[field as usize], b.values[field as usize],
                    "{field:?}"
                );
            }
        }
        assert_eq!(a.values[Field::Infrared as usize], None);
    }
    // The TMY3 records written as EPW and read back give the same weather, row for row.
    let text = epw::write(&tmy3.station, &tmy3.records, "test");
    let again = parse_epw(&text).unwrap();
    let site = at_file_site(&tmy3);
    let (w1, w2) = (
        tmy3.to_weather(&site, None).unwrap(),
        again.to_weather(&site, None).unwrap(),
    );
    assert_eq!(w1.span_s(), w2.span_s());
    let mut t = 0.0;
    while t <= w1.span_s().1 {
        let (a, b) = (w1.at(t).unwrap(), w2.at(t).unwrap());
        assert_eq!(
            (
                a.air_k,
                a.wind_m_s,
                a.direct_normal_w_m2,
                a.diffuse_horizontal_w_m2
            ),
            (
                b.air_k,
                b.wind_m_s,
                b.direct_normal_w_m2,
                b.diffuse_horizontal_w_m2
            )
        );
        assert_eq!(a.longwave_down_w_m2, b.longwave_down_w_m2);
        assert_eq!(a.sun_direction, b.sun_direction);
        t += 900.0;
    }
}

#[test]
fn a_missing_infrared_is_clark_and_allen_and_matches_the_files_own() {
    // Field 13 (infrared) missing everywhere.
    let text = edited_epw(|_, f| f[12] = "9999".into());
    let file = parse_epw(&text).unwrap();
    let weather = file.to_weather(&at_file_site(&file), None).unwrap();
    let sample_file = epw_sample();
    let mut worst: f64 = 0.0;
    for (i, r) in file.records.iter().enumerate().take(70) {
        let v = |f: Field| r.values[f as usize].unwrap();
        let lw = weather.at(i as f64 * 3600.0).unwrap().longwave_down_w_m2;
        let law = clark_allen_longwave_w_m2(
            v(Field::DryBulb) + 273.15,
            v(Field::DewPoint) + 273.15,
            v(Field::OpaqueCover),
        );
        assert!((lw - law).abs() < 1e-9, "row {i}: {lw} vs {law}");
        // The sample's infrared is the script's own Clark–Allen at the half hour (Python), from
        // its smooth air curve; where the cover jumps between labels the two differ by design.
        let next = &file.records[i + 1];
        if next.values[Field::OpaqueCover as usize] != r.values[Field::OpaqueCover as usize] {
            continue;
        }
        let mid = weather
            .at((i as f64 + 0.5) * 3600.0)
            .unwrap()
            .longwave_down_w_m2;
        let file_ir = sample_file.records[i + 1].values[Field::Infrared as usize].unwrap();
        worst = worst.max((mid - file_ir).abs() / file_ir);
    }
    assert!(worst < 0.01, "worst relative difference {worst}");
}

#[test]
fn missing_sunlight_on_the_overcast_day_is_kasten_and_czeplak() {
    // DNI, DHI missing on day 2 (rows 24…47): the overcast law, N = 1, gives all diffuse, G/4.
    let text = edited_epw(|i, f| {
        if (24..48).contains(&i) {
            f[14] = "9999".into();
            f[15] = "9999".into();
        }
    });
    let file = parse_epw(&text).unwrap();
    let weather = file.to_weather(&at_file_site(&file), None).unwrap();
    let sample_file = epw_sample();
    for i in 30..44 {
        let w = weather.at((i as f64 + 0.5) * 3600.0).unwrap();
        let file_dhi = sample_file.records[i + 1].values[Field::DiffuseHorizontal as usize];
        let file_dhi = file_dhi.unwrap();
        assert!(w.direct_normal_w_m2.abs() < 1e-9);
        // The file holds the hour's mean of the same law; irpol evaluates at the half hour.
        assert!(
            (w.diffuse_horizontal_w_m2 - file_dhi).abs() < 0.02 * file_dhi + 1.0,
            "hour {i}: {} vs {file_dhi}",
            w.diffuse_horizontal_w_m2
        );
    }
}

#[test]
fn missing_values_the_run_needs_are_refused_by_line_and_field_others_ignored() {
    // The dry bulb of line 30 (row 21, 2026-06-20 22:00 local) missing.
    let text = edited_epw(|i, f| {
        if i == 21 {
            f[6] = "99.9".into();
        }
    });
    let file = parse_epw(&text).unwrap();
    let site = at_file_site(&file);
    let error = file.to_weather(&site, None).unwrap_err().to_string();
    assert_eq!(
        error,
        "w.epw:30: field 7 (dry bulb temperature (°C)) is missing at 2026-06-20 22:00 local \
         standard time and the run needs it: fill it in (e.g. from the neighbouring hours) or \
         move the run off it"
    );
    // A run of the first 12 hours does not need it.
    let weather = file.to_weather(&site, Some(12.0 * 3600.0)).unwrap();
    assert!(weather.span_s().1 >= 12.0 * 3600.0 && weather.span_s().1 < 13.0 * 3600.0);
}

#[test]
fn bad_files_are_refused_by_line_with_what_to_fix() {
    let cases: Vec<(String, &str)> = vec![
        (
            edited_epw(|i, f| {
                if i == 3 {
                    f[21] = "abc".into()
                }
            }),
            "w.epw:12: field 22 (wind speed (m/s)): 'abc' is not a number",
        ),
        (
            edited_epw(|i, f| {
                if i == 5 {
                    f[6] = "85".into()
                }
            }),
            "w.epw:14: field 7 (dry bulb temperature (°C)): 85 is outside -90…70 (mark a missing \
             value with 99.9)",
        ),
        (
            edited_epw(|i, f| {
                if i == 10 {
                    f[0] = "2025".into()
                }
            }),
            "w.epw:19: the row for 2025-06-20 11:00 does not follow the row for 2026-06-20 10:00 \
             on line 18 by one hour",
        ),
        (
            "LOCATION,x\n".into(),
            "w.epw:1: the first line must be LOCATION",
        ),
    ];
    for (text, expected) in cases {
        let error = parse_epw(&text).unwrap_err().to_string();
        assert!(error.starts_with(expected), "{error}\nexpected {expected}");
    }
    // A typical-year file's mixed years are read in one year when asked.
    let mixed = edited_epw(|i, f| f[0] = if i < 24 { "1999" } else { "2005" }.into());
    assert!(parse_epw(&mixed).is_err());
    let file = StationWeather::parse(
        Path::new("w.epw"),
        mixed.as_bytes(),
        StationFormat::Epw,
        Some(2026),
    )
    .unwrap();
    assert_eq!(file.records[30].end_utc, epw_sample().records[30].end_utc);
}

/// The header is told by its keywords, not counted: without its DATA PERIODS line (or with a
/// third COMMENTS line) an EPW keeps every hourly row (issue 42: the first row was skipped unread).
#[test]
fn epw_header_lines_are_recognised_by_content_not_counted() {
    let text = std::fs::read_to_string(sample("munich_3days.epw")).unwrap();
    let full = parse_epw(&text).unwrap();
    let without: String = text
        .lines()
        .filter(|l| !l.starts_with("DATA PERIODS"))
        .map(|l| format!("{l}\n"))
        .collect();
    let read = parse_epw(&without).unwrap();
    assert_eq!(read.records.len(), full.records.len());
    assert_eq!(read.records[0].end_utc, full.records[0].end_utc);
    assert_eq!(read.records[0].values, full.records[0].values);
    assert_eq!(read.records[0].line, full.records[0].line - 1);
    let extra = text.replacen("COMMENTS 2,", "COMMENTS 2,\nCOMMENTS 3,more", 1);
    assert_eq!(parse_epw(&extra).unwrap().records.len(), full.records.len());
    // Only LOCATION: the data rows still start on line 2 and are read whole.
    let bare: String = text
        .lines()
        .enumerate()
        .filter(|(i, l)| *i == 0 || l.starts_with(|c: char| c.is_ascii_digit()))
        .map(|(_, l)| format!("{l}\n"))
        .collect();
    let read = parse_epw(&bare).unwrap();
    assert_eq!(read.records.len(), full.records.len());
    assert_eq!(read.records[0].line, 2);
}

/// The sample file's weather in a scene of one sunlit horizontal plate, with the site and start
/// from the file.
fn plate_scene(dir: &Path) -> PathBuf {
    let weather = sample("munich_3days.epw");
    let text = thermal_plate_scene(|t| {
        t.replace(
            "weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }\n\
             start_utc = \"2026-06-21T00:00:00Z\"\nlatitude_deg = 48.14\nlongitude_deg = 11.58\n",
            &format!("weather = {:?}\n", weather.display().to_string()),
        )
        .replace("duration_h = 2", "duration_h = 36")
        .replace(
            "solar_absorptance = 0.6",
            "solar_absorptance = 0.6\nemissivity = 0.9",
        )
    });
    assert!(text.contains("munich_3days.epw") && !text.contains("start_utc"));
    write_scene(dir, &text)
}

/// The quasi-steady surface temperature of a thin adiabatic horizontal plate under `w`: the root
/// of α(E_dn sin h + E_dh) + ε E_lw − εσT⁴ + h_c (T_air − T) = 0 (McAdams h_c = 5.7 + 3.8 v).
fn steady_plate_k(w: &irpol::weather::WeatherSample) -> (f64, f64) {
    let (alpha, eps) = (0.6, 0.9);
    let absorbed =
        alpha * (w.direct_normal_w_m2 * w.sun_direction.z.max(0.0) + w.diffuse_horizontal_w_m2);
    let h = 5.7 + 3.8 * w.wind_m_s;
    let net = |t: f64| {
        absorbed + eps * w.longwave_down_w_m2 - eps * STEFAN_BOLTZMANN * t.powi(4)
            + h * (w.air_k - t)
    };
    let (mut lo, mut hi) = (200.0, 450.0);
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if net(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let t = 0.5 * (lo + hi);
    (t, absorbed)
}

#[test]
fn an_overcast_noon_cools_a_sunlit_plate_by_what_the_balance_predicts() {
    let dir = tempfile::tempdir().unwrap();
    let scene = load_scene(&plate_scene(dir.path())).unwrap();
    let setup = scene.thermal.as_ref().unwrap();
    // The site and the start came from the file: 2026-06-20T00:00Z at 48.14 N, 11.58 E.
    assert_eq!(
        setup.site.start_utc.to_rfc3339(),
        "2026-06-20T00:00:00+00:00"
    );
    assert_eq!(setup.site.latitude_deg, 48.14);
    // 11:00 UTC is near solar noon (about 11:14 UTC at 11.58° E): clear day 1, overcast day 2.
    let (clear_s, cloudy_s) = (11.0 * 3600.0, 35.0 * 3600.0);
    let solution = solve_scene(&scene, &[clear_s, cloudy_s], &Silent).unwrap();
    let record = |t: f64| solution.times_s.iter().position(|&s| s == t).unwrap();
    let plate = |t: f64| solution.surface_k[record(t)][0];
    let weather: &Weather = &setup.weather;
    let (clear_w, cloudy_w) = (weather.at(clear_s).unwrap(), weather.at(cloudy_s).unwrap());
    let (clear_ss, clear_abs) = steady_plate_k(&clear_w);
    let (cloudy_ss, cloudy_abs) = steady_plate_k(&cloudy_w);
    // A 1 mm steel plate (3.7 kJ m⁻² K⁻¹) under ~20 W m⁻² K⁻¹ follows its steady state within a
    // time constant of ~3 min; the forcing drifts by < 3 K/h at noon, so the lag is < 0.2 K.
    let (t_clear, t_cloudy) = (plate(clear_s), plate(cloudy_s));
    assert!((t_clear - clear_ss).abs() < 0.5, "{t_clear} vs {clear_ss}");
    assert!(
        (t_cloudy - cloudy_ss).abs() < 0.5,
        "{t_cloudy} vs {cloudy_ss}"
    );
    // The linearized balance: ΔT ≈ q_cloudy(T_clear) / (4εσT_clear³ + h_cloudy), the overcast
    // net flux at the clear noon's temperature (dominated by the ~440 W/m² of sunlight lost, less
    // the warmer sky) over the total conductance; T⁴'s curvature makes it ~5 % off.
    let h_cloudy = 5.7 + 3.8 * cloudy_w.wind_m_s;
    let q = cloudy_abs + 0.9 * cloudy_w.longwave_down_w_m2
        - 0.9 * STEFAN_BOLTZMANN * t_clear.powi(4)
        + h_cloudy * (cloudy_w.air_k - t_clear);
    let linear = q / (4.0 * 0.9 * STEFAN_BOLTZMANN * t_clear.powi(3) + h_cloudy);
    let change = t_cloudy - t_clear;
    assert!(cloudy_abs < clear_abs - 300.0, "{clear_abs} → {cloudy_abs}");
    assert!(
        change < -10.0,
        "the overcast noon is only {change} K cooler"
    );
    assert!(
        (change - linear).abs() < 0.2 * linear.abs(),
        "model {change} K, linearized balance {linear} K"
    );
    eprintln!(
        "clear noon {t_clear:.2} K (steady {clear_ss:.2}), overcast {t_cloudy:.2} K (steady \
         {cloudy_ss:.2}); absorbed {clear_abs:.0} → {cloudy_abs:.0} W/m²; ΔT {change:.2} K, \
         linearized {linear:.2} K"
    );
}

#[test]
fn a_csv_weather_still_needs_the_site_and_start() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("w.csv"),
        "time_s,air_temperature_k\n0,288\n7200,290\n",
    )
    .unwrap();
    let text = thermal_plate_scene(|t| {
        t.replace(
            "weather = { clear_day = { air_min_k = 287.0, air_max_k = 301.0, wind_m_s = 2.0 } }\n\
             start_utc = \"2026-06-21T00:00:00Z\"\n",
            "weather = \"w.csv\"\n",
        )
    });
    let error = load_scene(&write_scene(dir.path(), &text))
        .unwrap_err()
        .to_string();
    assert!(
        error.contains("thermal.start_utc is required with a weather CSV or a clear day"),
        "{error}"
    );
}
