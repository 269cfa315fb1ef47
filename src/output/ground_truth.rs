//! Ground truth for users who train or validate algorithms: per pixel the
//! object and part seen, the depth, the world normal, the surface temperature and the apparent
//! (brightness) temperature, plus the camera, band and units as metadata (in `summary.json` and
//! in every TIFF's ImageDescription tag and the EXR header).

use crate::optics::TemperatureLookup;
use crate::render::film::{StokesImage, BACKGROUND};
use crate::scene::Scene;
use serde::Serialize;
use std::collections::BTreeMap;

/// The pinhole camera as a computer-vision user needs it: intrinsics in pixels (continuous pixel
/// coordinates, x right and y down from the top-left corner of the image, pixel (i, j) centred at
/// (i + ½, j + ½)) and the pose (world frame, z up).
#[derive(Clone, Debug, Serialize)]
pub struct CameraSummary {
    pub width: u32,
    pub height: u32,
    pub fov_y_deg: f64,
    pub fov_x_deg: f64,
    /// Focal lengths (px): f = (size/2) / tan(fov/2).
    pub fx_px: f64,
    pub fy_px: f64,
    /// Principal point (px): the image centre.
    pub cx_px: f64,
    pub cy_px: f64,
    /// Camera position (m).
    pub position: [f64; 3],
    /// Unit vectors of the camera frame in world coordinates: image right, image up and the
    /// viewing direction (right × up = −forward: a right-handed frame looking along −z is
    /// OpenGL's; along forward it is this).
    pub right: [f64; 3],
    pub up: [f64; 3],
    pub forward: [f64; 3],
}

/// What each ID in `object_id.tif` and `part_id.tif` means (0 is the background).
#[derive(Clone, Debug, Serialize)]
pub struct IdMaps {
    pub objects: BTreeMap<u32, String>,
    /// `object/part` names.
    pub parts: BTreeMap<u32, String>,
}

pub fn camera_summary(scene: &Scene) -> CameraSummary {
    let c = &scene.camera;
    let v = |x: &nalgebra::Vector3<f64>| [x.x, x.y, x.z];
    CameraSummary {
        width: c.width,
        height: c.height,
        fov_y_deg: 2.0 * c.tan_half_fov_y.atan().to_degrees(),
        fov_x_deg: 2.0 * c.tan_half_fov_x.atan().to_degrees(),
        fx_px: 0.5 * c.width as f64 / c.tan_half_fov_x,
        fy_px: 0.5 * c.height as f64 / c.tan_half_fov_y,
        cx_px: 0.5 * c.width as f64,
        cy_px: 0.5 * c.height as f64,
        position: v(&c.position),
        right: v(&c.right),
        up: v(&c.up),
        forward: v(&c.forward),
    }
}

pub fn id_maps(scene: &Scene) -> IdMaps {
    IdMaps {
        objects: (0..scene.object_names.len())
            .map(|i| (i as u32 + 1, scene.object_names[i].clone()))
            .collect(),
        parts: scene
            .surfaces
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let name = format!("{}/{}", scene.object_names[s.object], s.part);
                (i as u32 + 1, name)
            })
            .collect(),
    }
}

/// A ground-truth image: its samples (one or three per pixel) and unit.
pub enum TruthData {
    Float(Vec<f32>),
    /// Three floats per pixel (x, y, z).
    Vector(Vec<f32>),
    Id(Vec<u32>),
}

pub struct TruthImage {
    pub file: &'static str,
    pub unit: &'static str,
    pub data: TruthData,
}

/// Nodes of the apparent-temperature table: over a scene's radiance range linear interpolation
/// between 4097 exact inversions is within 1e-4 K of the exact brightness temperature (tested).
const APPARENT_TEMPERATURE_NODES: usize = 4097;

/// Every ground-truth image of a render.
pub fn truth_images(scene: &Scene, image: &StokesImage) -> Vec<TruthImage> {
    let t = &image.truth;
    let surface_id = |s: u32| if s == BACKGROUND { 0 } else { s + 1 };
    let object_id = |s: u32| {
        if s == BACKGROUND {
            0
        } else {
            scene.surfaces[s as usize].object as u32 + 1
        }
    };
    let (lo, hi) = image
        .stokes
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), s| {
            (lo.min(s[0]), hi.max(s[0]))
        });
    let lookup = TemperatureLookup::with_nodes(
        &scene.sensor.band,
        lo.max(0.0),
        hi.max(0.0),
        APPARENT_TEMPERATURE_NODES,
    );
    vec![
        TruthImage {
            file: "object_id.tif",
            unit: "id (0 = background; summary.json ids.objects)",
            data: TruthData::Id(image.surface.iter().map(|&s| object_id(s)).collect()),
        },
        TruthImage {
            file: "part_id.tif",
            unit: "id (0 = background; summary.json ids.parts)",
            data: TruthData::Id(image.surface.iter().map(|&s| surface_id(s)).collect()),
        },
        TruthImage {
            file: "depth.tif",
            unit: "m along the optical axis (0 = background)",
            data: TruthData::Float(t.iter().map(|p| p.depth_m).collect()),
        },
        TruthImage {
            file: "normal.tif",
            unit: "unit world normal x, y, z of the seen side (0 = background)",
            data: TruthData::Vector(t.iter().flat_map(|p| p.normal).collect()),
        },
        TruthImage {
            file: "surface_temperature.tif",
            unit: "K (0 = background)",
            data: TruthData::Float(t.iter().map(|p| p.temperature_k).collect()),
        },
        TruthImage {
            file: "apparent_temperature.tif",
            unit: "K, brightness temperature of S0 in the band (background included)",
            data: TruthData::Float(
                image
                    .stokes
                    .iter()
                    .map(|s| lookup.at(s[0]) as f32)
                    .collect(),
            ),
        },
    ]
}

/// What every image file of a render carries in its header (TIFF ImageDescription, EXR
/// attribute `irpol`): the file's quantity and unit, the band and the camera.
#[derive(Serialize)]
pub struct FileMetadata<'a> {
    pub software: &'static str,
    pub scene: String,
    pub file: &'a str,
    pub unit: &'a str,
    pub band_um: [f64; 2],
    /// Pixel frame of every image: x image right, y image up, row 0 the top.
    pub frame: &'static str,
    pub camera: &'a CameraSummary,
}

impl<'a> FileMetadata<'a> {
    pub fn new(scene: &Scene, camera: &'a CameraSummary, file: &'a str, unit: &'a str) -> Self {
        let (lo, hi) = scene.sensor.band.limits_um();
        FileMetadata {
            software: concat!("irpol ", env!("CARGO_PKG_VERSION")),
            scene: scene.path.display().to_string(),
            file,
            unit,
            band_um: [lo, hi],
            frame: "Stokes in the pixel frame: x image right, y image up (AoP counter-clockwise \
                    from image right); row 0 is the top of the image",
            camera,
        }
    }

    pub fn json(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }
}
