//! Physics checks of the pBRDF core against closed forms, invariants and the reference values of
//! docs/design.md §1.3–1.4 (which come from NIST SCATMECH and high-resolution integration).

use irpol::optics::{fresnel_amplitudes, RefractiveIndex};
use irpol::pbrdf::{Direction, HemisphereQuadrature, Pbrdf, Shadowing, SlopeDistribution};

fn direction(theta_deg: f64, phi_deg: f64) -> Direction {
    Direction::from_angles(theta_deg.to_radians(), phi_deg.to_radians())
}

fn model(
    distribution: SlopeDistribution,
    shadowing: Shadowing,
    n: f64,
    k: f64,
    rho_d: f64,
) -> Pbrdf {
    Pbrdf::new(distribution, shadowing, RefractiveIndex::new(n, k), rho_d).unwrap()
}

fn assert_rel(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * want.abs(),
        "{what}: got {got:.10e}, want {want:.10e}"
    );
}

/// docs/design.md §1.3 SCATMECH values: Gaussian s = 0.3 (σ = s/√2), N = 1.5 + 0.1i, G = 1.
/// SCATMECH's φ_s = φ_r − φ_i − 180°.
#[test]
fn matches_scatmech_reference_values() {
    let sigma = 0.3 / 2f64.sqrt();
    let gauss = SlopeDistribution::Gaussian { sigma };
    let m = model(gauss, Shadowing::None, 1.5, 0.1, 0.0);
    let mm = m.mueller(&direction(30.0, 0.0), &direction(30.0, 180.0));
    assert_rel(mm[(0, 0)], 5.08136012e-02, 1e-8, "m00");
    assert_rel(mm[(0, 1)], 1.98022899e-02, 1e-8, "m01");
    assert_rel(mm[(1, 0)], 1.98022899e-02, 1e-8, "m10");
    assert_rel(mm[(2, 2)], -4.67727312e-02, 1e-8, "m22");
    assert_rel(mm[(3, 3)], -4.67727312e-02, 1e-8, "m33");
    assert_rel(mm[(2, 3)], 1.48424927e-03, 1e-7, "m23");
    assert_rel(mm[(3, 2)], -1.48424927e-03, 1e-7, "m32");

    let (i, r) = (direction(10.0, 0.0), direction(70.0, 90.0));
    let mm = m.mueller(&i, &r);
    assert_rel(mm[(0, 0)], 8.50772992e-04, 1e-8, "oop m00");
    assert_rel(mm[(1, 0)], 4.25135713e-04, 1e-8, "oop m10");
    assert_rel(mm[(2, 0)], 1.65370386e-04, 1e-8, "oop m20");
    let ts = model(gauss, Shadowing::TorranceSparrow, 1.5, 0.1, 0.0);
    assert_rel(ts.mueller(&i, &r)[(0, 0)], 5.77611334e-04, 1e-8, "TS m00");
}

/// Smooth limit (σ → 0): ε0 = 1 − (R_s+R_p)/2, ε1 = (R_p − R_s)/2 (docs/design.md §1.4).
#[test]
fn emissivity_reaches_the_smooth_surface_fresnel_limit() {
    let quad = HemisphereQuadrature::default();
    let eps = RefractiveIndex::new(1.5, 0.1).permittivity();
    for &(sigma, tol) in &[(0.02, 2e-3), (0.002, 2e-4), (0.0002, 2e-5)] {
        let m = model(
            SlopeDistribution::Cauchy { sigma, q: 4.0 },
            Shadowing::Smith,
            1.5,
            0.1,
            0.0,
        );
        for theta in [0.0f64, 30.0, 60.0, 75.0] {
            let (rs, rp) = fresnel_amplitudes(theta.to_radians().cos(), eps);
            let (rs2, rp2) = (rs.norm_sqr(), rp.norm_sqr());
            let e = m.emissivity(theta.to_radians(), &quad);
            assert!(
                (e[0] - (1.0 - 0.5 * (rs2 + rp2))).abs() < tol,
                "σ={sigma} θ={theta}: ε0 {}",
                e[0]
            );
            assert!(
                (e[1] - 0.5 * (rp2 - rs2)).abs() < tol,
                "σ={sigma} θ={theta}: ε1 {}",
                e[1]
            );
        }
    }
    // docs/design.md §1.4 smooth reference at 60°.
    let m = model(
        SlopeDistribution::Gaussian { sigma: 1e-4 },
        Shadowing::Smith,
        1.5,
        0.1,
        0.0,
    );
    let e = m.emissivity(60f64.to_radians(), &quad);
    assert!(
        (e[0] - 0.908286).abs() < 2e-6 && (e[1] + 0.089534).abs() < 2e-6,
        "{e:?}"
    );
}

/// docs/design.md §1.4 rough-surface emissivity references (N = 1.5 + 0.1i).
#[test]
fn emissivity_matches_reference_values() {
    let quad = HemisphereQuadrature::default();
    let cauchy = SlopeDistribution::Cauchy { sigma: 0.2, q: 2.0 };
    let gauss = SlopeDistribution::Gaussian {
        sigma: 0.3 / 2f64.sqrt(),
    };
    let cases = [
        (cauchy, Shadowing::None, 60.0, 0.91947, -0.05425),
        (cauchy, Shadowing::None, 80.0, 0.76407, -0.10712),
        (cauchy, Shadowing::Smith, 60.0, 0.93559, -0.04479),
        (cauchy, Shadowing::Smith, 80.0, 0.87410, -0.06362),
        (gauss, Shadowing::Smith, 60.0, 0.92083, -0.06190),
    ];
    for (dist, shadow, theta, e0, e1) in cases {
        let e = model(dist, shadow, 1.5, 0.1, 0.0).emissivity(f64::to_radians(theta), &quad);
        // 1e-5: the references are given to 5 decimals (0.91947 is 0.9194781 truncated).
        assert!(
            (e[0] - e0).abs() < 1e-5,
            "{dist:?} {shadow:?} {theta}: ε0 {} vs {e0}",
            e[0]
        );
        assert!(
            (e[1] - e1).abs() < 1e-5,
            "{dist:?} {shadow:?} {theta}: ε1 {} vs {e1}",
            e[1]
        );
        assert!(
            e[2].abs() < 1e-12 && e[3] == 0.0,
            "isotropic: ε2 = ε3 = 0, got {e:?}"
        );
    }
}

/// The default quadrature against a much finer one: 1e-5 absolute for σ ≥ 0.02 up to 89°
/// (3e-4 with Torrance–Sparrow, whose min() puts kinks inside the integration domain).
#[test]
fn default_emissivity_quadrature_is_accurate_to_1e5() {
    let (default, fine) = (
        HemisphereQuadrature::default(),
        HemisphereQuadrature::fine(),
    );
    let models = [
        (
            SlopeDistribution::Cauchy {
                sigma: 0.02,
                q: 1.6,
            },
            Shadowing::Smith,
            0.0,
        ),
        (
            SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
            Shadowing::None,
            0.0,
        ),
        (
            SlopeDistribution::Cauchy {
                sigma: 0.02,
                q: 1.2,
            },
            Shadowing::None,
            0.0,
        ),
        (
            SlopeDistribution::Cauchy { sigma: 0.5, q: 3.0 },
            Shadowing::TorranceSparrow,
            0.05,
        ),
        (
            SlopeDistribution::Gaussian { sigma: 0.02 },
            Shadowing::Smith,
            0.0,
        ),
        (
            SlopeDistribution::Gaussian { sigma: 0.4 },
            Shadowing::Smith,
            0.1,
        ),
    ];
    for (dist, shadow, rho) in models {
        let m = model(dist, shadow, 1.2, 0.2, rho);
        for theta in [0.0f64, 20.0, 45.0, 70.0, 80.0, 85.0, 88.0, 89.0] {
            let a = m.emissivity(theta.to_radians(), &default);
            let b = m.emissivity(theta.to_radians(), &fine);
            let err = (a - b).abs().max();
            let tol = if shadow == Shadowing::TorranceSparrow {
                3e-4
            } else {
                1e-5
            };
            assert!(
                err < tol,
                "{dist:?} {shadow:?} θ={theta}: |Δε| = {err:.2e} ({a:?} vs {b:?})"
            );
        }
    }
}

fn sample_models() -> Vec<Pbrdf> {
    vec![
        model(
            SlopeDistribution::Cauchy { sigma: 0.1, q: 1.8 },
            Shadowing::None,
            1.2,
            0.2,
            0.0,
        ),
        model(
            SlopeDistribution::Cauchy { sigma: 0.3, q: 2.5 },
            Shadowing::Smith,
            1.55,
            0.05,
            0.03,
        ),
        model(
            SlopeDistribution::Gaussian { sigma: 0.2 },
            Shadowing::TorranceSparrow,
            10.0,
            30.0,
            0.0,
        ),
        model(
            SlopeDistribution::Gaussian { sigma: 0.15 },
            Shadowing::Smith,
            3.0,
            1.0,
            0.01,
        ),
    ]
}

fn geometry_grid() -> Vec<(Direction, Direction)> {
    let mut pairs = Vec::new();
    for ti in [0.0, 15.0, 40.0, 70.0, 85.0] {
        for tr in [0.0, 10.0, 45.0, 60.0, 88.0] {
            for (pi, pr) in [(0.0, 180.0), (0.0, 0.0), (30.0, 95.0), (200.0, 330.0)] {
                pairs.push((direction(ti, pi), direction(tr, pr)));
            }
        }
    }
    pairs
}

/// Helmholtz reciprocity in the psps frames: M(r→i) = Q Mᵀ(i→r) Q with Q = diag(1, 1, −1, 1)
/// (the p axis flips when the propagation direction reverses).
#[test]
fn mueller_brdf_is_reciprocal() {
    let q = nalgebra::Matrix4::from_diagonal(&nalgebra::Vector4::new(1.0, 1.0, -1.0, 1.0));
    for m in sample_models() {
        for (i, r) in geometry_grid() {
            let forward = m.mueller(&i, &r);
            let backward = m.mueller(&r, &i);
            let err = (backward - q * forward.transpose() * q).abs().max();
            assert!(
                err <= 1e-12 * forward[(0, 0)].max(1e-300),
                "{m:?}: {forward} vs {backward}"
            );
        }
    }
}

/// A Mueller–Jones matrix: |m_ij| ≤ m00, and the scattered light's DoLP ≤ 1; the fast first-column
/// path equals the full matrix's first column.
#[test]
fn mueller_elements_are_bounded_and_fast_path_agrees() {
    for m in sample_models() {
        for (i, r) in geometry_grid() {
            let full = m.mueller(&i, &r);
            let m00 = full[(0, 0)];
            assert!(m00 >= 0.0);
            assert!(full.abs().max() <= m00 * (1.0 + 1e-12), "{full}");
            let col = m.first_column(&i, &r);
            assert!((col - full.column(0)).abs().max() <= 1e-15 * m00.max(1e-300));
            assert!((col[1].powi(2) + col[2].powi(2)).sqrt() <= col[0] * (1.0 + 1e-12));
        }
    }
}

/// The slope-space hemispherical quadrature against a brute-force direction grid over ω_i, an
/// independent check of the change of variables dΩ_i = 4 cosβ dΩ_h and of the horizon cut.
#[test]
fn hemispherical_reflectance_matches_brute_force_direction_grid() {
    let quad = HemisphereQuadrature::default();
    let rule = gauss_quad::legendre::GaussLegendre::new(400.try_into().unwrap());
    let phi_nodes = 720;
    for m in sample_models().into_iter().skip(1) {
        for theta_r in [0.0f64, 35.0, 70.0] {
            let r = direction(theta_r, 180.0);
            let fast = m.reflected_stokes(&r, |_| 1.0, &quad);
            let mut brute = nalgebra::Vector4::zeros();
            for &(x, w) in rule.as_node_weight_pairs() {
                let theta_i = 0.25 * std::f64::consts::PI * (x + 1.0);
                for j in 0..phi_nodes {
                    let phi_i = (j as f64 + 0.5) * 2.0 * std::f64::consts::PI / phi_nodes as f64;
                    let i = Direction::from_angles(theta_i, phi_i);
                    let dw = w
                        * 0.25
                        * std::f64::consts::PI
                        * theta_i.sin()
                        * 2.0
                        * std::f64::consts::PI
                        / phi_nodes as f64;
                    brute += m.first_column(&i, &r) * theta_i.cos() * dw;
                }
            }
            assert!(
                (fast - brute).abs().max() < 2e-4,
                "{m:?} θr={theta_r}: {fast:?} vs {brute:?}"
            );
        }
    }
}

/// Energy: with Smith shadowing the directional-hemispherical reflectance stays ≤ 1 for σ up to
/// 0.5 (here for a perfect conductor-like index, the worst case), and checked_emissivity reports the
/// unshadowed model's excess at grazing angles instead of clamping it.
#[test]
fn smith_conserves_energy_and_excess_reflectance_is_reported() {
    let quad = HemisphereQuadrature::default();
    for sigma in [0.05, 0.2, 0.5] {
        for dist in [
            SlopeDistribution::Cauchy { sigma, q: 1.6 },
            SlopeDistribution::Gaussian { sigma },
        ] {
            let m = model(dist, Shadowing::Smith, 10.0, 60.0, 0.0);
            for theta in [0.0f64, 45.0, 75.0, 85.0, 89.0] {
                let e = m.checked_emissivity(theta.to_radians(), &quad).unwrap();
                assert!(
                    e[0] >= -1e-9,
                    "{dist:?} θ={theta}: reflectance {}",
                    1.0 - e[0]
                );
            }
        }
    }
    // ρ_d lowers ε0 by exactly ρ_d (docs/design.md §1.4), and ρ(θ) = 1 − ε0(θ).
    let smooth = model(
        SlopeDistribution::Gaussian { sigma: 0.1 },
        Shadowing::Smith,
        1.5,
        0.1,
        0.0,
    );
    let diffuse = model(
        SlopeDistribution::Gaussian { sigma: 0.1 },
        Shadowing::Smith,
        1.5,
        0.1,
        0.04,
    );
    for theta in [0.0f64, 50.0, 85.0] {
        let (a, b) = (
            smooth.emissivity(theta.to_radians(), &quad),
            diffuse.emissivity(theta.to_radians(), &quad),
        );
        assert!((a[0] - b[0] - 0.04).abs() < 1e-12 && (a[1] - b[1]).abs() < 1e-15);
        let rho = diffuse.directional_hemispherical_reflectance(theta.to_radians(), &quad);
        assert!((rho - (1.0 - b[0])).abs() < 1e-15);
    }
    let bare = model(
        SlopeDistribution::Cauchy { sigma: 0.5, q: 1.6 },
        Shadowing::None,
        10.0,
        60.0,
        0.0,
    );
    let err = bare
        .checked_emissivity(89f64.to_radians(), &quad)
        .unwrap_err();
    assert!(err.to_string().contains("> 1"), "{err}");
}

/// Isothermal enclosure (docs/design.md §1.5): reflected uniform radiance plus emission is (L, 0, 0, 0).
#[test]
fn isothermal_enclosure_is_unpolarized_blackbody() {
    let quad = HemisphereQuadrature::default();
    let radiance = irpol::optics::Band::lwir().radiance(300.0);
    for m in sample_models() {
        for theta in [0.0f64, 30.0, 60.0, 80.0] {
            let d = direction(theta, 0.0);
            let s = m.reflected_stokes(&d, |_| radiance, &quad)
                + m.emissivity(theta.to_radians(), &quad) * radiance;
            assert!(
                (s[0] / radiance - 1.0).abs() < 1e-12
                    && s.fixed_rows::<3>(1).norm() < 1e-12 * radiance
            );
            // and emission alone is p-polarized (ε1 < 0) for θ > 0
            if theta > 0.0 {
                assert!(m.emissivity(theta.to_radians(), &quad)[1] < 0.0);
            }
        }
    }
}

#[test]
fn bad_parameters_are_refused_with_a_clear_error() {
    let idx = RefractiveIndex::new(1.5, 0.1);
    let c = |sigma, q| SlopeDistribution::Cauchy { sigma, q };
    let cases: Vec<(Result<Pbrdf, _>, &str)> = vec![
        (Pbrdf::new(c(0.0, 2.0), Shadowing::None, idx, 0.0), "σ = 0"),
        (Pbrdf::new(c(0.1, 1.0), Shadowing::None, idx, 0.0), "q = 1"),
        (
            Pbrdf::new(c(0.1, 1.4), Shadowing::Smith, idx, 0.0),
            "q > 1.5",
        ),
        (
            Pbrdf::new(
                c(0.1, 2.0),
                Shadowing::None,
                RefractiveIndex::new(0.0, 0.1),
                0.0,
            ),
            "n = 0",
        ),
        (
            Pbrdf::new(
                c(0.1, 2.0),
                Shadowing::None,
                RefractiveIndex::new(1.5, -0.1),
                0.0,
            ),
            "k = -0.1",
        ),
        (
            Pbrdf::new(c(f64::NAN, 2.0), Shadowing::None, idx, 0.0),
            "σ = NaN",
        ),
        (
            Pbrdf::new(c(0.1, 2.0), Shadowing::None, idx, -0.01),
            "ρ_d = -0.01",
        ),
    ];
    for (result, needle) in cases {
        let message = result.unwrap_err().to_string();
        assert!(message.contains(needle), "{message:?} lacks {needle:?}");
    }
}

/// Hemispherical emissivity (the thermal model's default ε, docs/design.md §1.8): in the smooth limit it
/// is 1 − 2∫ R(θ) cosθ sinθ dθ with R the unpolarized Fresnel reflectance, integrated here by a
/// 20 000-point midpoint rule in θ; ρ_d lowers it by exactly ρ_d; a rough surface agrees with a
/// brute-force midpoint integral of its own ε0(θ).
#[test]
fn hemispherical_emissivity_is_the_flux_weighted_mean() {
    let eps = RefractiveIndex::new(1.5, 0.1).permittivity();
    let n = 20_000;
    let smooth_reference: f64 = 1.0
        - (0..n)
            .map(|i| {
                let theta = (i as f64 + 0.5) / n as f64 * std::f64::consts::FRAC_PI_2;
                let (rs, rp) = fresnel_amplitudes(theta.cos(), eps);
                let r = 0.5 * (rs.norm_sqr() + rp.norm_sqr());
                2.0 * r * theta.cos() * theta.sin() * std::f64::consts::FRAC_PI_2 / n as f64
            })
            .sum::<f64>();
    let cauchy = |sigma| SlopeDistribution::Cauchy { sigma, q: 4.0 };
    let smooth = model(cauchy(0.0002), Shadowing::Smith, 1.5, 0.1, 0.0);
    let e = smooth.hemispherical_emissivity();
    assert!(
        (e - smooth_reference).abs() < 2e-4,
        "{e} vs {smooth_reference}"
    );

    let rough = model(cauchy(0.2), Shadowing::Smith, 1.5, 0.1, 0.0);
    let with_rho = model(cauchy(0.2), Shadowing::Smith, 1.5, 0.1, 0.05);
    let (a, b) = (
        rough.hemispherical_emissivity(),
        with_rho.hemispherical_emissivity(),
    );
    assert!((a - b - 0.05).abs() < 1e-9, "{a} − {b}");

    let quad = HemisphereQuadrature::default();
    let m = 400;
    let brute: f64 = (0..m)
        .map(|i| {
            let theta = (i as f64 + 0.5) / m as f64 * std::f64::consts::FRAC_PI_2;
            let e0 = rough.emissivity(theta, &quad)[0];
            2.0 * e0 * theta.cos() * theta.sin() * std::f64::consts::FRAC_PI_2 / m as f64
        })
        .sum();
    assert!((a - brute).abs() < 1e-4, "{a} vs brute force {brute}");
    assert!(
        a > smooth_reference,
        "roughness raises ε: {a} vs {smooth_reference}"
    );
}
