//! The renderer's reflection integral and tables against an independent brute-force quadrature
//! of 10⁵ directions (docs/design.md §1.5): ∫ F_j0(ω_i→ω_r) L_env(ω_i) cosθ_i dΩ_i with the car scene's
//! sky (window model) and ground (with its jump at the horizon), for σ from 0.03 to 0.5.
//!
//! The brute force is stratified importance sampling: 300 × 300 half vectors drawn from the
//! slope distribution (docs/design.md §1.2 inverse CDFs) plus 100 × 100 cosine-weighted directions for
//! the diffuse term, combined with the balance heuristic; the pBRDF only enters through
//! `Pbrdf::first_column`.

use crate::common;

use irpol::optics::{Band, RefractiveIndex};
use irpol::pbrdf::{
    Direction, FacetSide, HemisphereQuadrature, Pbrdf, Shadowing, SlopeDistribution, Subsurface,
    Term,
};
use irpol::scene::config::{EnvironmentConfig, GroundConfig, SkyConfig};
use irpol::scene::environment::Environment;
use irpol::transport::kernel::{specular_kernel, KernelQuadrature};
use irpol::transport::tables::{MaterialTables, TableResolution};
use nalgebra::Vector3;
use std::f64::consts::PI;

fn autumn() -> Environment {
    let config = EnvironmentConfig {
        air_temperature_k: 283.15,
        sky: SkyConfig::Window {
            zenith_emissivity: 0.75,
        },
        ground: GroundConfig {
            temperature_k: 288.0,
            emissivity: 0.95,
            thermal: None,
        },
    };
    Environment::new(&config, &Band::lwir()).unwrap()
}

/// Facet density per solid angle of the half vector, P(θ) (docs/design.md §1.2), and its sampler.
fn facet_pdf(d: SlopeDistribution, cos_h: f64) -> f64 {
    let tan2 = (1.0 - cos_h * cos_h) / (cos_h * cos_h);
    match d {
        SlopeDistribution::Cauchy { sigma, q } => {
            let a = 2.0 * sigma * sigma;
            (q - 1.0) * a.powf(q - 1.0) / (PI * cos_h.powi(3) * (tan2 + a).powf(q))
        }
        SlopeDistribution::Gaussian { sigma } => {
            (-tan2 / (2.0 * sigma * sigma)).exp() / (2.0 * PI * sigma * sigma * cos_h.powi(3))
        }
    }
}

fn sample_tan2(d: SlopeDistribution, u: f64) -> f64 {
    match d {
        SlopeDistribution::Cauchy { sigma, q } => {
            let a = 2.0 * sigma * sigma;
            a * ((1.0 - u).powf(1.0 / (1.0 - q)) - 1.0)
        }
        SlopeDistribution::Gaussian { sigma } => -2.0 * sigma * sigma * (1.0 - u).ln(),
    }
}

/// Brute-force reflected Stokes (S0, S1, S2) toward ω_r = (sinθ_r, 0, cosθ_r).
fn brute_force(pbrdf: &Pbrdf, theta_r: f64, env: impl Fn(&Vector3<f64>) -> f64) -> [f64; 3] {
    const FACETS: usize = 300;
    const DIFFUSE: usize = 100;
    let total = (FACETS * FACETS + DIFFUSE * DIFFUSE) as f64;
    let (frac_facet, frac_diffuse) = (
        (FACETS * FACETS) as f64 / total,
        (DIFFUSE * DIFFUSE) as f64 / total,
    );
    let scattered = Direction::from_angles(theta_r, 0.0);
    let w_r = scattered.vector;
    let d = pbrdf.distribution();
    let mut sum = [0.0; 3];
    let mut add = |w_i: Vector3<f64>| {
        if w_i.z <= 0.0 {
            return;
        }
        let h = (w_i + w_r).normalize();
        let cos_beta = h.dot(&w_r);
        let pdf = frac_facet * facet_pdf(d, h.z) / (4.0 * cos_beta) + frac_diffuse * w_i.z / PI;
        let f = pbrdf.first_column(&Direction::from_unit_vector(w_i), &scattered);
        let weight = w_i.z * env(&w_i) / pdf;
        for j in 0..3 {
            sum[j] += f[j] * weight;
        }
    };
    for i in 0..FACETS {
        for j in 0..FACETS {
            let (u, v) = (
                (i as f64 + 0.5) / FACETS as f64,
                (j as f64 + 0.5) / FACETS as f64,
            );
            let tan2 = sample_tan2(d, u);
            let (sin_p, cos_p) = (2.0 * PI * v).sin_cos();
            let t = tan2.sqrt();
            let h = Vector3::new(t * cos_p, t * sin_p, 1.0).normalize();
            let cos_beta = h.dot(&w_r);
            if cos_beta > 0.0 {
                add(h * (2.0 * cos_beta) - w_r);
            }
        }
    }
    for i in 0..DIFFUSE {
        for j in 0..DIFFUSE {
            let r = ((i as f64 + 0.5) / DIFFUSE as f64).sqrt();
            let (sin_p, cos_p) = (2.0 * PI * (j as f64 + 0.5) / DIFFUSE as f64).sin_cos();
            add(Vector3::new(r * cos_p, r * sin_p, (1.0 - r * r).sqrt()));
        }
    }
    sum.map(|s| s / total)
}

/// The materials of the car scene (the shipped measurements' truths) and the inline asphalt.
fn materials() -> Vec<(String, Pbrdf)> {
    let m =
        |d, n, k, rho| Pbrdf::new(d, Shadowing::Smith, RefractiveIndex::new(n, k), rho).unwrap();
    let mut materials: Vec<(String, Pbrdf)> = common::shipped_truths()
        .into_iter()
        .map(|(name, distribution, n, k, rho_d, _)| {
            (
                format!("{name} σ{}", distribution.sigma()),
                m(distribution, n, k, rho_d),
            )
        })
        .collect();
    materials.push((
        "asphalt σ0.5".into(),
        m(
            SlopeDistribution::Cauchy { sigma: 0.5, q: 2.0 },
            1.6,
            0.1,
            0.05,
        ),
    ));
    // Volume scatterers (docs/design.md §1.10): PTFE's fit (internal facets, subsurface term with
    // d and d_c), and a strongly polarizing subsurface term under external facets.
    let volume = |d, n, k, side, rho_s, sub_d, d_c| {
        Pbrdf::new(d, Shadowing::Smith, RefractiveIndex::new(n, k), 0.0)
            .unwrap()
            .with_volume(
                side,
                Some(Subsurface {
                    term: Term::Subsurface,
                    rho_s,
                    d: sub_d,
                    n_sub: None,
                    d_c,
                    d1: None,
                }),
            )
            .unwrap()
    };
    materials.push((
        "PTFE internal+subsurface σ0.87".into(),
        volume(
            SlopeDistribution::Cauchy {
                sigma: 0.87,
                q: 2.42,
            },
            1.23,
            0.075,
            FacetSide::Internal,
            0.96,
            0.027,
            Some(-0.019),
        ),
    ));
    materials.push((
        "paint external+subsurface σ0.2 d0.6".into(),
        volume(
            SlopeDistribution::Gaussian { sigma: 0.2 },
            1.5,
            0.02,
            FacetSide::External,
            0.7,
            0.6,
            None,
        ),
    ));
    materials
}

/// Surface orientations (tilt from world up, θ_r, azimuth of ω_r from uphill), degrees: a
/// roof, a hood, a windshield, a door seen obliquely, an underside, a wall whose mirror
/// direction grazes the horizon, and pseudo-random ones.
fn geometries() -> Vec<(f64, f64, f64)> {
    let mut g = vec![
        (0.0, 40.0, 0.0),
        (12.0, 65.0, 150.0),
        (60.0, 30.0, 0.0),
        (90.0, 70.0, -40.0),
        (150.0, 35.0, 100.0),
        (90.0, 30.0, 90.0),
        (45.0, 80.0, -170.0),
    ];
    let mut x = 0.123_456_789f64;
    for _ in 0..13 {
        let mut next = || {
            x = (x * 997.0 + 0.618_033_988).fract();
            x
        };
        g.push((180.0 * next(), 85.0 * next(), 360.0 * next() - 180.0));
    }
    g
}

fn up_local(tilt: f64, phi: f64) -> Vector3<f64> {
    Vector3::new(tilt.sin() * phi.cos(), -tilt.sin() * phi.sin(), tilt.cos())
}

fn dolp(s: [f64; 3]) -> f64 {
    s[1].hypot(s[2]) / s[0]
}

#[test]
fn reflection_integral_matches_brute_force() {
    let env = autumn();
    let quadrature = KernelQuadrature {
        merge_cell: 1e-9,
        ..KernelQuadrature::default()
    };
    let hemisphere = quadrature.hemisphere();
    let diffuse_rule = hemisphere.cosine_weighted_nodes();
    for (name, pbrdf) in materials() {
        let (mut worst_s0, mut worst_dolp) = (0.0f64, 0.0f64);
        for (tilt, theta, phi) in geometries() {
            let (tilt, theta, phi) = (tilt.to_radians(), theta.to_radians(), phi.to_radians());
            let up = up_local(tilt, phi);
            let sky = |w: &Vector3<f64>| env.radiance_at_sine(w.dot(&up));
            let reference = brute_force(&pbrdf, theta, sky);
            let specular = specular_kernel(&pbrdf, theta, &quadrature).apply(sky);
            let diffuse: f64 =
                diffuse_rule.iter().map(|(w, wt)| wt * sky(w)).sum::<f64>() * pbrdf.rho_d() / PI;
            let ours = [specular[0] + diffuse, specular[1], specular[2]];
            worst_s0 = worst_s0.max((ours[0] - reference[0]).abs() / reference[0]);
            worst_dolp = worst_dolp.max((dolp(ours) - dolp(reference)).abs());
        }
        println!("integral {name}: worst S0 {worst_s0:.2e}, worst DoLP {worst_dolp:.2e}");
        assert!(worst_s0 < 5e-3, "{name}: S0 off by {worst_s0}");
        assert!(worst_dolp < 2e-3, "{name}: DoLP off by {worst_dolp}");
    }
}

#[test]
fn reflection_tables_match_brute_force() {
    let env = autumn();
    let band = Band::lwir();
    let surface = band.radiance(290.0);
    for (name, pbrdf) in materials() {
        let resolution = TableResolution::for_material(&pbrdf);
        let tables =
            MaterialTables::build(&pbrdf, &env, resolution, &KernelQuadrature::default()).unwrap();
        let (mut worst_reflected, mut worst_s0, mut worst_dolp, mut worst_reflected_dolp) =
            (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for (tilt, theta, phi) in geometries() {
            let (tilt, theta, phi) = (tilt.to_radians(), theta.to_radians(), phi.to_radians());
            let up = up_local(tilt, phi);
            let reference = brute_force(&pbrdf, theta, |w| env.radiance_at_sine(w.dot(&up)));
            let table = tables.reflected(tilt, theta.cos(), phi);
            worst_reflected = worst_reflected.max((table[0] - reference[0]).abs() / reference[0]);
            worst_reflected_dolp = worst_reflected_dolp.max((dolp(table) - dolp(reference)).abs());
            // What the camera sees from a 290 K surface: emission plus reflection.
            let e_table = tables.emissivity(theta.cos());
            let e_exact = pbrdf.emissivity(theta, &HemisphereQuadrature::default());
            let seen = [
                e_table[0] * surface + table[0],
                e_table[1] * surface + table[1],
                table[2],
            ];
            let exact = [
                e_exact[0] * surface + reference[0],
                e_exact[1] * surface + reference[1],
                reference[2],
            ];
            worst_s0 = worst_s0.max((seen[0] - exact[0]).abs() / exact[0]);
            worst_dolp = worst_dolp.max((dolp(seen) - dolp(exact)).abs());
        }
        println!(
            "table {name} {resolution:?}: reflected S0 {worst_reflected:.2e} DoLP {worst_reflected_dolp:.2e}; \
             leaving S0 {worst_s0:.2e} DoLP {worst_dolp:.2e}"
        );
        assert!(
            worst_reflected < 5e-3,
            "{name}: reflected S0 off by {worst_reflected}"
        );
        assert!(
            worst_reflected_dolp < 2e-3,
            "{name}: reflected DoLP off by {worst_reflected_dolp}"
        );
        assert!(worst_s0 < 5e-3, "{name}: S0 off by {worst_s0}");
        assert!(worst_dolp < 2e-3, "{name}: DoLP off by {worst_dolp}");
    }
}
