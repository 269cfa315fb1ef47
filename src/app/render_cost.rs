//! What a render will cost, estimated before any work starts: a render is refused up front when
//! its estimate exceeds a limit the user can raise (`render --max-minutes`), with the estimate
//! and its factors — frames (`--times`), pixels × path vertices (`resolution`, `samples`,
//! `bounces`) and the wavelength nodes of spectral materials — so that `--times 0:100000:1`
//! (≈ 13 h) or a spectral table of 1e5 wavelengths is not started without a word.
//!
//! The model is a sum of the measured costs of a render's stages (release build, two cores, the
//! starter scene at 64 × 48 and a spectral material of 1e4 wavelengths, 34 284 nodes):
//! per material its tables (≈ 80 ms, plus ≈ 1 ms per wavelength node of a spectral one),
//! per path vertex ≈ 0.17 µs plus ≈ 0.4 ns per wavelength node, and per frame ≈ 0.1 s plus
//! 1 µs per pixel of writing. It is scaled by the cores available; it is meant to within a
//! factor of a few, enough to tell minutes from days.

use super::AppError;
use crate::scene::{Scene, Transport};
use crate::text::{about, duration};

/// The limit of an estimate unless `--max-minutes` says otherwise.
pub const DEFAULT_MAX_MINUTES: f64 = 60.0;

/// Seconds of tables per material, and per wavelength node of a spectral one.
const TABLE_S: f64 = 0.08;
const TABLE_NODE_S: f64 = 1.0e-3;
/// Seconds per path vertex, and per path vertex and wavelength node.
const VERTEX_S: f64 = 1.7e-7;
const VERTEX_NODE_S: f64 = 4.2e-10;
/// Seconds of writing per frame, and per pixel.
const FRAME_S: f64 = 0.1;
const FRAME_PIXEL_S: f64 = 1.0e-6;
/// The cores the constants were measured on.
const MEASURED_CORES: f64 = 2.0;

/// A render's estimated cost and its factors.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderEstimate {
    pub frames: usize,
    pub pixels: u64,
    /// Path vertices per pixel: samples × (bounces + 1), or 1 in an open world.
    pub vertices_per_pixel: u64,
    /// Wavelength nodes of the spectral material with the most (1 for grey materials only).
    pub band_nodes: usize,
    /// Seconds on this machine.
    pub seconds: f64,
    /// Of which the spectral materials' tables (per frame × frames).
    pub table_seconds: f64,
}

/// Wavelength nodes from which a render whose time goes mostly into its spectral tables is told
/// so (a table of 1e4 wavelengths gives 34 284 nodes in 8–14 µm; a shipped one, 36).
pub const MANY_BAND_NODES: usize = 2000;

impl RenderEstimate {
    /// A warning when the spectral materials' tables take most of the time, naming the node
    /// count and the share: a table far denser than its features costs time and no accuracy.
    pub fn advice(&self) -> Option<String> {
        (self.band_nodes >= MANY_BAND_NODES && self.table_seconds > 0.5 * self.seconds).then(|| {
            format!(
                "a spectral material puts {} wavelength nodes in the band: its tables take \
                 ≈ {} of this render's ≈ {}; a table denser than its features costs time, not \
                 accuracy (4 nodes per interval between table wavelengths)",
                self.band_nodes,
                duration(self.table_seconds),
                duration(self.seconds)
            )
        })
    }
}

/// The estimate of rendering `scene` at `frames` instants.
pub fn estimate(scene: &Scene, frames: usize) -> RenderEstimate {
    let pixels = u64::from(scene.camera.width) * u64::from(scene.camera.height);
    let vertices_per_pixel = match scene.transport {
        Transport::OpenWorld => 1,
        Transport::Path(settings) => {
            u64::from(settings.samples.max(1)) * (u64::from(settings.bounces) + 1)
        }
    };
    let nodes: Vec<usize> = scene
        .materials
        .iter()
        .map(|m| m.optics.band().map_or(1, |band| band.nodes().len()))
        .collect();
    let band_nodes = nodes.iter().copied().max().unwrap_or(1);
    let spectral_tables: f64 = nodes
        .iter()
        .filter(|&&n| n > 1)
        .map(|&n| n as f64 * TABLE_NODE_S)
        .sum();
    let tables = nodes.len() as f64 * TABLE_S + spectral_tables;
    let vertices = pixels as f64 * vertices_per_pixel as f64;
    let shading = vertices * (VERTEX_S + band_nodes as f64 * VERTEX_NODE_S);
    let writing = FRAME_S + pixels as f64 * FRAME_PIXEL_S;
    let cores = std::thread::available_parallelism().map_or(1.0, |n| n.get() as f64);
    let scale = frames as f64 * MEASURED_CORES / cores;
    RenderEstimate {
        frames,
        pixels,
        vertices_per_pixel,
        band_nodes,
        seconds: scale * (tables + shading + writing),
        table_seconds: scale * spectral_tables,
    }
}

/// [`estimate`], refused when over `max_minutes` (`render --max-minutes`).
pub fn check_estimate(
    scene: &Scene,
    frames: usize,
    max_minutes: f64,
) -> Result<RenderEstimate, AppError> {
    if !(max_minutes.is_finite() && max_minutes > 0.0) {
        return Err(AppError::invalid(format!(
            "--max-minutes {} must be a positive number of minutes",
            crate::text::number(max_minutes)
        )));
    }
    let estimate = estimate(scene, frames);
    if estimate.seconds <= max_minutes * 60.0 {
        return Ok(estimate);
    }
    let e = &estimate;
    let nodes = match e.band_nodes {
        1 => String::new(),
        n => format!(" × {n} wavelength nodes"),
    };
    Err(AppError::invalid(format!(
        "{}: this render is estimated at {} ({} × {} pixels × {} path vertices{nodes}), more \
         than --max-minutes {}: give --max-minutes {} to render it anyway, or render fewer \
         frames (a larger --times STEP), pixels, samples or wavelengths",
        crate::text::path(&scene.path),
        duration(e.seconds),
        crate::text::counted(e.frames, "frame"),
        e.pixels,
        e.vertices_per_pixel,
        crate::text::number(max_minutes),
        about((e.seconds / 60.0).ceil()),
    )))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dense_spectral_tables_are_pointed_out() {
        let mut estimate = RenderEstimate {
            frames: 1,
            pixels: 3072,
            vertices_per_pixel: 64,
            band_nodes: 34_284,
            seconds: 37.4,
            table_seconds: 34.3,
        };
        let advice = estimate.advice().unwrap();
        assert!(advice.contains("34284 wavelength nodes"), "{advice}");
        assert!(
            advice.contains("≈ 34.3 s of this render's ≈ 37.4 s"),
            "{advice}"
        );
        estimate.band_nodes = 36;
        assert_eq!(estimate.advice(), None);
    }
}
