//! Per-part summaries of a thermal solution: min, mean and max surface temperature over each
//! part's vertices at every recorded instant (`temperatures.csv` and the plot), with the solved
//! environment ground and enclosures' air as series of their own.

use super::{vertex_surfaces, ThermalSolution};
use crate::scene::Scene;

/// Min, mean and max over one part's vertices at every recorded instant.
pub struct PartSeries {
    /// `object/part`.
    pub name: String,
    /// (min, mean, max) per recorded instant (K).
    pub surface_k: Vec<[f64; 3]>,
}

/// Every part's series, in scene order, then the environment's ground (`environment/ground`)
/// when it is solved and each enclosure's air (`enclosure/NAME`), min = mean = max.
pub fn part_series(scene: &Scene, solution: &ThermalSolution) -> Vec<PartSeries> {
    let mut series = surface_series(scene, solution);
    let single = |name: String, values: &[f64]| PartSeries {
        name,
        surface_k: values.iter().map(|&t| [t, t, t]).collect(),
    };
    if let Some(ground_k) = &solution.ground_k {
        series.push(single("environment/ground".to_owned(), ground_k));
    }
    let enclosures = scene.thermal.as_deref().map_or(&[][..], |s| &s.enclosures);
    for (enclosure, air_k) in enclosures.iter().zip(&solution.enclosure_air_k) {
        series.push(single(format!("enclosure/{}", enclosure.name), air_k));
    }
    series
}

/// Every part's series, in scene order.
fn surface_series(scene: &Scene, solution: &ThermalSolution) -> Vec<PartSeries> {
    let vertex_surface = vertex_surfaces(scene);
    scene
        .surfaces
        .iter()
        .enumerate()
        .map(|(s, surface)| {
            let vertices: Vec<usize> = (0..vertex_surface.len())
                .filter(|&v| vertex_surface[v] as usize == s)
                .collect();
            let surface_k = solution
                .surface_k
                .iter()
                .map(|row| {
                    let values = vertices.iter().map(|&v| row[v]);
                    let min = values.clone().fold(f64::INFINITY, f64::min);
                    let max = values.clone().fold(f64::NEG_INFINITY, f64::max);
                    let mean = values.sum::<f64>() / vertices.len().max(1) as f64;
                    [min, mean, max]
                })
                .collect();
            PartSeries {
                name: format!("{}/{}", scene.object_names[surface.object], surface.part),
                surface_k,
            }
        })
        .collect()
}
