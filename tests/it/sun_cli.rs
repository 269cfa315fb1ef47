//! `irpol sun` end to end: one instant, a file of instants, and one-line errors for bad input.

use crate::common;

use common::irpol;

#[test]
fn one_instant_is_one_csv_line_after_the_header() {
    // Sydney at local noon in June: the winter sun stands due north, 90° − (33.87° + 23.44°) high.
    let (ok, stdout, stderr) = irpol(&[
        "sun",
        "--latitude",
        "-33.87",
        "--longitude",
        "151.21",
        "--time-utc",
        "2026-06-21T02:00:00Z",
    ]);
    assert!(ok, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert_eq!(lines[0], "time_utc,elevation_deg,azimuth_deg");
    let fields: Vec<&str> = lines[1].split(',').collect();
    assert_eq!(fields[0], "2026-06-21T02:00:00Z");
    let elevation: f64 = fields[1].parse().unwrap();
    let azimuth: f64 = fields[2].parse().unwrap();
    assert!(
        (elevation - (90.0 - 33.87 - 23.44)).abs() < 0.3,
        "{elevation}"
    );
    // Due north: within 5° of 0° on the circle.
    let off_north = (azimuth + 180.0).rem_euclid(360.0) - 180.0;
    assert!(off_north.abs() < 5.0, "{azimuth}");
}

/// `irpol sun` at Munich for the instants in `times` (a times file), plus `extra` flags.
fn munich_times(times: &str, extra: &[&str]) -> (bool, String, String) {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("times.txt");
    std::fs::write(&file, times).unwrap();
    let mut args = vec![
        "sun",
        "--latitude",
        "48.14",
        "--longitude",
        "11.58",
        "--times-file",
        file.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    irpol(&args)
}

#[test]
fn a_times_file_gives_one_line_per_instant_in_order() {
    let (ok, stdout, stderr) = munich_times(
        "# Munich, 21 June\n2026-06-21T06:00:00Z\n2026-06-21T11:00:00Z\n2026-06-21T16:00:00Z\n",
        &[],
    );
    assert!(ok, "{stderr}");
    let rows: Vec<Vec<String>> = stdout
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    let times: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(
        times,
        [
            "2026-06-21T06:00:00Z",
            "2026-06-21T11:00:00Z",
            "2026-06-21T16:00:00Z"
        ]
    );
    // Morning sun in the east, midday in the south and highest, evening in the west.
    let azimuth: Vec<f64> = rows.iter().map(|r| r[2].parse().unwrap()).collect();
    let elevation: Vec<f64> = rows.iter().map(|r| r[1].parse().unwrap()).collect();
    assert!(azimuth[0] < 100.0 && (azimuth[1] - 180.0).abs() < 10.0 && azimuth[2] > 260.0);
    assert!(elevation[1] > elevation[0] && elevation[1] > elevation[2]);
}

/// A bad line of a times file is quoted cut short and with its control characters escaped: a
/// 100 000-character line gives a short message, a record separator (0x1e) shows as `\u{1e}`.
#[test]
fn a_bad_times_line_is_quoted_short_and_escaped() {
    let long = format!("2026-06-21T06:00:00Z\n{}\n", "9".repeat(100_000));
    let (ok, _, stderr) = munich_times(&long, &[]);
    assert!(!ok);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(stderr.chars().count() < 400, "{} characters", stderr.len());
    assert!(
        stderr.contains(&format!(
            "times.txt:2: time '{}…' is not an RFC 3339 instant",
            "9".repeat(40)
        )),
        "{stderr}"
    );
    let (ok, _, stderr) = munich_times("2026-06-21T06:00:00Z\u{1e}\n", &[]);
    assert!(!ok);
    assert!(
        stderr.contains("time '2026-06-21T06:00:00Z\\u{1e}'"),
        "{stderr:?}"
    );
    assert!(
        !stderr.trim_end().chars().any(char::is_control),
        "{stderr:?}"
    );
}

#[test]
fn bad_input_is_one_clear_line() {
    let base = ["sun", "--latitude", "48.14", "--longitude", "11.58"];
    for (extra, needle) in [
        (vec!["--time-utc", "2026-06-21T10:00:00"], "RFC 3339"),
        (vec!["--time-utc", "21/06/2026"], "RFC 3339"),
        (
            vec!["--times-file", "/nonexistent/times.txt"],
            "cannot read",
        ),
    ] {
        let args: Vec<&str> = base.iter().copied().chain(extra).collect();
        let (ok, stdout, stderr) = irpol(&args);
        assert!(!ok && stdout.is_empty(), "{args:?}: {stdout}");
        assert!(
            stderr.starts_with("irpol: error:") && stderr.contains(needle),
            "{args:?}: {stderr}"
        );
        assert_eq!(stderr.lines().count(), 1, "{stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
    }
    let (ok, stdout, stderr) = irpol(&[
        "sun",
        "--latitude",
        "95",
        "--longitude",
        "0",
        "--time-utc",
        "2026-06-21T10:00:00Z",
    ]);
    assert!(
        !ok && stdout.is_empty() && stderr.contains("latitude"),
        "{stderr}"
    );
    // One of --time-utc and --times-file, not both, not neither (clap's usage error).
    assert!(!irpol(&base).0);
}

#[test]
fn clear_sky_adds_the_solis_irradiance() {
    // Munich at midsummer: near noon, at sunset and at night. The numbers are the library's
    // simplified Solis model at the elevation irpol prints (pvlib agreement:
    // scripts/crosscheck_clearsky.py).
    let (ok, stdout, stderr) = munich_times(
        "2026-06-21T11:15:00Z\n2026-06-21T19:00:00Z\n2026-06-21T23:00:00Z\n",
        &["--clear-sky"],
    );
    assert!(ok, "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(
        lines[0],
        "time_utc,elevation_deg,azimuth_deg,dni_w_m2,dhi_w_m2,ghi_w_m2"
    );
    let rows: Vec<Vec<f64>> = lines[1..]
        .iter()
        .map(|l| l.split(',').skip(1).map(|f| f.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 3);
    for row in &rows {
        let solis =
            irpol::weather::simplified_solis(row[0], &irpol::weather::SolisAtmosphere::DEFAULT);
        assert_eq!(
            row[2..],
            [
                solis.direct_normal_w_m2,
                solis.diffuse_horizontal_w_m2,
                solis.global_horizontal_w_m2
            ]
        );
    }
    // High sun: strong beam; low evening sun: weak; night: nothing.
    assert!(rows[0][2] > 850.0 && rows[0][4] > 850.0, "{:?}", rows[0]);
    assert!(rows[1][0] > 0.0 && rows[1][4] < 100.0, "{:?}", rows[1]);
    assert_eq!(rows[2][2..], [0.0, 0.0, 0.0]);
    // Without the flag the columns are not there.
    let (ok, stdout, _) = irpol(&[
        "sun",
        "--latitude",
        "48.14",
        "--longitude",
        "11.58",
        "--time-utc",
        "2026-06-21T11:15:00Z",
    ]);
    assert!(ok && stdout.starts_with("time_utc,elevation_deg,azimuth_deg\n"));
}
