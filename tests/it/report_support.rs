//! Shared by the report tests: a synthetic goniometer measurement of a known pBRDF with seeded
//! noise, written as a real CSV (docs/design.md §2.1), and a material whose fit record is filled by hand.

use irpol::material::{AlternativeFit, FitRecord, Material, ModelSpec};
use irpol::measure::{read_measurement_csv, MeasurementSet, MUELLER_ELEMENT_NAMES};
use irpol::pbrdf::{Direction, Shadowing, SlopeDistribution};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The model that generates the synthetic data.
pub fn truth() -> ModelSpec {
    ModelSpec {
        distribution: SlopeDistribution::Cauchy { sigma: 0.2, q: 2.5 },
        shadowing: Shadowing::Smith,
        n: 1.5,
        k: 0.1,
        rho_d: 0.02,
        facet: Default::default(),
        lobe_keys: Default::default(),
        wavelength_um: 9.925,
    }
}

/// The competing Gaussian model drawn dashed.
pub fn competitor() -> ModelSpec {
    ModelSpec {
        distribution: SlopeDistribution::Gaussian { sigma: 0.17 },
        ..truth()
    }
}

/// (θ_i, φ_i, θ_r, φ_r) in degrees of a goniometer run: in-plane sweeps of the signed detector
/// angle every 5° (1° near specular) for θ_i = 20°, 40°, 60°, and rings at θ_r = θ_i and 30°
/// every 15°; points within 3° of retro-reflection are skipped (the detector shadows the source).
pub fn goniometer() -> Vec<(f64, f64, f64, f64)> {
    let mut rows = Vec::new();
    for theta_i in [20.0, 40.0, 60.0] {
        let mut signed: Vec<f64> = (-17..=17).map(|i| i as f64 * 5.0).collect();
        signed.extend(
            (-4..=4)
                .map(|d| theta_i + d as f64)
                .filter(|&d: &f64| d % 5.0 != 0.0),
        );
        signed.sort_by(f64::total_cmp);
        for s in signed {
            if (s + theta_i).abs() < 3.0 {
                continue;
            }
            rows.push((theta_i, 0.0, s.abs(), if s >= 0.0 { 180.0 } else { 0.0 }));
        }
        for theta_r in [theta_i, 30.0] {
            if theta_r == 30.0 && theta_i == 40.0 {
                continue;
            }
            for step in 0..24 {
                let phi_r = step as f64 * 15.0;
                if phi_r == 0.0 || phi_r == 180.0 {
                    continue;
                }
                rows.push((theta_i, 0.0, theta_r, phi_r));
            }
        }
    }
    rows
}

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let (u1, u2): (f64, f64) = (rng.random::<f64>().max(1e-300), rng.random());
    (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
}

/// CSV text of `model` at the goniometer geometry for `elements` (Mueller indices, m00 first):
/// 3 % multiplicative noise on m00 and 1 % of m00 on the others, with matching `u_` columns
/// when `with_uncertainties`.
pub fn synthetic_csv(
    name: &str,
    model: &ModelSpec,
    elements: &[usize],
    with_uncertainties: bool,
    seed: u64,
) -> String {
    let pbrdf = model.pbrdf().unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut text = format!(
        "# material: {name}\n# wavelength_um: {}\n# mueller_convention: psps\n",
        model.wavelength_um
    );
    let mut header = vec!["theta_i_deg", "phi_i_deg", "theta_r_deg", "phi_r_deg"];
    header.extend(elements.iter().map(|&e| MUELLER_ELEMENT_NAMES[e]));
    let uncertainty_names: Vec<String> = elements
        .iter()
        .map(|&e| format!("u_{}", MUELLER_ELEMENT_NAMES[e]))
        .collect();
    if with_uncertainties {
        header.extend(uncertainty_names.iter().map(String::as_str));
    }
    writeln!(text, "{}", header.join(",")).unwrap();
    for (ti, pi, tr, pr) in goniometer() {
        let m = pbrdf.mueller(
            &Direction::from_angles(ti.to_radians(), pi.to_radians()),
            &Direction::from_angles(tr.to_radians(), pr.to_radians()),
        );
        let m00 = m[(0, 0)];
        let sigmas: Vec<f64> = elements
            .iter()
            .map(|&e| if e == 0 { 0.03 * m00 } else { 0.01 * m00 })
            .collect();
        // A measured m00 is never negative (docs/design.md §2.1); 3 % noise keeps it so anyway.
        let values: Vec<f64> = elements
            .iter()
            .zip(&sigmas)
            .map(|(&e, &s)| m[(e / 4, e % 4)] + s * gaussian(&mut rng))
            .zip(elements)
            .map(|(v, &e)| if e == 0 { v.max(0.0) } else { v })
            .collect();
        let mut row = format!("{ti},{pi},{tr},{pr}");
        for v in &values {
            write!(row, ",{v:.6e}").unwrap();
        }
        if with_uncertainties {
            for s in &sigmas {
                write!(row, ",{s:.4e}").unwrap();
            }
        }
        writeln!(text, "{row}").unwrap();
    }
    text
}

/// Writes the synthetic CSV to `dir/<name>.csv` and reads it back.
pub fn synthetic_set(dir: &Path, name: &str, elements: &[usize]) -> (PathBuf, MeasurementSet) {
    let path = dir.join(format!("{name}.csv"));
    std::fs::write(
        &path,
        synthetic_csv(name, &truth(), elements, true, 20240611),
    )
    .unwrap();
    let set = read_measurement_csv(&path).unwrap();
    (path, set)
}

/// The 3×3 linear block (m00 … m22).
pub const LINEAR: [usize; 9] = [0, 1, 2, 4, 5, 6, 8, 9, 10];

/// A material fitted (by hand) to `set`: the truth with plausible uncertainties, the Gaussian
/// competitor, and a GA + Nelder–Mead convergence history.
pub fn fitted_material(name: &str, set: &MeasurementSet, source: &Path) -> Material {
    let observations = set.points.len() * set.elements.len();
    let free: Vec<String> = ["sigma", "q", "n", "k", "rho_d"].map(String::from).to_vec();
    let cost = observations as f64 * 1.02;
    let dof = observations - free.len();
    let ln_n = (observations as f64).ln();
    let mut convergence: Vec<f64> = (0..40)
        .map(|g| cost * (1.1 + 300.0 * (-0.2 * g as f64).exp()))
        .collect();
    convergence.extend((1..=25).map(|i| cost * (1.0 + 0.1 * (-0.4 * i as f64).exp())));
    let uncertainty = BTreeMap::from([
        ("sigma".to_string(), 0.0021),
        ("q".to_string(), 0.034),
        ("n".to_string(), 0.0042),
        ("k".to_string(), 0.0031),
        ("rho_d".to_string(), 0.0008),
    ]);
    let mut correlation = vec![vec![0.0; 5]; 5];
    for (i, row) in correlation.iter_mut().enumerate() {
        row[i] = 1.0;
    }
    correlation[0][1] = 0.87;
    correlation[1][0] = 0.87;
    let alt_cost = cost * 2.7;
    let alternative = AlternativeFit {
        model: competitor(),
        cost: alt_cost,
        reduced_chi2: alt_cost / (dof + 1) as f64,
        aic: alt_cost + 8.0,
        bic: alt_cost + 4.0 * ln_n,
    };
    // Through serde, so that fields the fit engine adds with serde defaults keep this compiling.
    let fit: FitRecord = serde_json::from_value(serde_json::json!({
        "source": source,
        "source_sha256": set.sha256,
        "points": set.points.len(),
        "elements": set.elements.iter().map(|&e| MUELLER_ELEMENT_NAMES[e]).collect::<Vec<_>>(),
        "free_parameters": free,
        "optimizer": "ga+nm",
        "seed": 7,
        "settings": { "robust_loss": "none" },
        "iterations": 65,
        "evaluations": 16_400,
        "cost": cost,
        "reduced_chi2": cost / dof as f64,
        "degrees_of_freedom": dof,
        "aic": cost + 10.0,
        "bic": cost + 5.0 * ln_n,
        "termination": "nm: simplex diameter below 1e-8",
        "rmse": { "m00": 0.0012 },
        "uncertainty": uncertainty,
        "correlation": correlation,
        "undetermined": [],
        "alternative": alternative,
        "convergence": convergence,
        "global_iterations": 40,
    }))
    .unwrap();
    Material {
        name: name.to_owned(),
        tool_version: "irpol test".into(),
        model: irpol::material::MaterialModel::Grey(truth()),
        fit: Some(fit),
    }
}
