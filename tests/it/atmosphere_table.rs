//! `[atmosphere] table = "path.csv"` (docs/design.md §1.12, §2.9): a band table of the grey
//! slab renders the `extinction_per_km` image; a spectral table is integrated over the band
//! before it is interpolated in range, consistently with the band radiance; every malformed table
//! is refused naming the file, the line and the fix.

use crate::common;

use common::*;
use irpol::optics::{spectral_radiance, Band};
use irpol::progress::Silent;
use irpol::render::render;
use irpol::scene::{load_scene, Scene};
use std::fmt::Write as _;
use std::path::Path;

/// Air temperature of [`AUTUMN_ENVIRONMENT`].
const AIR_K: f64 = 283.15;

/// A shiny sphere 4 m away in the autumn environment, `atmosphere` as its `[atmosphere]` body and
/// `sensor` its `[sensor]` body.
fn scene_text(atmosphere: &str, sensor: &str) -> String {
    format!(
        "{}[sensor]\n{sensor}\n{}[atmosphere]\n{atmosphere}\n{}{}{}",
        camera_toml(24),
        AUTUMN_ENVIRONMENT,
        material_toml(0.15, 2.0, 1.6, 0.3, 0.02),
        sphere_toml(2, 305.0),
        PLATE,
    )
}

/// A warm plate beside the sphere: the two see each other, so the path tracer's correction
/// (and its standard error) is not zero.
const PLATE: &str = "[[objects]]\nname = \"plate\"\n\
    shape = { kind = \"plane\", size = [3.0, 3.0], divisions = [2, 2] }\n\
    material = \"m\"\ntemperature_k = 320.0\nrotate_deg = [0.0, 60.0, 0.0]\n\
    translate = [1.3, 0.5, 0.0]\n";

/// Loads `scene` written into `dir` with `files` (name, text) beside it.
fn load(dir: &Path, scene: &str, files: &[(&str, &str)]) -> Result<Scene, String> {
    for (name, text) in files {
        std::fs::write(dir.join(name), text).unwrap();
    }
    load_scene(&write_scene(dir, scene)).map_err(|e| e.to_string())
}

/// A band table of the grey slab β (1/m) at the air temperature: rows at `ranges`.
fn grey_band_table(beta_per_m: f64, ranges: &[f64], header: &str) -> String {
    let blackbody = Band::lwir().radiance(AIR_K);
    let mut csv = format!("{header}range_m,transmittance,path_radiance_w_m2_sr\n");
    for &r in ranges {
        let tau = (-beta_per_m * r).exp();
        writeln!(csv, "{r},{tau},{}", (1.0 - tau) * blackbody).unwrap();
    }
    csv
}

/// A spectral table over `wavelengths` × `ranges` with τ(λ, r) = `tau` and path radiance
/// `radiance` (per µm).
fn spectral_table(
    wavelengths: &[f64],
    ranges: &[f64],
    tau: impl Fn(f64, f64) -> f64,
    radiance: impl Fn(f64, f64) -> f64,
) -> String {
    let mut csv = String::from(
        "# source: synthetic\nwavelength_um,range_m,transmittance,path_radiance_w_m2_sr_um\n",
    );
    for &w in wavelengths {
        for &r in ranges {
            writeln!(csv, "{w},{r},{},{}", tau(w, r), radiance(w, r)).unwrap();
        }
    }
    csv
}

/// 7.9, 7.91, … 14.1 µm: a radiative-transfer code's fine spectral grid over the LWIR band.
fn fine_wavelengths() -> Vec<f64> {
    (0..=620).map(|i| 7.9 + 0.01 * i as f64).collect()
}

#[test]
fn a_grey_band_table_renders_the_extinction_image() {
    // β = 0.1 /m (τ ≈ 0.7 at the sphere), rows every 0.5 m from 1 m (not from 0: the row
    // (0, 1, 0) is implied), through the path tracer so the standard error is scaled too.
    let dir = tempfile::tempdir().unwrap();
    let ranges: Vec<f64> = (2..=20).map(|i| 0.5 * i as f64).collect();
    let table = grey_band_table(0.1, &ranges, "");
    let by_table = load(
        dir.path(),
        &scene_text("table = \"path.csv\"", ""),
        &[("path.csv", &table)],
    )
    .unwrap();
    assert!(by_table.warnings.is_empty(), "{:?}", by_table.warnings);
    let by_extinction = load(
        dir.path(),
        &scene_text("extinction_per_km = 100.0", ""),
        &[],
    )
    .unwrap();
    let a = render(&by_table, &Silent).unwrap().image;
    let b = render(&by_extinction, &Silent).unwrap().image;
    let mut checked = 0;
    for i in 0..a.stokes.len() {
        let (sa, sb) = (a.stokes[i], b.stokes[i]);
        for j in 0..4 {
            assert!(
                (sa[j] - sb[j]).abs() <= 1e-9 * sb[0].abs(),
                "pixel {i} S{j}: {} vs {}",
                sa[j],
                sb[j]
            );
            let (ea, eb) = (a.standard_error[i][j], b.standard_error[i][j]);
            assert!(
                (ea - eb).abs() <= 1e-9 * eb.abs(),
                "pixel {i} σ{j}: {ea} vs {eb}"
            );
        }
        checked += (a.surface[i] != irpol::render::BACKGROUND) as usize;
    }
    assert!(checked > 100, "{checked}");
    // The path does something here: without it S0 and the standard error differ by far more
    // than the tolerance.
    let clear = load(dir.path(), &scene_text("extinction_per_km = 0.0", ""), &[]).unwrap();
    let c = render(&clear, &Silent).unwrap().image;
    let centre = 12 * 24 + 12;
    assert!((c.stokes[centre][0] - a.stokes[centre][0]).abs() > 1e-3 * c.stokes[centre][0]);
    let total_error = |image: &irpol::render::StokesImage| -> f64 {
        image.standard_error.iter().map(|e| e[0]).sum()
    };
    assert!(total_error(&c) > 0.0);
    assert!(total_error(&a) < 0.8 * total_error(&c));
}

#[test]
fn a_spectral_table_of_a_grey_path_is_its_band_table() {
    // Flat τ(λ) = exp(−βr) and L_λ = (1 − τ) B_λ(T_air), seen with a sloped response: the band
    // table is τ and (1 − τ) L_bb(T_air) with L_bb = ∫R B_λ dλ (Band::radiance).
    let dir = tempfile::tempdir().unwrap();
    let sensor = "response = [[8.0, 0.5], [10.0, 1.0], [14.0, 0.5]]";
    let beta = 0.05;
    let ranges = [0.0, 5.0, 10.0, 20.0, 50.0];
    let per_um = |w: f64| spectral_radiance(w * 1e-6, AIR_K) * 1e-6;
    let table = spectral_table(
        &fine_wavelengths(),
        &ranges,
        |_, r| (-beta * r).exp(),
        |w, r| (1.0 - (-beta * r).exp()) * per_um(w),
    );
    let scene = load(
        dir.path(),
        &scene_text("table = \"s.csv\"", sensor),
        &[("s.csv", &table)],
    )
    .unwrap();
    let band = Band::new(8.0, 14.0, Some(vec![(8.0, 0.5), (10.0, 1.0), (14.0, 0.5)])).unwrap();
    let blackbody = band.radiance(AIR_K);
    let atmosphere = scene.atmosphere.as_ref().unwrap();
    // The table's L_λ is linear between its wavelengths 0.01 µm apart: the band integral of that
    // interpolant exceeds ∫R B_λ by ≈ (h²/12) ∫ R B_λ'' dλ ≈ 4e-7 relative here (B_λ'' / B_λ is
    // ≈ 0.04 µm⁻² around 10 µm); both quadratures are exact to ~1e-10. Measured: ≤ 3.3e-7 of
    // the path radiance (3.05e-7 of L_bb at 50 m), τ to 3e-15. Hence 1e-6.
    let mut worst: f64 = 0.0;
    for r in [0.0, 2.5, 5.0, 7.0, 10.0, 15.0, 20.0, 35.0, 50.0] {
        let (tau, path) = atmosphere.along(r);
        let expected = (-beta * r).exp();
        assert!(
            (tau - expected).abs() < 1e-14,
            "{r} m: τ {tau} vs {expected}"
        );
        let expected_path = (1.0 - expected) * blackbody;
        let error = (path - expected_path).abs() / blackbody;
        worst = worst.max(error);
        assert!(error < 1e-6, "{r} m: L {path} vs {expected_path}");
    }
    // The quadrature is not a coincidence of zeros: at 50 m the path is most of a blackbody.
    assert!(atmosphere.path_radiance(50.0) > 0.9 * blackbody, "{worst}");
}

/// Band transmittance by a direct integral: Simpson's rule on 60 000 intervals over 8–14 µm of
/// B_λ(T) τ(λ, r), over that of B_λ(T) (a flat response).
fn direct_band_tau(t_k: f64, r: f64, tau: &impl Fn(f64, f64) -> f64) -> f64 {
    let n = 60_000;
    let h = 6.0 / n as f64;
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..=n {
        let w = 8.0 + h * i as f64;
        let simpson = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let b = spectral_radiance(w * 1e-6, t_k);
        num += simpson * b * tau(w, r);
        den += simpson * b;
    }
    num / den
}

#[test]
fn a_spectral_band_transmittance_is_integrated_before_range_and_is_not_exponential() {
    // A window below 11 µm and an absorption band above (a logistic edge 0.5 µm wide): each
    // wavelength decays exponentially, their band mean does not (the absorbing part is used up
    // within metres, the window carries on), so an exponential in range through the table's
    // far row misses the near rows. τ is weighted by a blackbody at the NETD reference, 300 K.
    let k = |w: f64| 0.01 + 0.4 / (1.0 + (-(w - 11.0) / 0.5).exp());
    let tau = |w: f64, r: f64| (-k(w) * r).exp();
    let ranges = [0.0, 1.0, 2.0, 5.0, 10.0, 20.0];
    let table = spectral_table(&fine_wavelengths(), &ranges, tau, |_, _| 0.0);
    let dir = tempfile::tempdir().unwrap();
    let sensor = "netd_reference_k = 300.0";
    let scene = load(
        dir.path(),
        &scene_text("table = \"s.csv\"", sensor),
        &[("s.csv", &table)],
    )
    .unwrap();
    let atmosphere = scene.atmosphere.as_ref().unwrap();
    // At the table's ranges: the direct integral, to the table's linear-in-λ interpolation of τ
    // (≈ (h²/12) ∫ B (∂²τ/∂λ²) dλ / ∫B with h = 0.01 µm; measured ≤ 4.1e-8, so 2e-7).
    for &r in &ranges {
        let direct = direct_band_tau(300.0, r, &tau);
        let got = atmosphere.transmittance(r);
        assert!((got - direct).abs() < 2e-7, "{r} m: {got} vs {direct}");
    }
    // Not exponential: ln τ / r at 1 m and at 20 m differ by a factor of several.
    let rate = |r: f64| -direct_band_tau(300.0, r, &tau).ln() / r;
    assert!(rate(1.0) > 2.0 * rate(20.0), "{} {}", rate(1.0), rate(20.0));
    // An exponential through the 20 m row is 23 % off at 2 m (0.872 against 0.707); the table
    // is right there (above).
    let exponential = (-rate(20.0) * 2.0).exp();
    let direct = direct_band_tau(300.0, 2.0, &tau);
    assert!(
        (exponential - direct).abs() > 0.05 * direct,
        "{exponential} vs {direct}"
    );
    // The weighting temperature matters: at the air's 283.15 K τ(5 m) is 0.013 lower.
    assert!((direct_band_tau(AIR_K, 5.0, &tau) - atmosphere.transmittance(5.0)).abs() > 1e-3);
}

#[test]
fn a_table_ending_before_the_objects_is_clamped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let table = grey_band_table(0.1, &[0.0, 1.0, 2.0], "");
    let scene = load(
        dir.path(),
        &scene_text("table = \"path.csv\"", ""),
        &[("path.csv", &table)],
    )
    .unwrap();
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let warning = &scene.warnings[0];
    assert!(
        warning.contains("path.csv' ends at 2 m but objects reach 6.47 m from the camera")
            && warning.contains("extend the table"),
        "{warning}"
    );
    let atmosphere = scene.atmosphere.as_ref().unwrap();
    assert_eq!(atmosphere.along(3.0), atmosphere.along(2.0));
}

#[test]
fn the_summary_reports_the_table_and_its_notes() {
    let dir = tempfile::tempdir().unwrap();
    let table = grey_band_table(
        0.1,
        &[0.0, 10.0],
        "# source: MODTRAN 6.0, mid-latitude summer, rural 23 km\n# geometry: horizontal, 2 m\n# other\n",
    );
    std::fs::write(dir.path().join("path.csv"), table).unwrap();
    let scene = write_scene(dir.path(), &scene_text("table = \"path.csv\"", ""));
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let atmosphere = &summary["atmosphere"];
    assert_eq!(atmosphere["kind"], "table");
    assert_eq!(
        atmosphere["source"],
        "MODTRAN 6.0, mid-latitude summer, rural 23 km"
    );
    assert_eq!(atmosphere["geometry"], "horizontal, 2 m");
    assert!(atmosphere["table"].as_str().unwrap().ends_with("path.csv"));

    let plain = write_scene(dir.path(), &scene_text("extinction_per_km = 1.0", ""));
    let (ok, _, stderr) = irpol(&[
        "render",
        plain.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(ok, "{stderr}");
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(
        summary["atmosphere"],
        serde_json::json!({"kind": "extinction"})
    );
}

#[test]
fn malformed_tables_are_refused_with_file_line_and_fix() {
    let band = "range_m,transmittance,path_radiance_w_m2_sr\n";
    let spectral = "wavelength_um,range_m,transmittance,path_radiance_w_m2_sr_um\n";
    let over_band = |rows: &str| {
        format!("{spectral}8.0,0,1,0\n8.0,10,0.9,0.1\n{rows}14.0,0,1,0\n14.0,10,0.9,0.1\n")
    };
    let cases: Vec<(String, &str, &str)> = vec![
        (format!("# c\n{band}0,1,0\n20,0.5,1\n10,0.4,2\n"), ":5: ", "10 m is not after 20 m on the row before: ranges must be strictly increasing"),
        (format!("{spectral}8,0,1,0\n8,10,0.9,0.1\n8,20,0.8,0.2\n14,0,1,0\n14,10,0.9,0.1\n14,5,0.95,0.05\n"), ":7: ", "5 m is not after 10 m on the row before: ranges must be strictly increasing within wavelength 14 µm"),
        (over_band("11.0,0,1,0\n11.0,20,0.9,0.1\n"), ":5: ", "20 m where the first wavelength has 10 m (its range number 2): every wavelength needs the same ranges"),
        (over_band("11.0,0,1,0\n"), ":5: ", "wavelength 11 µm (from line 4) has 1 range(s), the first wavelength 2"),
        (over_band("7.0,0,1,0\n"), ":4: ", "7 µm comes after 8 µm: group the rows by wavelength, wavelengths ascending"),
        (format!("{band}0,1,0\n10,1.2,1\n"), ":3: ", "column 'transmittance': 1.2 is outside [0, 1] (a fraction, not a percentage)"),
        (format!("{band}0,1,0\n10,-0.1,1\n"), ":3: ", "column 'transmittance': -0.1 is outside [0, 1]"),
        (format!("{band}0,1,0\n10,0.5,-1\n"), ":3: ", "column 'path_radiance_w_m2_sr': -1 must be ≥ 0 (a radiance)"),
        (over_band("11.0,0,1,-2\n11.0,10,1,0\n"), ":4: ", "column 'path_radiance_w_m2_sr_um': -2 must be ≥ 0"),
        (format!("{band}0,1,0\n10,0.5,3e9\n"), ":3: ", "column 'path_radiance_w_m2_sr': 3e9 is beyond 1e9: not a radiance in W·m⁻²·sr⁻¹"),
        (format!("{band}0,1,0\n10,NaN,1\n"), ":3: ", "column 'transmittance': 'NaN' is not a finite number"),
        (format!("{band}0,1,0\ninf,0.5,1\n"), ":3: ", "column 'range_m': 'inf' is not a finite number"),
        (format!("{band}0,1,0\n10,0.5,\n"), ":3: ", "column 'path_radiance_w_m2_sr': empty, expected a number"),
        (format!("{band}0,1,0\n10,0.5\n"), ":3: ", "the row has 2 fields, the header row has 3"),
        (format!("{band}-1,1,0\n10,0.5,1\n"), ":2: ", "column 'range_m': -1 m must be ≥ 0"),
        (format!("{spectral}9.0,0,1,0\n9.0,10,0.9,0.1\n14.0,0,1,0\n14.0,10,0.9,0.1\n"), ": ", "the wavelengths cover 9–14 µm, not the whole sensor band 8–14 µm: add rows over the band (or narrow sensor.band_um)"),
        ("range_m,transmittance,radiance\n0,1,0\n".into(), ":1: ", "unknown column 'radiance' (a band table has range_m, transmittance, path_radiance_w_m2_sr; a spectral table has"),
        ("Range_m,transmittance,path_radiance_w_m2_sr\n".into(), ":1: ", "did you mean 'range_m'?"),
        ("range_m,path_radiance_w_m2_sr\n0,0\n".into(), ":1: ", "missing column 'transmittance' (a band table has"),
        ("range_m,transmittance,path_radiance_w_m2_sr_um\n".into(), ":1: ", "'path_radiance_w_m2_sr_um' is per µm but the table has no wavelength_um"),
        ("wavelength_um,range_m,transmittance,path_radiance_w_m2_sr\n".into(), ":1: ", "a spectral table gives path_radiance_w_m2_sr_um"),
        ("range_m,range_m,transmittance,path_radiance_w_m2_sr\n".into(), ":1: ", "column 'range_m' appears twice: keep one"),
        (format!("{band}0,1,0\n"), ":2: ", "1 range(s): the table needs at least two ranges to interpolate between"),
        (format!("{spectral}8,0,1,0\n14,0,1,0\n"), ":3: ", "1 range(s) at wavelength 8 µm: the table needs at least two ranges"),
        ("# only a comment\n\n".into(), ":1: ", "no header row: the file is empty or only comments"),
        (String::new(), ":1: ", "no header row"),
    ];
    let dir = tempfile::tempdir().unwrap();
    let table_path = dir.path().join("t.csv");
    let prefix = format!(
        "{}: atmosphere.table: {}",
        dir.path().join("scene.toml").display(),
        table_path.display()
    );
    for (csv, at, fix) in &cases {
        let message = load(
            dir.path(),
            &scene_text("table = \"t.csv\"", ""),
            &[("t.csv", csv)],
        )
        .unwrap_err();
        assert!(
            message.starts_with(&format!("{prefix}{at}")),
            "{csv:?}:\n{message}"
        );
        assert!(message.contains(fix), "{csv:?}:\n{message}");
        assert!(!message.contains('\n'), "{message}");
    }
    // Not UTF-8 (a Latin-1 'µ' on line 3).
    std::fs::write(
        &table_path,
        b"range_m,transmittance,path_radiance_w_m2_sr\n0,1,0\n# 10 \xb5m\n10,0.5,1\n",
    )
    .unwrap();
    let message = load_scene(&write_scene(
        dir.path(),
        &scene_text("table = \"t.csv\"", ""),
    ))
    .unwrap_err()
    .to_string();
    assert!(
        message.starts_with(&format!("{prefix}:3: invalid UTF-8"))
            && message.contains("save it as UTF-8"),
        "{message}"
    );
}

#[test]
fn atmosphere_keys_that_do_not_fit_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let table = grey_band_table(0.1, &[0.0, 10.0], "");
    let cases = [
        ("extinction_per_km = 1.0\ntable = \"path.csv\"", "atmosphere: extinction_per_km and table both describe the path: keep one"),
        ("temperature_k = 280.0", "atmosphere: give extinction_per_km (a grey path) or table = \"path.csv\""),
        ("table = \"path.csv\"\ntemperature_k = 280.0", "atmosphere.temperature_k belongs to extinction_per_km: a table gives its own path radiance, remove temperature_k"),
        ("table = \" \"", "atmosphere.table is empty: give the CSV file's path"),
        ("table = \"missing.csv\"", "missing.csv: cannot read the atmosphere table: "),
        ("extinction_per_km = -1.0", "atmosphere.extinction_per_km = -1 must be finite and ≥ 0"),
    ];
    for (keys, expected) in cases {
        let message = load(dir.path(), &scene_text(keys, ""), &[("path.csv", &table)]).unwrap_err();
        assert!(message.contains(expected), "{keys}:\n{message}");
        assert!(
            message.starts_with(&dir.path().join("scene.toml").display().to_string()),
            "{message}"
        );
    }
    // Through the command line: one line naming the scene, the table, the line and the fix.
    std::fs::write(
        dir.path().join("path.csv"),
        "range_m,transmittance,path_radiance_w_m2_sr\n0,1,0\n10,1.5,0\n",
    )
    .unwrap();
    let scene = write_scene(dir.path(), &scene_text("table = \"path.csv\"", ""));
    let out = dir.path().join("out");
    let (ok, _, stderr) = irpol(&[
        "render",
        scene.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert_eq!(stderr.lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("path.csv:3: column 'transmittance': 1.5 is outside [0, 1]"),
        "{stderr}"
    );
}

#[test]
fn a_thermal_instant_moves_the_path_with_the_air() {
    // The extinction path's temperature and a spectral table's weighting (the NETD reference)
    // follow the air of the instant, as they default to the air's.
    let dir = tempfile::tempdir().unwrap();
    let k = |w: f64| 0.01 + 0.4 / (1.0 + (-(w - 11.0) / 0.5).exp());
    let tau = |w: f64, r: f64| (-k(w) * r).exp();
    let table = spectral_table(&fine_wavelengths(), &[0.0, 5.0, 20.0], tau, |_, _| 0.0);
    std::fs::write(dir.path().join("s.csv"), table).unwrap();
    for atmosphere in ["extinction_per_km = 50.0", "table = \"s.csv\""] {
        let text = thermal_plate_scene(|t| format!("{t}\n[atmosphere]\n{atmosphere}\n"));
        let scene = load_scene(&write_scene(dir.path(), &text)).unwrap();
        let solution = irpol::thermal_scene::solve_scene(&scene, &[3600.0], &Silent).unwrap();
        let i = solution.times_s.iter().position(|&t| t == 3600.0).unwrap();
        let air = solution.weather[i].air_k;
        assert!((air - 290.0).abs() > 0.5, "{air}");
        let at = irpol::thermal_scene::scene_at(&scene, &solution, i).unwrap();
        let path = at.atmosphere.as_ref().unwrap();
        if atmosphere.starts_with("extinction") {
            assert_eq!(path.temperature_k(), Some(air));
            let tau = (-0.05f64 * 20.0).exp();
            let expected = (1.0 - tau) * Band::lwir().radiance(air);
            assert!((path.path_radiance(20.0) - expected).abs() < 1e-12 * expected);
        } else {
            let direct = direct_band_tau(air, 5.0, &tau);
            assert!((path.transmittance(5.0) - direct).abs() < 2e-7, "{air} K");
            let loaded = scene.atmosphere.as_ref().unwrap().transmittance(5.0);
            assert!((loaded - direct_band_tau(290.0, 5.0, &tau)).abs() < 2e-7);
            assert!((loaded - direct).abs() > 1e-4);
        }
    }
}
