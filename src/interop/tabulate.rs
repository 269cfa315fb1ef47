//! A material's pBRDF tabulated on a `.pbsdf` grid (docs/design.md §2.10): each node's
//! directions, irpol's Mueller BRDF there (docs/design.md §1.3), re-expressed in the table's
//! frames. Nodes with either direction at or below the horizon hold zeros: finite (a NaN would
//! make Mitsuba return 0 for the whole cell) and what irpol's model is there.

use super::convention::{node_directions, table_from_psps};
use super::pbsdf::{PbsdfGrid, PbsdfTable};
use crate::optics::{Direction, Mueller};
use crate::pbrdf::Pbrdf;
use rayon::prelude::*;

/// The table-frame Mueller BRDF of `model` at angles (θ_h, θ_d, φ_d); zeros unless both
/// directions are above the horizon.
pub fn table_value(model: &Pbrdf, theta_h: f64, theta_d: f64, phi_d: f64) -> Mueller {
    let (light, view) = node_directions(theta_h, theta_d, phi_d);
    if light.z <= 0.0 || view.z <= 0.0 {
        return Mueller::zeros();
    }
    let incident = Direction::from_unit_vector(light);
    let scattered = Direction::from_unit_vector(view);
    table_from_psps(&model.mueller(&incident, &scattered), &light, &view)
}

/// The table of `models` (one per wavelength of `wavelengths_nm`) on `grid`, φ_d slabs in
/// parallel.
pub fn tabulate(models: &[Pbrdf], wavelengths_nm: Vec<u16>, grid: PbsdfGrid) -> PbsdfTable {
    assert_eq!(
        models.len(),
        wavelengths_nm.len(),
        "one model per wavelength"
    );
    let per_node = models.len() * 16;
    let slab_len = grid.theta_d.len() * grid.theta_h.len() * per_node;
    let mut values = vec![0f32; grid.phi_d.len() * slab_len];
    values
        .par_chunks_mut(slab_len)
        .zip(grid.phi_d.par_iter())
        .for_each(|(slab, &phi_d)| {
            let mut nodes = slab.chunks_mut(per_node);
            for &theta_d in &grid.theta_d {
                for &theta_h in &grid.theta_h {
                    let node = nodes.next().expect("the slab holds every node");
                    for (model, out) in models.iter().zip(node.chunks_mut(16)) {
                        let m = table_value(model, theta_h, theta_d, phi_d);
                        for (o, v) in out.iter_mut().zip(m.transpose().iter()) {
                            *o = *v as f32;
                        }
                    }
                }
            }
        });
    PbsdfTable {
        grid,
        wavelengths_nm,
        values,
    }
}
