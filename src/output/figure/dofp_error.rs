//! `dofp_error.png`: how far the division-of-focal-plane camera's polarization is from the
//! noise-free truth.

use super::canvas::{draw_panel, Canvas};
use super::colouring::{robust_range, widen};
use super::{cell_size, ranged_pixels, LinearPanel};
use crate::output::colormap::{DIVERGING, SEQUENTIAL};
use crate::render::film::{dolp_aop, StokesImage};
use crate::render::instrument::metrics::{aop_difference, AOP_DOLP_THRESHOLD};
use crate::render::instrument::DofpImages;
use crate::scene::Scene;
use rayon::prelude::*;
use std::io;

/// `dofp_error.png` (with `[sensor.dofp]`): the DoLP of the noise-free radiance and of the DoFP
/// camera on one colour range, their difference, and the AoP error where the true DoLP exceeds
/// 1 % (elsewhere the angle is noise), in a 2 × 2 sheet.
pub fn dofp_error_png(
    scene: &Scene,
    image: &StokesImage,
    dofp: &DofpImages,
) -> io::Result<Vec<u8>> {
    let ranged = ranged_pixels(image);
    let panels = dofp_panels(scene, dofp, &ranged).map(|p| p.panel(&ranged, &scene.preview));
    let (w, h) = cell_size(image.width, image.height);
    let cells: Vec<Canvas> = panels
        .iter()
        .map(|p| draw_panel(p, image.width, image.height, w, h))
        .collect::<io::Result<_>>()?;
    let (cell_w, cell_h) = (cells[0].width, cells[0].height);
    let mut sheet = Canvas::white(2 * cell_w, 2 * cell_h);
    for (i, cell) in cells.iter().enumerate() {
        sheet.blit(cell, (i % 2) * cell_w, (i / 2) * cell_h);
    }
    sheet.png()
}

/// The four panels of [`dofp_error_png`]; the two DoLP panels share the truth's range over the
/// `ranged` pixels.
fn dofp_panels(scene: &Scene, dofp: &DofpImages, ranged: &[bool]) -> [LinearPanel; 4] {
    let polarization = |s: &[f64; 3]| dolp_aop([s[0], s[1], s[2], 0.0]);
    let truth: Vec<(f64, f64)> = dofp.truth.par_iter().map(polarization).collect();
    let camera: Vec<(f64, f64)> = dofp.stokes.par_iter().map(polarization).collect();
    let dolp_percent = |v: &[(f64, f64)]| v.iter().map(|p| 100.0 * p.0).collect::<Vec<f64>>();
    let (true_dolp, camera_dolp) = (dolp_percent(&truth), dolp_percent(&camera));
    let ranging: Vec<f64> = true_dolp
        .iter()
        .zip(ranged)
        .filter(|(_, &r)| r)
        .map(|(&v, _)| v)
        .collect();
    let top = widen(0.0, robust_range(ranging, 0.0, 0.999, 0.0).1).1;
    let panel = |title: String, values, fixed, symmetric, map| LinearPanel {
        file: "dofp_error.png",
        title,
        values,
        fixed,
        symmetric,
        map,
    };
    let method = scene.sensor.dofp.map_or("bilinear", |d| d.demosaic.name());
    let difference = camera_dolp
        .iter()
        .zip(&true_dolp)
        .map(|(c, t)| c - t)
        .collect();
    let aop_error = truth
        .iter()
        .zip(&camera)
        .map(|(t, c)| match t.0 > AOP_DOLP_THRESHOLD {
            true => aop_difference(c.1, t.1).to_degrees(),
            false => f64::NAN,
        })
        .collect();
    let dolp_range = Some([0.0, top]);
    [
        panel(
            "DoLP, noise-free truth (%)".into(),
            true_dolp,
            dolp_range,
            false,
            &SEQUENTIAL,
        ),
        panel(
            format!("DoLP, DoFP camera, {method} (%)"),
            camera_dolp,
            dolp_range,
            false,
            &SEQUENTIAL,
        ),
        panel(
            "DoLP error, camera − truth (%)".into(),
            difference,
            None,
            true,
            &DIVERGING,
        ),
        panel(
            "AoP error (°), true DoLP > 1 %".into(),
            aop_error,
            Some([-45.0, 45.0]),
            true,
            &DIVERGING,
        ),
    ]
}
