use irpol::optics::{Band, RefractiveIndex};
use irpol::pbrdf::*;
use irpol::render::kernel::*;
use irpol::render::tables::*;
use irpol::scene::config::*;
use irpol::scene::environment::Environment;
use nalgebra::Vector3;
use std::time::Instant;
use rand::{Rng, SeedableRng};

#[test]
fn accuracy() {
    let band = Band::lwir();
    let env = Environment::new(&EnvironmentConfig { air_temperature_k: 283.15, sky: SkyConfig::Window { zenith_emissivity: 0.75 }, ground: GroundConfig { temperature_k: 288.0, emissivity: 0.95 } }, &band).unwrap();
    let l290 = band.radiance(290.0);
    for (d, sh) in [
        (SlopeDistribution::Gaussian { sigma: 0.03 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.05, q: 3.0 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.1, q: 2.0 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.2, q: 2.0 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.5, q: 2.0 }, Shadowing::Smith),
    ] {
        let p = Pbrdf::new(d, sh, RefractiveIndex::new(1.6, 0.1), 0.0).unwrap();
        let res = TableResolution::for_material(&p);
        let t = Instant::now();
        let tables = MaterialTables::build(&p, &env, res, &KernelQuadrature::default()).unwrap();
        let dt = t.elapsed().as_secs_f64();
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let (mut e_s0, mut e_dolp, mut e_tot, mut e_tot_dolp) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        let mut worst = (0.0, 0.0, 0.0);
        for _ in 0..300 {
            let tilt: f64 = rng.random::<f64>() * 3.14159;
            let theta: f64 = rng.random::<f64>() * 1.4;
            let phi: f64 = (rng.random::<f64>() * 2.0 - 1.0) * 3.14159;
            let up = Vector3::new(tilt.sin() * phi.cos(), -tilt.sin() * phi.sin(), tilt.cos());
            let exact = p.reflected_stokes(&Direction::from_angles(theta, 0.0), |w| env.radiance_at_sine(w.dot(&up)), &HemisphereQuadrature::default());
            let tab = tables.reflected(tilt, theta, phi);
            let rel = (tab[0] - exact[0]).abs() / exact[0];
            let dolp_t = (tab[1].hypot(tab[2])) / tab[0];
            let dolp_e = exact[1].hypot(exact[2]) / exact[0];
            if rel > e_s0 { worst = (tilt.to_degrees(), theta.to_degrees(), phi.to_degrees()); }
            e_s0 = e_s0.max(rel);
            e_dolp = e_dolp.max((dolp_t - dolp_e).abs());
            // total leaving radiance at 290 K
            let em = p.emissivity(theta, &HemisphereQuadrature::default());
            let et = tables.emissivity(theta);
            let tot_e = [em[0] * l290 + exact[0], em[1] * l290 + exact[1], exact[2]];
            let tot_t = [et[0] * l290 + tab[0], et[1] * l290 + tab[1], tab[2]];
            e_tot = e_tot.max((tot_t[0] - tot_e[0]).abs() / tot_e[0]);
            e_tot_dolp = e_tot_dolp.max((tot_t[1].hypot(tot_t[2]) / tot_t[0] - tot_e[1].hypot(tot_e[2]) / tot_e[0]).abs());
        }
        println!("{d:?}: res {res:?} build {dt:.3}s  refl S0 rel {e_s0:.2e} (worst at {worst:?}) refl DoLP {e_dolp:.2e}  total S0 rel {e_tot:.2e} total DoLP {e_tot_dolp:.2e}");
    }
}

#[test]
fn breakdown() {
    for (d, sh) in [
        (SlopeDistribution::Gaussian { sigma: 0.03 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.05, q: 3.0 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.5, q: 2.0 }, Shadowing::Smith),
    ] {
        let p = Pbrdf::new(d, sh, RefractiveIndex::new(1.6, 0.1), 0.0).unwrap();
        for cell in [1e-9, 1.0, 2.0, 4.0] {
            let q = KernelQuadrature { merge_cell: f64::to_radians(cell), ..KernelQuadrature::default() };
            let t = Instant::now();
            let mut n = 0;
            for i in 0..46 { n += specular_kernel(&p, (i as f64 * 89.0 / 45.0).to_radians(), &q).directions.len(); }
            println!("{d:?} cell {cell}: kernels {:.3}s, mean nodes {}", t.elapsed().as_secs_f64(), n / 46);
        }
    }
}
#[test]
fn counts() {
    for (d, sh) in [
        (SlopeDistribution::Gaussian { sigma: 0.03 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.05, q: 3.0 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.1, q: 2.0 }, Shadowing::Smith),
        (SlopeDistribution::Cauchy { sigma: 0.5, q: 2.0 }, Shadowing::Smith),
    ] {
        let p = Pbrdf::new(d, sh, RefractiveIndex::new(1.6, 0.1), 0.0).unwrap();
        let res = TableResolution::for_material(&p);
        let q = KernelQuadrature { merge_cell: res.merge_cell_deg.to_radians(), ..KernelQuadrature::default() };
        let mut n = 0;
        for i in 0..46 { n += specular_kernel(&p, (i as f64 * 89.0 / 45.0).to_radians(), &q).directions.len(); }
        println!("{d:?}: {res:?} mean nodes {} → node-entries {:.2e}", n / 46, (n / 46 * res.entries()) as f64);
    }
}
