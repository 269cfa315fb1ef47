//! The thermal model's weather (docs/design.md §1.8, §2.5): the weather CSV read and refused with
//! file:line:column, interpolation in time, and the built-in clear day.

use irpol::emitter::{parse_time_utc, sun_direction, sun_position};
use irpol::weather::{
    simplified_solis, swinbank_longwave_w_m2, ClearDay, Site, SolisAtmosphere, Weather,
    WeatherError,
};
use std::path::{Path, PathBuf};

fn munich(start: &str) -> Site {
    Site {
        latitude_deg: 48.14,
        longitude_deg: 11.58,
        start_utc: parse_time_utc(start).unwrap(),
    }
}

/// Writes `text` as `name` in a fresh folder and reads it as weather at Munich from midnight UTC.
fn read(name: &str, text: &str) -> (Result<Weather, WeatherError>, PathBuf, tempfile::TempDir) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    let weather = Weather::read_csv(&path, &munich("2026-06-21T00:00:00Z"));
    (weather, path, dir)
}

/// The message of a refused file, with its path replaced by `FILE`.
fn refusal(text: &str) -> String {
    let (weather, path, _dir) = read("w.csv", text);
    let error = weather.expect_err("the file should be refused");
    assert!(matches!(error, WeatherError::Csv { .. }), "{error}");
    error
        .to_string()
        .replace(&path.display().to_string(), "FILE")
}

#[test]
fn a_full_file_is_read_with_its_columns_in_any_order() {
    let text = "# Munich, a made-up afternoon\n\
                wind_speed_m_s, time_s,air_temperature_k,direct_normal_w_m2,\
                diffuse_horizontal_w_m2,longwave_down_w_m2,sun_azimuth_deg,sun_elevation_deg\n\
                2,0,290,800,100,330,180,60\n\
                \n\
                # a comment between rows\n\
                4,3600,296,600,120,340,240,40\n";
    let (weather, _path, _dir) = read("w.csv", text);
    let weather = weather.unwrap();
    assert_eq!(weather.span_s(), (0.0, 3600.0));
    let first = weather.at(0.0).unwrap();
    assert_eq!(
        (first.air_k, first.wind_m_s, first.direct_normal_w_m2),
        (290.0, 2.0, 800.0)
    );
    assert_eq!(
        (first.diffuse_horizontal_w_m2, first.longwave_down_w_m2),
        (100.0, 330.0)
    );
    assert_eq!(first.sun_direction, sun_direction(60.0, 180.0));
    let half = weather.at(1800.0).unwrap();
    assert!((half.air_k - 293.0).abs() < 1e-12 && (half.wind_m_s - 3.0).abs() < 1e-12);
    assert!((half.direct_normal_w_m2 - 700.0).abs() < 1e-12);
    assert!((half.diffuse_horizontal_w_m2 - 110.0).abs() < 1e-12);
    assert!((half.longwave_down_w_m2 - 335.0).abs() < 1e-12);
    let mean = (sun_direction(60.0, 180.0) + sun_direction(40.0, 240.0)).normalize();
    assert!((half.sun_direction - mean).norm() < 1e-15);
}

#[test]
fn absent_columns_take_their_defaults() {
    let text = "time_s,air_temperature_k\n0,288\n600,290\n";
    let (weather, _path, _dir) = read("w.csv", text);
    let weather = weather.unwrap();
    let first = weather.at(0.0).unwrap();
    assert_eq!(first.wind_m_s, 0.0);
    assert_eq!(first.direct_normal_w_m2, 0.0);
    assert_eq!(first.diffuse_horizontal_w_m2, 0.0);
    // Swinbank: 5.31e-13 · 288⁶ = 303.00 W m⁻².
    assert_eq!(first.longwave_down_w_m2, swinbank_longwave_w_m2(288.0));
    assert!((first.longwave_down_w_m2 - 303.0048).abs() < 1e-4);
    // The sun from the SPA at the site and start_utc + time_s: midnight in Munich, below.
    let spa = sun_position(
        48.14,
        11.58,
        &parse_time_utc("2026-06-21T00:10:00Z").unwrap(),
    )
    .unwrap();
    assert_eq!(weather.at(600.0).unwrap().sun_direction, spa.direction());
    assert!(spa.direction().z < 0.0);
}

#[test]
fn bad_files_are_refused_with_file_line_and_column() {
    let header = "time_s,air_temperature_k,wind_speed_m_s\n";
    for (text, expected) in [
        (
            "air_temperature_k,wind_speed_m_s\n290,1\n291,1\n".to_string(),
            "FILE:1:1: missing required column 'time_s'",
        ),
        (
            format!("{header}0,290,1\n# c\n\n600,291,1\n300,292,1\n"),
            "FILE:6:1: column 'time_s': 300 s is not after 600 s on line 5; times must be \
             strictly ascending",
        ),
        (
            "# a\r\n\r\ntime_s,air_temperature_k,wind_speed_m_s\r\n# b\r\n0,290,1\r\n# c\r\n\
             600,291,x\r\n"
                .to_string(),
            "FILE:7:9: column 'wind_speed_m_s': 'x' is not a number",
        ),
        (
            format!("{header}0,290,1\n0,291,1\n"),
            "FILE:3:1: column 'time_s': 0 s is not after 0 s on line 2; times must be strictly \
             ascending",
        ),
        (
            "time_s,air_temperature_k,sun_azimuth_deg\n0,290,180\n600,291,180\n".to_string(),
            "FILE:1:26: column 'sun_azimuth_deg' without 'sun_elevation_deg': give both sun \
             angles or neither (then the sun comes from the site and the time)",
        ),
        (
            "time_s,air_temperature_k,Wind_Speed_m_s\n0,290,1\n600,291,1\n".to_string(),
            "FILE:1:26: unknown column 'Wind_Speed_m_s' (column names are case-sensitive: did \
             you mean 'wind_speed_m_s'?)",
        ),
        (
            "time_s,air_temperature_k,humidity\n0,290,1\n600,291,1\n".to_string(),
            "FILE:1:26: unknown column 'humidity' (expected time_s, air_temperature_k, \
             wind_speed_m_s, direct_normal_w_m2, diffuse_horizontal_w_m2, longwave_down_w_m2, \
             sun_elevation_deg, sun_azimuth_deg)",
        ),
        (
            format!("{header}0,290,1\n600, 29l ,1\n"),
            "FILE:3:6: column 'air_temperature_k': '29l' is not a number",
        ),
        (
            format!("{header}0,290,1\n600,291,-0.5\n"),
            "FILE:3:9: column 'wind_speed_m_s': -0.5 m/s is outside 0…150 m/s",
        ),
        (
            format!("{header}0,NaN,1\n600,291,1\n"),
            "FILE:2:3: column 'air_temperature_k': 'NaN' is not a finite number",
        ),
        (
            format!("{header}0,0,1\n600,291,1\n"),
            "FILE:2:3: column 'air_temperature_k': 0 K is outside (0, 10000] K",
        ),
        (
            format!("{header}0,290,\n600,291,1\n"),
            "FILE:2:7: column 'wind_speed_m_s' is empty, expected a number",
        ),
        (
            format!("{header}0,290,1,7\n600,291,1\n"),
            "FILE:2:9: the row has 4 fields, the header row has 3",
        ),
        (
            "time_s,air_temperature_k,direct_normal_w_m2\n0,290,-1\n600,291,0\n".to_string(),
            "FILE:2:7: column 'direct_normal_w_m2': -1 W/m² is outside 0…100000 W/m² (an irradiance)",
        ),
        (
            "time_s,air_temperature_k,sun_elevation_deg,sun_azimuth_deg\n0,290,91,0\n".to_string(),
            "FILE:2:7: column 'sun_elevation_deg': 91° is outside [-90°, 90°]",
        ),
        (
            "time_s,air_temperature_k,sun_elevation_deg,sun_azimuth_deg\n0,290,0,0\n\
             600,291,0,180\n"
                .to_string(),
            "FILE:3:9: the sun is opposite to where it is on line 2: no interpolation between \
             them, add rows in between",
        ),
        (
            format!("{header}0,290,1\n"),
            "FILE:2:1: 1 data row(s): the weather needs at least two rows to interpolate between",
        ),
        (
            "# only a comment\n".to_string(),
            "FILE:1:1: no header row: the file is empty or only comments",
        ),
        (
            "time_s,air_temperature_k,time_s\n".to_string(),
            "FILE:1:26: duplicate column 'time_s' (already column 1)",
        ),
        (
            format!("{header}0,290,1\n1e14,291,1\n"),
            "FILE:3:1: time_s 1e14 s after start_utc 2026-06-21T00:00:00Z is not an instant irpol \
             can represent",
        ),
        (
            "time_s,air_temperature_k,sun_elevation_deg,sun_azimuth_deg\n0,290,1,2\n1e16,291,1,2\n"
                .to_string(),
            "FILE:3:1: column 'time_s': 1e16 s is beyond ±1e15 s (31.7 million years) from \
             start_utc",
        ),
    ] {
        assert_eq!(refusal(&text), expected, "{text}");
    }
    // Invalid UTF-8 names its line.
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("bin.csv");
    std::fs::write(&path, b"time_s,air_temperature_k\n0,2\xff9\n").unwrap();
    let error = Weather::read_csv(&path, &munich("2026-06-21T00:00:00Z")).unwrap_err();
    assert!(
        error
            .to_string()
            .ends_with("bin.csv:2:1: invalid UTF-8: a weather CSV must be UTF-8 text"),
        "{error}"
    );
}

#[test]
fn a_missing_file_and_a_bad_site_are_one_line() {
    let missing = Weather::read_csv(Path::new("no/such.csv"), &munich("2026-06-21T00:00:00Z"));
    let text = missing.unwrap_err().to_string();
    assert!(
        text.starts_with("no/such.csv: cannot read the weather file: "),
        "{text}"
    );
    let mut site = munich("2026-06-21T00:00:00Z");
    site.latitude_deg = 91.0;
    let day = ClearDay {
        air_min_k: 281.0,
        air_max_k: 293.0,
        wind_m_s: 2.0,
    };
    let error = Weather::clear_day(&day, &site, 3600.0).unwrap_err();
    assert!(error.to_string().contains("latitude 91°"), "{error}");
    for (bad, needle) in [
        (
            ClearDay {
                air_min_k: 300.0,
                ..day
            },
            "air_min_k = 300 K is above air_max_k = 293 K",
        ),
        (
            ClearDay {
                air_min_k: -1.0,
                ..day
            },
            "air_min_k = -1 K is outside (0, 10000] K",
        ),
        (
            ClearDay {
                wind_m_s: f64::NAN,
                ..day
            },
            "wind_m_s = NaN is outside 0…150 m/s",
        ),
    ] {
        let error = Weather::clear_day(&bad, &munich("2026-06-21T00:00:00Z"), 3600.0);
        let text = error.unwrap_err().to_string();
        assert!(
            text.starts_with("clear day: ") && text.contains(needle),
            "{text}"
        );
    }
    // Beyond the SPA's ΔT estimate: the sun's failure, as one line.
    let error = Weather::clear_day(&day, &munich("9999-06-21T00:00:00Z"), 3600.0).unwrap_err();
    let text = error.to_string();
    assert!(
        text.starts_with("clear day: no sun position at latitude 48.14°") && !text.contains('\n'),
        "{text}"
    );
    let error = Weather::clear_day(&day, &munich("2026-06-21T00:00:00Z"), -1.0).unwrap_err();
    assert!(error.to_string().contains("duration -1 s"), "{error}");
}

const DAY: ClearDay = ClearDay {
    air_min_k: 281.0,
    air_max_k: 293.0,
    wind_m_s: 2.0,
};

#[test]
fn clear_day_in_munich_at_midsummer() {
    let site = munich("2026-06-21T00:00:00Z");
    let weather = Weather::clear_day(&DAY, &site, 48.0 * 3600.0).unwrap();
    assert_eq!(weather.span_s(), (0.0, 48.0 * 3600.0));
    let minute = |m: i64| weather.at(60.0 * m as f64).unwrap();
    // Minimum at sunrise, 03:12 UTC (05:12 CEST); maximum at 15:00 apparent solar time = transit
    // (11:16 UTC) + 3 h = 14:16 UTC. Search the first day minute by minute.
    let first_day: Vec<f64> = (0..24 * 60).map(|m| minute(m).air_k).collect();
    let argmin = (0..first_day.len())
        .min_by(|&a, &b| first_day[a].total_cmp(&first_day[b]))
        .unwrap();
    let argmax = (0..first_day.len())
        .max_by(|&a, &b| first_day[a].total_cmp(&first_day[b]))
        .unwrap();
    assert!(
        (argmin as i64 - (3 * 60 + 12)).abs() <= 5,
        "minimum at minute {argmin}"
    );
    assert!(
        (argmax as i64 - (14 * 60 + 16)).abs() <= 5,
        "maximum at minute {argmax}"
    );
    // Extremes reached to within the 5-minute rows' sampling of a flat-topped cosine.
    assert!((first_day[argmin] - 281.0).abs() < 0.01 && (first_day[argmax] - 293.0).abs() < 0.01);
    // Same again the next day.
    assert!((minute(24 * 60 + 14 * 60 + 16).air_k - 293.0).abs() < 0.01);
    // Night: no sun, no solar irradiance; constant wind; Swinbank everywhere.
    for m in [0, 60, 23 * 60, 24 * 60 + 60] {
        let night = minute(m);
        assert!(night.sun_direction.z < 0.0);
        assert_eq!(night.direct_normal_w_m2, 0.0);
        assert_eq!(night.diffuse_horizontal_w_m2, 0.0);
    }
    for k in 0..=576 {
        let row = weather.at(300.0 * k as f64).unwrap();
        assert_eq!(row.wind_m_s, 2.0);
        assert_eq!(row.longwave_down_w_m2, swinbank_longwave_w_m2(row.air_k));
    }
    // Noon: rows are the Solis model at the SPA's apparent elevation; the global horizontal the
    // solver sees, DNI sin h + DHI, is within 1.5 % of Solis's own GHI at this height.
    let noon_time = parse_time_utc("2026-06-21T11:15:00Z").unwrap();
    let noon = weather.at(11.25 * 3600.0).unwrap();
    let sun = sun_position(48.14, 11.58, &noon_time).unwrap();
    let solis = simplified_solis(sun.elevation_deg, &SolisAtmosphere::DEFAULT);
    assert_eq!(noon.direct_normal_w_m2, solis.direct_normal_w_m2);
    assert_eq!(noon.diffuse_horizontal_w_m2, solis.diffuse_horizontal_w_m2);
    assert!((noon.sun_direction - sun.direction()).norm() < 1e-15);
    let ghi = noon.direct_normal_w_m2 * noon.sun_direction.z + noon.diffuse_horizontal_w_m2;
    assert!(
        (ghi / solis.global_horizontal_w_m2 - 1.0).abs() < 0.015,
        "{ghi} vs {solis:?}"
    );
    assert!(noon.direct_normal_w_m2 > 850.0 && ghi > 850.0, "{noon:?}");
    // Outside [0, 48 h] there is no weather.
    for t in [-1.0, 48.0 * 3600.0 + 1.0] {
        assert!(matches!(
            weather.at(t),
            Err(WeatherError::OutOfRange { .. })
        ));
    }
}

#[test]
fn clear_days_cover_any_duration() {
    let site = munich("2026-03-20T06:00:00Z");
    for (duration, last) in [(0.0, 300.0), (1.0, 300.0), (300.0, 300.0), (7201.0, 7500.0)] {
        let weather = Weather::clear_day(&DAY, &site, duration).unwrap();
        assert_eq!(weather.span_s(), (0.0, last), "{duration}");
    }
    let week = Weather::clear_day(&DAY, &site, 7.0 * 86_400.0).unwrap();
    assert_eq!(week.span_s().1, 7.0 * 86_400.0);
}

#[test]
fn polar_day_and_night_have_a_cycle_without_sunrise() {
    // Tromsø (69.65° N, 18.96° E): midnight sun in June, polar night in December. The minimum
    // falls at 03:00 apparent solar time, transit (≈ 10:45 UTC) − 9 h ≈ 01:45 UTC, the maximum at
    // 15:00 ≈ 13:45 UTC.
    for start in ["2026-06-21T00:00:00Z", "2026-12-21T00:00:00Z"] {
        let site = Site {
            latitude_deg: 69.65,
            longitude_deg: 18.96,
            start_utc: parse_time_utc(start).unwrap(),
        };
        let weather = Weather::clear_day(&DAY, &site, 86_400.0).unwrap();
        let day: Vec<f64> = (0..24 * 60)
            .map(|m| weather.at(60.0 * m as f64).unwrap().air_k)
            .collect();
        let argmin = (0..day.len())
            .min_by(|&a, &b| day[a].total_cmp(&day[b]))
            .unwrap();
        let argmax = (0..day.len())
            .max_by(|&a, &b| day[a].total_cmp(&day[b]))
            .unwrap();
        assert!(
            (argmin as i64 - 105).abs() <= 10,
            "{start}: minimum at minute {argmin}"
        );
        assert!(
            (argmax as i64 - (13 * 60 + 45)).abs() <= 10,
            "{start}: maximum at {argmax}"
        );
        let noon = weather.at(10.75 * 3600.0).unwrap();
        if start.contains("-06-") {
            assert!(noon.sun_direction.z > 0.0 && noon.direct_normal_w_m2 > 500.0);
            // Midnight sun: up at local midnight too.
            assert!(weather.at(22.75 * 3600.0).unwrap().sun_direction.z > 0.0);
        } else {
            assert!(noon.sun_direction.z < 0.0 && noon.direct_normal_w_m2 == 0.0);
        }
    }
}

#[test]
fn the_example_of_the_scenes_page_reads() {
    // docs/scenes.md, "The weather CSV": the fenced block that starts with the Munich comment.
    let page =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/scenes.md"))
            .unwrap();
    let start = page
        .find("```\n# Munich, 21 June 2026")
        .expect("the example block")
        + 4;
    let block = &page[start..start + page[start..].find("```").unwrap()];
    let (weather, _path, _dir) = read("weather.csv", block);
    let weather = weather.unwrap();
    assert_eq!(weather.span_s(), (0.0, 86_400.0));
    assert!((weather.at(43_200.0).unwrap().air_k - 292.1).abs() < 1e-12);
}
