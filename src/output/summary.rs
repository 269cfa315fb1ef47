//! `summary.json` of a render (docs/design.md §4): its schema and how it is filled from the
//! scene and the rendered image.

use super::channel::{Channel, ErrorSummary, Stats};
use super::ground_truth::{id_maps, CameraSummary, IdMaps};
use crate::optics::TemperatureLookup;
use crate::render::film::{StokesImage, BACKGROUND};
use crate::render::instrument::metrics::CameraMetrics;
use crate::render::TableResolution;
use crate::render::{Rendered, Timings};
use crate::scene::config::Shading;
use crate::scene::{Scene, Transport};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;

#[derive(Clone, Debug, Serialize)]
pub struct ChannelSummary {
    pub name: &'static str,
    pub unit: &'static str,
    /// Over object pixels; null when the camera sees no object.
    pub object_pixels: Option<Stats>,
    /// Monte Carlo standard error of a Stokes channel relative to S0, over object pixels
    /// (absent for derived channels).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub relative_standard_error: Option<ErrorSummary>,
}

/// How light was transported (docs/design.md §1.7, §2.6).
#[derive(Clone, Debug, Serialize)]
pub struct TransportSummary {
    pub open_world: bool,
    pub bounces: Option<u32>,
    pub samples: Option<u32>,
    pub seed: Option<u64>,
    /// The sun, if the scene has one above the horizon.
    pub sun: Option<SunSummary>,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct SunSummary {
    pub elevation_deg: f64,
    /// Clockwise from north (+y) toward east (+x).
    pub azimuth_deg: f64,
    /// Band irradiance on a surface facing the sun.
    pub irradiance_w_m2: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct PixelCounts {
    pub total: usize,
    pub object: usize,
    pub background: usize,
    pub per_object: BTreeMap<String, usize>,
    /// Keyed "object/part".
    pub per_part: BTreeMap<String, usize>,
}

#[derive(Clone, Debug, Serialize)]
pub struct MaterialSummary {
    pub name: String,
    pub origin: String,
    pub table: TableResolution,
    /// A spectral material is band-integrated (docs/design.md §1.9) on this many wavelength nodes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub band_nodes: Option<usize>,
}

/// `summary.json`, also returned to the caller.
#[derive(Clone, Debug, Serialize)]
pub struct RenderSummary {
    pub scene: String,
    pub output_dir: String,
    pub width: usize,
    pub height: usize,
    pub shading: Shading,
    pub band_um: [f64; 2],
    pub pixels: PixelCounts,
    pub channels: Vec<ChannelSummary>,
    /// Brightness temperature of S0 over object pixels (K).
    pub apparent_temperature_k: Option<Stats>,
    pub transport: TransportSummary,
    /// The atmospheric path, if the scene has one (`kind`, and a table's file, source, geometry).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub atmosphere: Option<crate::atmosphere::AtmosphereSummary>,
    /// The instant of the thermal run shown (`render --time`), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub thermal_instant: Option<crate::scene::ThermalInstant>,
    /// Probable mistakes noticed while loading and rendering.
    pub warnings: Vec<String>,
    /// Intrinsics and pose (ground truth).
    pub camera: CameraSummary,
    /// Reconstruction quality of the camera (optics, detector, DoFP) against the noise-free
    /// radiance; absent for the ideal camera.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reconstruction: Option<CameraMetrics>,
    /// What the IDs of `object_id.tif` and `part_id.tif` are.
    pub ids: IdMaps,
    pub materials: Vec<MaterialSummary>,
    pub timings_s: Timings,
    pub files: Vec<String>,
}

/// `summary.json` of a render whose files are `files` (timings as the render measured them).
pub(super) fn summarize(
    scene: &Scene,
    rendered: &Rendered,
    out_dir: &Path,
    channels: &[(Channel, Vec<f32>)],
    camera: CameraSummary,
    files: Vec<String>,
) -> RenderSummary {
    let image = &rendered.image;
    let (w, h) = (image.width, image.height);
    let pixels = pixel_counts(scene, image);
    let warnings = render_warnings(scene, &pixels.per_object);
    let (lo, hi) = scene.sensor.band.limits_um();
    RenderSummary {
        scene: scene.path.display().to_string(),
        output_dir: out_dir.display().to_string(),
        width: w,
        height: h,
        shading: scene.shading,
        band_um: [lo, hi],
        pixels,
        channels: channel_summaries(image, channels),
        apparent_temperature_k: apparent_temperature(scene, image, &channels[0].1),
        transport: transport_summary(scene),
        atmosphere: scene.atmosphere.as_ref().map(|a| a.summary()),
        thermal_instant: scene.thermal_instant.clone(),
        warnings,
        camera,
        reconstruction: rendered.camera_metrics.clone(),
        ids: id_maps(scene),
        materials: material_summaries(scene, rendered),
        timings_s: rendered.timings,
        files,
    }
}

fn channel_summaries(image: &StokesImage, channels: &[(Channel, Vec<f32>)]) -> Vec<ChannelSummary> {
    channels
        .iter()
        .map(|(c, data)| ChannelSummary {
            name: c.name(),
            unit: c.unit(),
            object_pixels: image.object_stats(data),
            relative_standard_error: stokes_index(*c).and_then(|j| image.relative_error(j)),
        })
        .collect()
}

/// Brightness temperature of S0 (`s0`) over the object pixels.
fn apparent_temperature(scene: &Scene, image: &StokesImage, s0: &[f32]) -> Option<Stats> {
    image.object_stats(s0).map(|s| {
        let lookup = TemperatureLookup::new(&scene.sensor.band, s.min.max(0.0), s.max.max(0.0));
        let temperatures: Vec<f32> = s0.iter().map(|&r| lookup.at(r as f64) as f32).collect();
        let mean = image.object_stats(&temperatures).map_or(0.0, |t| t.mean);
        Stats {
            min: lookup.at(s.min),
            max: lookup.at(s.max),
            mean,
        }
    })
}

/// Pixels in all, on objects, on background, per object and per part.
fn pixel_counts(scene: &Scene, image: &StokesImage) -> PixelCounts {
    let mut per_surface = vec![0usize; scene.surfaces.len()];
    for &s in image.surface.iter().filter(|&&s| s != BACKGROUND) {
        per_surface[s as usize] += 1;
    }
    let (mut per_object, mut per_part) = (BTreeMap::new(), BTreeMap::new());
    for (surface, &count) in scene.surfaces.iter().zip(&per_surface) {
        let object = scene.object_names[surface.object].clone();
        per_part.insert(format!("{object}/{}", surface.part), count);
        *per_object.entry(object).or_insert(0) += count;
    }
    let object_pixels: usize = per_surface.iter().sum();
    let total = image.width * image.height;
    PixelCounts {
        total,
        object: object_pixels,
        background: total - object_pixels,
        per_object,
        per_part,
    }
}

fn material_summaries(scene: &Scene, rendered: &Rendered) -> Vec<MaterialSummary> {
    scene
        .materials
        .iter()
        .zip(&rendered.table_resolutions)
        .map(|(m, &table)| MaterialSummary {
            name: m.name.clone(),
            origin: m.origin.clone(),
            table,
            band_nodes: m.optics.band().map(|b| b.nodes().len()),
        })
        .collect()
}

/// The scene's warnings, plus every object that covers no pixel (behind the camera, outside the
/// field of view or hidden behind other objects).
fn render_warnings(scene: &Scene, per_object: &BTreeMap<String, usize>) -> Vec<String> {
    let mut warnings = scene.warnings.clone();
    for name in &scene.object_names {
        if per_object.get(name).copied().unwrap_or(0) == 0 {
            warnings.push(format!(
                "object '{name}' covers no pixel: it is behind the camera, outside the field of \
                 view or hidden behind other objects"
            ));
        }
    }
    warnings
}

/// The Stokes component a channel is, if it is one.
fn stokes_index(channel: Channel) -> Option<usize> {
    match channel {
        Channel::S0 => Some(0),
        Channel::S1 => Some(1),
        Channel::S2 => Some(2),
        Channel::S3 => Some(3),
        _ => None,
    }
}

fn transport_summary(scene: &Scene) -> TransportSummary {
    let sun = scene.sun.map(|sun| {
        let p = sun.position();
        SunSummary {
            elevation_deg: p.elevation_deg,
            azimuth_deg: p.azimuth_deg,
            irradiance_w_m2: sun.irradiance,
        }
    });
    match scene.transport {
        Transport::OpenWorld => TransportSummary {
            open_world: true,
            bounces: None,
            samples: None,
            seed: None,
            sun: None,
        },
        Transport::Path(settings) => TransportSummary {
            open_world: false,
            bounces: Some(settings.bounces),
            samples: Some(settings.samples),
            seed: Some(settings.seed),
            sun,
        },
    }
}
