//! DoFP demosaicking on the shipped car: each method against the truth of a 2× supersampled
//! render, as Li et al. (2019) compare methods on synthetic DoFP images.

use crate::common;

use irpol::progress::Silent;
use irpol::render::dofp::{demosaic, mosaic, stokes_from_polarizers, Demosaic};
use irpol::render::instrument::metrics::psnr;
use irpol::render::render;
use irpol::scene::load_scene;

/// The car rendered at `2w` × `2h` without detector noise, averaged over 2×2 blocks: the
/// (S0, S1, S2) truth at `w` × `h`.
fn car_truth(w: usize, h: usize) -> Vec<[f64; 3]> {
    let dir = tempfile::tempdir().unwrap();
    let path = common::car_scene_with_shipped_fits(dir.path(), 2 * w as u32, 2 * h as u32, "pixel");
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("netd_mk = 20.0"), "the car's NETD line moved");
    std::fs::write(&path, text.replace("netd_mk = 20.0", "netd_mk = 0.0")).unwrap();
    let scene = load_scene(&path).unwrap();
    let image = render(&scene, &Silent).unwrap().image;
    assert_eq!((image.width, image.height), (2 * w, 2 * h));
    (0..w * h)
        .map(|p| {
            let (x, y) = (p % w, p / w);
            let mut s = [0.0; 3];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let fine = image.stokes[(2 * y + dy) * 2 * w + 2 * x + dx];
                for c in 0..3 {
                    s[c] += 0.25 * fine[c];
                }
            }
            s
        })
        .collect()
}

/// Ideal polarizer images I_α = ½(S0 + S1 cos 2α + S2 sin 2α) for α = 0°, 45°, 90°, 135°.
fn polarizers(s: [f64; 3]) -> [f64; 4] {
    [
        0.5 * (s[0] + s[1]),
        0.5 * (s[0] + s[2]),
        0.5 * (s[0] - s[1]),
        0.5 * (s[0] - s[2]),
    ]
}

#[test]
fn newton_beats_bilinear_in_s1_and_s2_on_the_car() {
    let (w, h) = (160, 120);
    let truth = car_truth(w, h);
    let raw = mosaic(w, &truth.iter().map(|&s| polarizers(s)).collect::<Vec<_>>());
    let channel = |c: usize| truth.iter().map(|s| s[c]).collect::<Vec<f64>>();
    let psnrs = |method| {
        let stokes: Vec<[f64; 3]> = demosaic(w, h, &raw, method)
            .into_iter()
            .map(stokes_from_polarizers)
            .collect();
        [0, 1, 2].map(|c| {
            let estimate: Vec<f64> = stokes.iter().map(|s| s[c]).collect();
            psnr(&channel(c), &estimate).expect("demosaicking is not exact on the car")
        })
    };
    let [bilinear, newton, residual] = Demosaic::ALL.map(psnrs);
    for (method, p) in Demosaic::ALL.iter().zip([bilinear, newton, residual]) {
        eprintln!(
            "{:>9}: PSNR S0 {:.2} dB, S1 {:.2} dB, S2 {:.2} dB",
            method.name(),
            p[0],
            p[1],
            p[2]
        );
    }
    assert!(
        newton[1] > bilinear[1],
        "S1: newton {newton:?} bilinear {bilinear:?}"
    );
    assert!(
        newton[2] > bilinear[2],
        "S2: newton {newton:?} bilinear {bilinear:?}"
    );
}
