//! Acceptance tests of the batched fixed-step BDF2 solver (docs/design.md §1.8): agreement with
//! the adaptive solver on the same forcing, a closed form, the steady surface balance, energy
//! closure of the BDF2 balance, lane independence and refused input. `--nocapture` prints the
//! measured differences.

#![allow(clippy::needless_range_loop)] // lanes are indexed in several arrays at once

use irpol::thermal::{
    Back, BatchForcing, BatchSolver, BatchState, Forcing, Grid, Lanes, Layer, LayerMaterial,
    LayerStack, Resolution, Solver, SolverControl, ThermalState, BATCH_MAX_SUBSTEP_S, LANES,
};
use std::f64::consts::PI;

const DAY: f64 = 86_400.0;
const HOUR: f64 = 3600.0;

fn asphalt_soil() -> LayerStack {
    LayerStack::new(vec![
        Layer::new(LayerMaterial::new("asphalt", 0.75, 2300.0, 920.0), 0.05),
        Layer::new(LayerMaterial::new("soil", 1.0, 1600.0, 1000.0), 0.5),
    ])
    .unwrap()
}

fn painted_steel() -> LayerStack {
    LayerStack::new(vec![
        Layer::new(LayerMaterial::new("paint", 0.2, 1200.0, 1500.0), 1e-4),
        Layer::new(LayerMaterial::new("steel", 45.0, 7850.0, 470.0), 8e-4),
    ])
    .unwrap()
}

/// Lane `l` of a diurnal day at t (s from midnight): absorbed short-wave a half-sine of peak
/// 800 W/m² (scaled per lane) from 06:00 to 18:00, cut to 10 % by a shadow that falls and lifts
/// within one 60 s sample (a window shifted 20 min per lane); long-wave 0.9 × (300 ± 20) W/m²;
/// h = 10; air 292.5 ∓ 7.5 K (coolest at 05:00).
fn diurnal(t: f64, l: usize, back: Back) -> Forcing {
    let day = (t - 6.0 * HOUR) / (12.0 * HOUR);
    let sun = if (0.0..=1.0).contains(&day) {
        800.0 * (PI * day).sin()
    } else {
        0.0
    };
    let scale = 1.0 - 0.08 * (l % 8) as f64;
    let shadow_from = 10.0 * HOUR + 1200.0 * (l % 8) as f64 + 300.0 * (l / 8) as f64;
    let shaded = t > shadow_from && t <= shadow_from + 1.5 * HOUR;
    let w = 2.0 * PI / DAY;
    let mut f = Forcing {
        front: irpol::thermal::FrontForcing {
            absorbed_w_m2: sun * scale * if shaded { 0.1 } else { 1.0 },
            longwave_in_w_m2: 0.9 * (300.0 + 20.0 * (w * t).sin() + 3.0 * l as f64),
            emissivity: 0.9,
            h_w_m2k: 10.0,
            air_k: 292.5 - 7.5 * (w * (t - 5.0 * HOUR)).cos(),
        },
        back,
        internal_w_m2: 0.0,
    };
    if let Back::Convective { .. } = back {
        f.internal_w_m2 = 20.0;
    }
    f
}

/// The lanes' forcings at one instant, packed for the batch solver.
fn pack(lanes: &[Forcing; LANES]) -> BatchForcing {
    let f = &lanes[0];
    BatchForcing {
        absorbed_w_m2: std::array::from_fn(|l| lanes[l].front.absorbed_w_m2),
        longwave_in_w_m2: std::array::from_fn(|l| lanes[l].front.longwave_in_w_m2),
        emissivity: f.front.emissivity,
        h_w_m2k: f.front.h_w_m2k,
        air_k: f.front.air_k,
        back: f.back,
        internal_w_m2: f.internal_w_m2,
    }
}

/// Surface temperatures of each lane at every step end, and the day's closure
/// |Σ(stored + deferred − net in)| / Σ|front + back + internal| per lane.
struct BatchRun {
    surface_k: Vec<Lanes>,
    closure: Lanes,
    state: BatchState,
}

fn run_batch(
    grid: &Grid,
    steps: &[f64],
    max_substep_s: f64,
    initial_k: f64,
    forcing: impl Fn(f64) -> [Forcing; LANES],
) -> BatchRun {
    let mut solver = BatchSolver::new(grid.clone(), max_substep_s, 1e-9).unwrap();
    let mut state = BatchState::uniform(grid, [initial_k; LANES]).unwrap();
    let mut surface_k = vec![state.surface_k()];
    let (mut residual, mut flux) = ([0.0; LANES], [0.0; LANES]);
    let mut t = 0.0;
    for &dt in steps {
        let (f0, f1) = (pack(&forcing(t)), pack(&forcing(t + dt)));
        let r = solver.step(&mut state, dt, &f0, &f1).unwrap();
        let net = r.net_in_j_m2();
        for l in 0..LANES {
            residual[l] += r.stored_j_m2[l] + r.deferred_j_m2[l] - net[l];
            flux[l] +=
                r.front_in_j_m2[l].abs() + r.back_in_j_m2[l].abs() + r.internal_j_m2[l].abs();
        }
        surface_k.push(state.surface_k());
        t += dt;
    }
    BatchRun {
        surface_k,
        closure: std::array::from_fn(|l| residual[l].abs() / flux[l]),
        state,
    }
}

/// The adaptive solver's surface temperature at every step end for one lane's forcing.
fn run_adaptive(
    grid: &Grid,
    steps: &[f64],
    initial_k: f64,
    forcing: impl Fn(f64) -> Forcing,
) -> Vec<f64> {
    let mut solver = Solver::new(grid.clone(), SolverControl::default()).unwrap();
    let mut state = ThermalState::uniform(grid, initial_k).unwrap();
    let mut out = vec![state.surface_k()];
    let mut t = 0.0;
    for &dt in steps {
        solver
            .step(&mut state, dt, &forcing(t), &forcing(t + dt))
            .unwrap();
        out.push(state.surface_k());
        t += dt;
    }
    out
}

/// Largest |ΔT_s| over the lanes of a 24 h day at 60 s steps against each lane's own adaptive
/// run, everywhere and away from the shadow's edges (outside the 10 min after each).
fn against_adaptive(stack: &LayerStack, back: Back, initial_k: f64, name: &str) -> (f64, f64) {
    against_adaptive_at(stack, back, initial_k, name, BATCH_MAX_SUBSTEP_S)
}

fn against_adaptive_at(
    stack: &LayerStack,
    back: Back,
    initial_k: f64,
    name: &str,
    sub: f64,
) -> (f64, f64) {
    let grid = stack.discretise(&Resolution::default()).unwrap();
    let steps = vec![60.0; (DAY / 60.0) as usize];
    let batch = run_batch(&grid, &steps, sub, initial_k, |t| {
        std::array::from_fn(|l| diurnal(t, l, back))
    });
    let (mut worst, mut smooth): (f64, f64) = (0.0, 0.0);
    for l in 0..LANES {
        let adaptive = run_adaptive(&grid, &steps, initial_k, |t| diurnal(t, l, back));
        let (mut lane_worst, mut at) = (0.0, 0);
        let edge = 10.0 * HOUR + 1200.0 * (l % 8) as f64 + 300.0 * (l / 8) as f64;
        for (i, (b, a)) in batch.surface_k.iter().zip(&adaptive).enumerate() {
            let d = (b[l] - a).abs();
            let t = i as f64 * 60.0;
            if !(edge..=edge + 600.0).contains(&t)
                && !(edge + 1.5 * HOUR..=edge + 1.5 * HOUR + 600.0).contains(&t)
            {
                smooth = smooth.max(d);
            }
            if d > lane_worst {
                (lane_worst, at) = (d, i);
            }
        }
        let range = adaptive.iter().fold(f64::NEG_INFINITY, |m, &t| m.max(t))
            - adaptive.iter().fold(f64::INFINITY, |m, &t| m.min(t));
        println!(
            "{name} lane {l}: max |ΔT_s| {lane_worst:.4} K at {:.2} h (day's range {range:.1} K), closure {:.1e}",
            at as f64 / 60.0,
            batch.closure[l]
        );
        worst = worst.max(lane_worst);
    }
    println!(
        "{name} at {sub} s: max |ΔT_s| {worst:.4} K, away from the shadow's edges {smooth:.4} K"
    );
    (worst, smooth)
}

/// (1a) Asphalt over soil, fixed back: every lane follows its own adaptive run. The largest
/// difference is in the minutes after the shadow lifts within one 60 s sample (measured 0.221 K,
/// 0.034 K elsewhere; it falls as h²: 0.057 K at 30 s sub-steps, 0.0105 K at 15 s).
#[test]
fn asphalt_over_soil_matches_the_adaptive_solver() {
    let (worst, smooth) =
        against_adaptive(&asphalt_soil(), Back::Fixed(288.0), 288.0, "asphalt/soil");
    assert!(worst < 0.25, "{worst} K");
    assert!(smooth < 0.05, "{smooth} K");
}

/// (1b) Painted steel panel with a convective back and internal heat: likewise (measured 1.27 K
/// in the minute after the shadow's edge, where the panel heats ~0.2 K/s; 0.41 K at 30 s
/// sub-steps, 0.10 K at 15 s, 0.042 K at 10 s).
#[test]
fn painted_steel_panel_matches_the_adaptive_solver() {
    let back = Back::Convective {
        h_w_m2k: 3.0,
        air_k: None,
    };
    let (worst, smooth) = against_adaptive(&painted_steel(), back, 288.0, "paint/steel");
    assert!(worst < 1.5, "{worst} K");
    assert!(smooth < 0.15, "{smooth} K");
}

/// (2) Semi-infinite solid under a step of absorbed flux: ΔT_s = 2q√(t/π)/√(kρc).
#[test]
fn semi_infinite_step_flux_matches_analytic() {
    let m = LayerMaterial::new("solid", 1.0, 2000.0, 1000.0);
    let (k, rho_c) = (m.conductivity_w_mk, m.volumetric_heat_capacity());
    let grid = LayerStack::new(vec![Layer::new(m, 1.0)])
        .unwrap()
        .discretise(&Resolution::default())
        .unwrap();
    let t0 = 300.0;
    let q: Lanes = std::array::from_fn(|l| 100.0 + 100.0 * l as f64);
    let f = BatchForcing {
        absorbed_w_m2: q,
        longwave_in_w_m2: [0.0; LANES],
        emissivity: 0.0,
        h_w_m2k: 0.0,
        air_k: t0,
        back: Back::Adiabatic,
        internal_w_m2: 0.0,
    };
    let mut solver = BatchSolver::new(grid.clone(), BATCH_MAX_SUBSTEP_S, 1e-9).unwrap();
    let mut state = BatchState::uniform(&grid, [t0; LANES]).unwrap();
    let mut t = 0.0;
    let mut worst: f64 = 0.0;
    for tc in [300.0, 1800.0, 3600.0, 4.0 * 3600.0] {
        while t < tc - 1e-9 {
            solver.step(&mut state, 60.0, &f, &f).unwrap();
            t += 60.0;
        }
        for l in 0..LANES {
            let exact = 2.0 * q[l] * (tc / PI).sqrt() / (k * rho_c).sqrt();
            let rel = ((state.surface_k()[l] - t0) - exact).abs() / exact;
            worst = worst.max(rel);
        }
        println!(
            "semi-infinite t = {tc:>6} s: lane 7 ΔT = {:.5} K, worst relative error {worst:.2e}",
            state.surface_k()[7] - t0
        );
    }
    assert!(worst < 5e-3, "{worst}");
}

/// The steady surface temperature of a stack of resistance `r` whose back is held at (or
/// convects to, through `r_back`) `back_k`: q_net(T) = (T − back_k)/(r + r_back), by bisection.
fn steady_surface(f: &Forcing, r: f64, r_back: f64, back_k: f64) -> f64 {
    let residual = |t: f64| f.front.net_flux_w_m2(t) - (t - back_k) / (r + r_back);
    let (mut lo, mut hi) = (100.0, 1000.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if residual(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// (3) Constant forcing for long enough: every lane reaches its own steady surface balance,
/// for a fixed and a convective back.
#[test]
fn constant_forcing_reaches_the_steady_surface_balance() {
    let stack = LayerStack::new(vec![
        Layer::new(LayerMaterial::new("asphalt", 0.75, 2300.0, 920.0), 0.05),
        Layer::new(LayerMaterial::new("soil", 1.0, 1600.0, 1000.0), 0.1),
    ])
    .unwrap();
    let grid = stack.discretise(&Resolution::default()).unwrap();
    let r = stack.resistance_m2k_w();
    let backs = [
        (Back::Fixed(288.0), 0.0, 288.0),
        (
            Back::Convective {
                h_w_m2k: 4.0,
                air_k: Some(295.0),
            },
            0.25,
            295.0,
        ),
    ];
    for (back, r_back, back_k) in backs {
        let lanes: [Forcing; LANES] = std::array::from_fn(|l| {
            let mut f = diurnal(12.0 * HOUR, l, back);
            f.internal_w_m2 = 0.0;
            f
        });
        let mut solver = BatchSolver::new(grid.clone(), BATCH_MAX_SUBSTEP_S, 1e-9).unwrap();
        let mut state = BatchState::uniform(&grid, [288.0; LANES]).unwrap();
        let f = pack(&lanes);
        for _ in 0..(30.0 * DAY / HOUR) as usize {
            solver.step(&mut state, HOUR, &f, &f).unwrap();
        }
        for l in 0..LANES {
            let exact = steady_surface(&lanes[l], r, r_back, back_k);
            let got = state.surface_k()[l];
            println!("steady {back:?} lane {l}: {got:.9} K, balance {exact:.9} K");
            assert!((got - exact).abs() < 1e-6, "lane {l}: {got} vs {exact}");
        }
    }
}

/// (4a) The BDF2 balance closes to round-off over a day, with sub-steps that change length
/// (steps of 60, 90 and 45 s; a longest sub-step of 40 s), for each back boundary.
#[test]
fn energy_closes_to_round_off_with_changing_steps() {
    let grid = asphalt_soil().discretise(&Resolution::default()).unwrap();
    let pattern = [60.0, 90.0, 45.0, 60.0, 60.0, 120.0];
    let mut steps = Vec::new();
    while steps.iter().sum::<f64>() < DAY {
        steps.push(pattern[steps.len() % pattern.len()]);
    }
    let backs = [
        Back::Adiabatic,
        Back::Fixed(290.0),
        Back::Convective {
            h_w_m2k: 3.0,
            air_k: None,
        },
    ];
    for back in backs {
        let run = run_batch(&grid, &steps, 40.0, 288.0, |t| {
            std::array::from_fn(|l| {
                let mut f = diurnal(t, l, back);
                f.internal_w_m2 = 50.0;
                f
            })
        });
        let worst = run.closure.iter().fold(0.0_f64, |m, &c| m.max(c));
        println!(
            "closure {back:?}: worst lane {worst:.2e}, deferred {:.3e} J/m²",
            run.state.deferred_j_m2()[0]
        );
        assert!(worst <= 1e-9, "{back:?}: {worst}");
    }
}

/// (4b) Lanes are independent: reversing the lanes' forcings reverses every node's temperatures
/// and every booked energy, bit for bit.
#[test]
fn permuting_lanes_permutes_results_bit_for_bit() {
    let grid = painted_steel().discretise(&Resolution::default()).unwrap();
    let back = Back::Convective {
        h_w_m2k: 3.0,
        air_k: None,
    };
    let steps = vec![60.0; 600];
    let forward = |t: f64| std::array::from_fn(|l| diurnal(t, l, back));
    let reversed = |t: f64| std::array::from_fn(|l| diurnal(t, LANES - 1 - l, back));
    let a = run_batch(&grid, &steps, 30.0, 288.0, forward);
    let b = run_batch(&grid, &steps, 30.0, 288.0, reversed);
    let mirrored =
        |x: &Lanes, y: &Lanes| (0..LANES).all(|l| x[l].to_bits() == y[LANES - 1 - l].to_bits());
    let (ta, tb) = (a.state.temperatures_k(), b.state.temperatures_k());
    assert!(ta.iter().zip(tb).all(|(x, y)| mirrored(x, y)));
    assert!(a
        .surface_k
        .iter()
        .zip(&b.surface_k)
        .all(|(x, y)| mirrored(x, y)));
    assert!(mirrored(&a.state.deferred_j_m2(), &b.state.deferred_j_m2()));
}

/// (5) A NaN in one lane's forcing is refused naming the lane; so are a step ≤ 0 and a bad start.
#[test]
fn bad_input_is_refused_naming_the_lane() {
    let grid = painted_steel().discretise(&Resolution::default()).unwrap();
    let mut solver = BatchSolver::new(grid.clone(), BATCH_MAX_SUBSTEP_S, 1e-9).unwrap();
    let mut state = BatchState::uniform(&grid, [288.0; LANES]).unwrap();
    let good = pack(&std::array::from_fn(|l| {
        diurnal(12.0 * HOUR, l, Back::Adiabatic)
    }));
    let mut bad = good;
    bad.absorbed_w_m2[3] = f64::NAN;
    let text = solver
        .step(&mut state, 60.0, &good, &bad)
        .unwrap_err()
        .to_string();
    assert!(
        text.contains("lane 3") && text.contains("absorbed_w_m2"),
        "{text}"
    );
    // A start forcing is read, and checked, when the step is split into sub-steps (120 s
    // here); a single sub-step evaluates the end alone.
    let mut bad = good;
    bad.longwave_in_w_m2[6] = -1.0;
    let text = solver
        .step(&mut state, 120.0, &bad, &good)
        .unwrap_err()
        .to_string();
    assert!(
        text.contains("lane 6") && text.contains("longwave_in_w_m2"),
        "{text}"
    );
    for dt in [0.0, -60.0, f64::NAN, f64::INFINITY] {
        let text = solver
            .step(&mut state, dt, &good, &good)
            .unwrap_err()
            .to_string();
        assert!(
            text.contains("time step must be positive and finite"),
            "{dt}: {text}"
        );
    }
    let mut start = [288.0; LANES];
    start[5] = f64::NAN;
    let text = BatchState::uniform(&grid, start).unwrap_err().to_string();
    assert!(text.contains("lane 5"), "{text}");
    assert!(BatchSolver::new(grid.clone(), 0.0, 1e-9).is_err());
    // Nothing refused changed the state.
    assert_eq!(state, BatchState::uniform(&grid, [288.0; LANES]).unwrap());
}

/// (1c) The batched solver's own grid (`BATCH_FIRST_CELL_M`, 44 nodes for asphalt over soil
/// instead of 61) against the adaptive solver on the default grid: the mean |ΔT_s| over the day
/// and the lanes (measured 0.5 mK on the default grid, 1.0 mK on the batch grid; 1.6 mK with a
/// 2 mm first cell), and the largest (the shadow edges' time error, 0.19 K).
#[test]
fn the_batch_grid_costs_a_millikelvin_on_average() {
    let stack = asphalt_soil();
    let fine = stack.discretise(&Resolution::default()).unwrap();
    let coarse = stack.discretise(&Resolution::batch()).unwrap();
    assert_eq!((fine.len(), coarse.len()), (61, 44));
    let steps = vec![60.0; (DAY / 60.0) as usize];
    let back = Back::Fixed(288.0);
    let batch = run_batch(&coarse, &steps, BATCH_MAX_SUBSTEP_S, 288.0, |t| {
        std::array::from_fn(|l| diurnal(t, l, back))
    });
    let (mut worst, mut sum, mut count) = (0.0f64, 0.0, 0);
    for l in 0..LANES {
        let adaptive = run_adaptive(&fine, &steps, 288.0, |t| diurnal(t, l, back));
        for (b, a) in batch.surface_k.iter().zip(&adaptive) {
            worst = worst.max((b[l] - a).abs());
            sum += (b[l] - a).abs();
            count += 1;
        }
    }
    let mean = sum / count as f64;
    eprintln!("batch grid: mean |ΔT_s| {mean:.5} K, largest {worst:.4} K");
    assert!(
        mean < 2e-3 && worst < 0.25,
        "mean {mean} K, largest {worst} K"
    );
}
