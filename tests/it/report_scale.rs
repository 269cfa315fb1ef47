//! Fit reports of large measurements: a report summarises the data, so that
//! its curves, legend entries and file size stay bounded however many rows and distinct incidence
//! angles the file holds. The old report drew a curve per incidence angle in five panels and a
//! circle per residual, about 200 KB of SVG per angle.

use crate::common;
use crate::fit_support;
#[allow(dead_code)]
use crate::report_support;

use irpol::measure::{read_measurement_csv, MUELLER_ELEMENT_NAMES};
use irpol::pbrdf::Direction;
use irpol::report::fit_report::{write_fit_report, REPORT_SIZE};
use report_support::{fitted_material, truth, LINEAR};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// SVG bytes a report may take whatever the data: the shipped measurements' reports take 1.6–2.4
/// MB with six incidence angles and every point drawn.
const MAX_SVG_BYTES: usize = 4_000_000;

/// Writes a noise-free CSV of the truth model at `geometry` (θ_i, φ_i, θ_r, φ_r in degrees) for the
/// linear block, and the m00 uncertainty 3 % of m00, 1 % for the others.
fn write_csv(dir: &Path, name: &str, geometry: &[(f64, f64, f64, f64)]) -> PathBuf {
    let pbrdf = truth().pbrdf().unwrap();
    let mut text = format!(
        "# material: {name}\n# wavelength_um: {}\ntheta_i_deg,phi_i_deg,theta_r_deg,phi_r_deg",
        truth().wavelength_um
    );
    for &e in &LINEAR {
        write!(text, ",{}", MUELLER_ELEMENT_NAMES[e]).unwrap();
    }
    text.push('\n');
    for &(ti, pi, tr, pr) in geometry {
        let m = pbrdf.mueller(
            &Direction::from_angles(ti.to_radians(), pi.to_radians()),
            &Direction::from_angles(tr.to_radians(), pr.to_radians()),
        );
        write!(text, "{ti},{pi},{tr},{pr}").unwrap();
        for &e in &LINEAR {
            write!(text, ",{:.6e}", m[(e / 4, e % 4)]).unwrap();
        }
        text.push('\n');
    }
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(&path, text).unwrap();
    path
}

/// One incidence angle's share of a goniometer export: an in-plane sweep of `in_plane` detector
/// angles over ±85° and a ring of `ring` azimuths at θ_r = 30°.
fn sweep_and_ring(theta_i: f64, in_plane: usize, ring: usize) -> Vec<(f64, f64, f64, f64)> {
    let mut rows = Vec::new();
    for k in 0..in_plane {
        let mut signed = -85.0 + 170.0 * (k as f64 + 0.5) / in_plane as f64;
        if (signed + theta_i).abs() < 3.0 {
            signed += 6.0; // the detector would shadow the source
        }
        rows.push((
            theta_i,
            0.0,
            signed.abs(),
            if signed >= 0.0 { 180.0 } else { 0.0 },
        ));
    }
    for k in 0..ring {
        rows.push((theta_i, 0.0, 30.0, 360.0 * (k as f64 + 0.37) / ring as f64));
    }
    rows
}

fn report(dir: &Path, name: &str, geometry: &[(f64, f64, f64, f64)]) -> (Vec<u8>, String) {
    let csv = write_csv(dir, name, geometry);
    let set = read_measurement_csv(&csv).unwrap();
    assert_eq!(set.points.len(), geometry.len());
    let material = fitted_material(name, &set, &csv);
    let paths = write_fit_report(&material, &set, &dir.join("reports")).unwrap();
    let png = std::fs::read(&paths[0]).unwrap();
    let image = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), REPORT_SIZE);
    (png, std::fs::read_to_string(&paths[1]).unwrap())
}

/// Legend and caption texts of the SVG that contain `needle`.
fn texts_with(svg: &str, needle: &str) -> usize {
    svg.match_indices('>')
        .filter(|&(at, _)| {
            let rest = &svg[at + 1..];
            let text = &rest[..rest.find('<').unwrap_or(rest.len())];
            text.contains(needle)
        })
        .count()
}

#[test]
fn a_report_of_50000_rows_at_500_incidence_angles_draws_8_curves_and_stays_small() {
    let dir = tempfile::tempdir().unwrap();
    // 500 distinct θ_i from 5° to 75°, 100 rows each: 50 in the plane, 50 on a ring.
    let geometry: Vec<_> = (0..500)
        .flat_map(|j| sweep_and_ring(5.0 + 70.0 * j as f64 / 499.0, 50, 50))
        .collect();
    let (_, svg) = report(dir.path(), "many_angles", &geometry);

    // The colour key names the incidence angles with curves: 8, spread from first to last.
    assert_eq!(texts_with(&svg, "θi = "), 8, "one legend entry per curve");
    for angle in ["θi = 5°", "θi = 75°"] {
        assert!(svg.contains(angle), "the range's ends are drawn: {angle}");
    }
    assert!(svg.contains("(curves at 8 of 500 incidence angles)"));
    // One ring per drawn incidence angle in the ring legend; the others' points are counted.
    assert_eq!(texts_with(&svg, "° → 30°"), 8);
    assert!(
        svg.contains("24600 pts on"),
        "492 rings × 50 points not drawn"
    );
    // 450 000 residuals are a 2-D histogram, not 450 000 circles.
    assert!(svg.contains("450000 residuals, all elements: count per"));
    assert!(
        svg.matches("<circle").count() < 20_000,
        "{} circles",
        svg.matches("<circle").count()
    );
    assert!(svg.len() < MAX_SVG_BYTES, "SVG of {} bytes", svg.len());
}

#[test]
fn dense_sweeps_at_few_angles_are_binned_and_many_rings_are_capped() {
    let dir = tempfile::tempdir().unwrap();
    // 4 incidence angles (all drawn), 12 500 rows each: 1250 in the plane and 50 rings of 225.
    let mut geometry = Vec::new();
    for theta_i in [20.0, 40.0, 55.0, 70.0] {
        geometry.extend(sweep_and_ring(theta_i, 1250, 0));
        for ring in 0..50 {
            let theta_r = 5.0 + ring as f64 * 1.5;
            geometry.extend(
                (0..225).map(|k| (theta_i, 0.0, theta_r, 360.0 * (k as f64 + 0.37) / 225.0)),
            );
        }
    }
    assert_eq!(geometry.len(), 50_000);
    let (_, svg) = report(dir.path(), "dense", &geometry);
    assert_eq!(texts_with(&svg, "θi = "), 4, "few angles: every one drawn");
    assert!(!svg.contains("incidence angles)"));
    // 5000 in-plane points, and 4050 on the drawn rings, become medians per 1° bin.
    assert!(svg.contains("(a) m00 in the plane of incidence (median per 1° bin)"));
    assert!(svg.contains("(b) m00 on out-of-plane rings (median per 1° bin)"));
    // 200 rings: 18 drawn (the legend lists them all), the rest counted.
    assert_eq!(texts_with(&svg, "° → "), 18);
    assert!(
        svg.contains("40950 pts on"),
        "182 rings × 225 points not drawn"
    );
    assert!(svg.len() < MAX_SVG_BYTES, "SVG of {} bytes", svg.len());
}

#[test]
fn a_mid_size_file_draws_its_residual_scatter_as_one_image_in_the_svg() {
    let dir = tempfile::tempdir().unwrap();
    let geometry: Vec<_> = [20.0, 40.0, 60.0, 75.0]
        .into_iter()
        .flat_map(|theta_i| sweep_and_ring(theta_i, 400, 100))
        .collect();
    // 2000 rows × 9 elements: 18 000 residuals, drawn as dots (below the density threshold).
    let (_, svg) = report(dir.path(), "mid", &geometry);
    assert_eq!(svg.matches("<image").count(), 1, "the scatter of (g)");
    assert!(svg.contains("data:image/png;base64,"));
    let circles = svg.matches("<circle").count();
    assert!(
        circles < 16_000,
        "{circles} circles: the residuals are not among them"
    );
    eprintln!("mid-size SVG: {} bytes, {circles} circles", svg.len());
    // 2.7 MB; with the 18 000 residual dots as SVG circles it was 4.3 MB.
    assert!(svg.len() < 3_000_000, "SVG of {} bytes", svg.len());
}

/// A dense goniometer scan through `irpol fit`: beyond `fit::COARSE_POINTS` rows the search
/// runs on a subsample and the figure thins what it draws, and says both, while every statistic
/// it prints counts every row: the points and residuals, and the χ², recomputed here from the
/// fitted model over all rows (on the subsample alone it would be about half).
#[test]
fn a_dense_scan_is_drawn_thinned_but_its_statistics_use_every_row() {
    use fit_support::{dense_geometry, dense_truth, synthetic_set, to_csv, LINEAR_ELEMENTS};
    use irpol::material::{Material, MaterialModel};
    let rows = 24_000;
    assert!(rows > irpol::fit::COARSE_POINTS);
    let set = synthetic_set(
        "dense_scan",
        &dense_truth(0.01),
        &dense_geometry(rows),
        &LINEAR_ELEMENTS,
        1.0,
        7,
    );
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("dense_scan.csv");
    std::fs::write(&csv, to_csv(&set, true)).unwrap();
    let (ok, _, stderr) = common::fit_into(dir.path(), &[&csv], &["--distribution", "cauchy"]);
    assert!(ok, "{stderr}");
    let material = Material::load(&dir.path().join("fits/dense_scan.toml")).unwrap();
    let MaterialModel::Grey(spec) = &material.model else {
        panic!("a grey material")
    };
    let pbrdf = spec.pbrdf().unwrap();
    let chi2: f64 = set
        .points
        .iter()
        .map(|p| {
            let m = pbrdf.mueller(
                &Direction::from_degrees(p.theta_i_deg, p.phi_i_deg),
                &Direction::from_degrees(p.theta_r_deg, p.phi_r_deg),
            );
            LINEAR_ELEMENTS
                .iter()
                .zip(p.values.iter().zip(p.uncertainties()))
                .map(|(&e, (v, u))| ((m[(e / 4, e % 4)] - v) / u.unwrap()).powi(2))
                .sum::<f64>()
        })
        .sum();
    let fit = material.fit.as_ref().unwrap();
    assert!(
        (fit.cost / chi2 - 1.0).abs() < 1e-6,
        "{} vs {chi2}",
        fit.cost
    );
    assert_eq!(fit.points, rows);

    let svg = std::fs::read_to_string(dir.path().join("reports/dense_scan.svg")).unwrap();
    let residuals = rows * LINEAR_ELEMENTS.len();
    for every_row in [
        format!("{rows} points × 9 elements"),
        format!("residuals, N = {residuals}"),
        format!("{residuals} residuals, all elements: count per"),
        format!("{:.3e}", chi2),
    ] {
        assert!(svg.contains(&every_row), "{every_row}");
    }
    // Thinned, and said so: most ring points only in (g), and the search's subsample.
    assert!(svg.contains(" pts on"), "rings not drawn are counted");
    assert!(svg.contains("(search on 1 point in 2, then on all)"));
}
