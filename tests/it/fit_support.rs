//! Synthetic Mueller-BRDF measurements made with our own pBRDF, for the fit tests and benches:
//! a goniometer-like geometry (in-plane scans on both sides of the normal plus out-of-plane
//! arcs), Gaussian noise of 3 % on m00 and 1 % of m00 on the other elements, with u_ columns.
#![allow(dead_code)]

use irpol::measure::{MeasurementPoint, MeasurementSet};
use irpol::optics::RefractiveIndex;
use irpol::pbrdf::{Direction, Pbrdf, Shadowing, SlopeDistribution};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// The nine linear-polarization elements m00…m22 (what a rotating-polarizer system measures).
pub const LINEAR_ELEMENTS: [usize; 9] = [0, 1, 2, 4, 5, 6, 8, 9, 10];

/// (θ_i, φ_i, θ_r, φ_r) in degrees: 4 incidence angles × (70 in-plane + 48 out-of-plane) = 472.
pub fn goniometer_geometry() -> Vec<[f64; 4]> {
    let mut rows = Vec::new();
    for theta_i in [15.0, 35.0, 55.0, 70.0] {
        for step in 0..35 {
            let theta_r = 2.5 * step as f64;
            rows.push([theta_i, 0.0, theta_r, 180.0]);
            rows.push([theta_i, 0.0, theta_r + 1.25, 0.0]);
        }
        for phi_r in [165.0, 150.0, 135.0, 120.0, 105.0, 90.0] {
            for theta_r in [5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0] {
                rows.push([theta_i, 0.0, theta_r, phi_r]);
            }
        }
    }
    rows
}

pub fn model(
    distribution: SlopeDistribution,
    shadowing: Shadowing,
    n: f64,
    k: f64,
    rho_d: f64,
) -> Pbrdf {
    Pbrdf::new(distribution, shadowing, RefractiveIndex::new(n, k), rho_d).unwrap()
}

/// Standard normal deviate by Box–Muller.
fn normal(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = 1.0 - rng.random::<f64>();
    let u2: f64 = rng.random();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// A measurement of `truth` on `geometry` with the elements `elements` (Mueller indices), noise
/// of 3 % on m00 and 1 % of m00 on the others scaled by `noise` (0 = exact), and u_ columns
/// holding the true standard deviations.
pub fn synthetic_set(
    name: &str,
    truth: &Pbrdf,
    geometry: &[[f64; 4]],
    elements: &[usize],
    noise: f64,
    seed: u64,
) -> MeasurementSet {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let points = geometry
        .iter()
        .enumerate()
        .map(|(row, &[ti, pi, tr, pr])| {
            let m = truth.mueller(
                &Direction::from_angles(ti.to_radians(), pi.to_radians()),
                &Direction::from_angles(tr.to_radians(), pr.to_radians()),
            );
            let m00 = m[(0, 0)];
            let mut values = Vec::new();
            let mut uncertainties = Vec::new();
            for &e in elements {
                let sigma = if e == 0 { 0.03 * m00 } else { 0.01 * m00 };
                values.push(m[(e / 4, e % 4)] + noise * sigma * normal(&mut rng));
                uncertainties.push(Some(if noise > 0.0 { noise * sigma } else { sigma }));
            }
            values[0] = values[0].max(0.0);
            MeasurementPoint {
                theta_i_deg: ti,
                phi_i_deg: pi,
                theta_r_deg: tr,
                phi_r_deg: pr,
                values,
                uncertainties,
                line: row as u64 + 2,
            }
        })
        .collect();
    MeasurementSet {
        source: PathBuf::from(format!("{name}.csv")),
        sha256: "0".repeat(64),
        material: name.to_owned(),
        wavelength_um: 10.0,
        metadata: BTreeMap::new(),
        elements: elements.to_vec(),
        points,
        merged: Vec::new(),
        notes: Vec::new(),
    }
}

/// The set as a measurement CSV (docs/design.md §2.1), with u_ columns when `with_uncertainties`.
pub fn to_csv(set: &MeasurementSet, with_uncertainties: bool) -> String {
    use irpol::measure::MUELLER_ELEMENT_NAMES;
    let mut text = format!(
        "# material: {}\n# wavelength_um: {}\n# mueller_convention: psps\n",
        set.material, set.wavelength_um
    );
    let mut header = vec!["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"]
        .into_iter()
        .map(String::from)
        .collect::<Vec<_>>();
    header.extend(
        set.elements
            .iter()
            .map(|&e| MUELLER_ELEMENT_NAMES[e].to_owned()),
    );
    if with_uncertainties {
        header.extend(
            set.elements
                .iter()
                .map(|&e| format!("u_{}", MUELLER_ELEMENT_NAMES[e])),
        );
    }
    text += &header.join(",");
    text.push('\n');
    for p in &set.points {
        let mut row = vec![
            p.theta_i_deg.to_string(),
            p.phi_i_deg.to_string(),
            p.theta_r_deg.to_string(),
            p.phi_r_deg.to_string(),
        ];
        row.extend(p.values.iter().map(|v| format!("{v:e}")));
        if with_uncertainties {
            row.extend(p.uncertainties().map(|u| format!("{:e}", u.unwrap())));
        }
        text += &row.join(",");
        text.push('\n');
    }
    text
}

/// A dense goniometer scan of exactly `rows` geometries (θ_i, φ_i, θ_r, φ_r in degrees), as an
/// archive of a scanning instrument holds: 8 incidence angles 5°…75°, and for each a raster of
/// detector directions over the hemisphere, θ_r in 0.5° steps to 84.75° by φ_r stepped finely
/// enough to give that angle its share of the rows. Detector positions within 3° of the source
/// (where the detector would shadow it) move 6° outward in θ_r, as an instrument skips them.
pub fn dense_geometry(rows: usize) -> Vec<[f64; 4]> {
    const THETA_I: [f64; 8] = [5.0, 15.0, 25.0, 35.0, 45.0, 55.0, 65.0, 75.0];
    const THETA_R_STEPS: usize = 170;
    let mut out = Vec::with_capacity(rows);
    for (a, &theta_i) in THETA_I.iter().enumerate() {
        // the first angles take the remainder, so the total is exactly `rows`
        let share = rows / THETA_I.len() + usize::from(a < rows % THETA_I.len());
        let azimuths = share.div_ceil(THETA_R_STEPS).max(1);
        for j in 0..share {
            let mut theta_r = 0.25 + 0.5 * (j % THETA_R_STEPS) as f64;
            let phi_r = 360.0 * (j / THETA_R_STEPS) as f64 / azimuths as f64;
            let retro = Direction::from_angles(theta_i.to_radians(), 0.0);
            let detector = Direction::from_angles(theta_r.to_radians(), phi_r.to_radians());
            if retro.vector.dot(&detector.vector) > 3f64.to_radians().cos() {
                theta_r = (theta_r + 6.0).min(84.75);
            }
            out.push([theta_i, 0.0, theta_r, phi_r]);
        }
    }
    out
}

/// The paint that [`dense_geometry`] files are made of: Cauchy σ = 0.15, q = 2.5, Smith,
/// N = 1.6 + 0.05i and a diffuse term `rho_d` (0.01 is the fit bench's synthetic truth; 0 puts
/// ρ_d on its bound, so the fit adds profile-likelihood bounds).
pub fn dense_truth(rho_d: f64) -> Pbrdf {
    model(
        SlopeDistribution::Cauchy {
            sigma: 0.15,
            q: 2.5,
        },
        Shadowing::Smith,
        1.6,
        0.05,
        rho_d,
    )
}
