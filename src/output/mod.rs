//! Render outputs (docs/design.md §4 `irpol render`): one 32-bit float single-channel TIFF per channel,
//! `stokes.exr` with every channel, PNG previews with colour bars, `composite.png` (the paper's
//! Fig. 5 layout) and `summary.json`. Every file is encoded in memory first; the set is then
//! written into a staging folder and swapped with the output folder in one step
//! ([`StagedFolder`]), so the folder holds the complete old set or the complete new one.

pub mod colormap;
pub mod figure;
pub mod ground_truth;
pub mod thermal;
pub mod thermal_plot;

use crate::atomic::{StagedDir, StagedFolder};
use crate::optics::TemperatureLookup;
use crate::render::camera::{metrics::CameraMetrics, DofpImages};
use crate::render::film::{dolp_aop, polarizer, StokesImage, BACKGROUND};
use crate::render::TableResolution;
use crate::render::{RenderError, Rendered, Timings};
use crate::scene::config::Shading;
use crate::scene::{Scene, Transport};
use ground_truth::{
    camera_summary, id_maps, truth_images, CameraSummary, FileMetadata, IdMaps, TruthData,
    TruthImage,
};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::io::Cursor;
use std::path::Path;
use std::time::Instant;

/// The image channels written (docs/design.md §1.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Channel {
    S0,
    S1,
    S2,
    S3,
    Dolp,
    Aop,
    I0,
    I45,
    I90,
    I135,
}

impl Channel {
    pub const ALL: [Channel; 10] = [
        Channel::S0,
        Channel::S1,
        Channel::S2,
        Channel::S3,
        Channel::Dolp,
        Channel::Aop,
        Channel::I0,
        Channel::I45,
        Channel::I90,
        Channel::I135,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Channel::S0 => "S0",
            Channel::S1 => "S1",
            Channel::S2 => "S2",
            Channel::S3 => "S3",
            Channel::Dolp => "DoLP",
            Channel::Aop => "AoP",
            Channel::I0 => "I0",
            Channel::I45 => "I45",
            Channel::I90 => "I90",
            Channel::I135 => "I135",
        }
    }

    pub fn unit(self) -> &'static str {
        match self {
            Channel::Dolp => "1",
            Channel::Aop => "rad",
            _ => "W m-2 sr-1",
        }
    }

    /// Which of I0, I45, I90, I135 the channel is, if a polarizer image.
    pub fn polarizer_index(self) -> Option<usize> {
        match self {
            Channel::I0 => Some(0),
            Channel::I45 => Some(1),
            Channel::I90 => Some(2),
            Channel::I135 => Some(3),
            _ => None,
        }
    }

    /// The channel's value for a pixel-frame Stokes vector.
    #[inline]
    pub fn value(self, s: [f64; 4]) -> f64 {
        use std::f64::consts::{FRAC_PI_2, FRAC_PI_4};
        match self {
            Channel::S0 => s[0],
            Channel::S1 => s[1],
            Channel::S2 => s[2],
            Channel::S3 => s[3],
            Channel::Dolp => dolp_aop(s).0,
            Channel::Aop => dolp_aop(s).1,
            Channel::I0 => polarizer(s, 0.0),
            Channel::I45 => polarizer(s, FRAC_PI_4),
            Channel::I90 => polarizer(s, FRAC_PI_2),
            Channel::I135 => polarizer(s, 3.0 * FRAC_PI_4),
        }
    }
}

impl StokesImage {
    /// One channel as 32-bit floats, row-major from the top. The polarizer images are the
    /// recorded (noisy) ones when the sensor has noise, not re-derived from the Stokes estimate.
    pub fn channel(&self, channel: Channel) -> Vec<f32> {
        if let (Some(k), false) = (
            channel.polarizer_index(),
            self.recorded_polarizers.is_empty(),
        ) {
            return self.recorded_polarizers.iter().map(|i| i[k]).collect();
        }
        self.stokes
            .iter()
            .map(|&s| channel.value(s) as f32)
            .collect()
    }

    /// Minimum, maximum and mean of a channel over the object pixels (None without any).
    pub fn object_stats(&self, values: &[f32]) -> Option<Stats> {
        let mut stats = Stats {
            min: f64::INFINITY,
            max: f64::NEG_INFINITY,
            mean: 0.0,
        };
        let mut count = 0usize;
        for (&v, &o) in values.iter().zip(&self.surface) {
            if o != BACKGROUND {
                let v = v as f64;
                stats.min = stats.min.min(v);
                stats.max = stats.max.max(v);
                stats.mean += v;
                count += 1;
            }
        }
        (count > 0).then(|| Stats {
            mean: stats.mean / count as f64,
            ..stats
        })
    }
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct Stats {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
}

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

#[derive(Clone, Copy, Debug, Serialize)]
pub struct ErrorSummary {
    pub mean: f64,
    pub median: f64,
    pub p99: f64,
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

/// Writes every output of `rendered` into `out_dir` and returns the summary.
pub fn write_outputs(
    scene: &Scene,
    rendered: &Rendered,
    out_dir: &Path,
    started: Instant,
) -> Result<RenderSummary, RenderError> {
    let write_error = |source| RenderError::Write {
        path: out_dir.to_owned(),
        source,
    };
    let staged = StagedFolder::begin(out_dir).map_err(write_error)?;
    let summary = stage_outputs(scene, rendered, &staged.root(), out_dir, started)?;
    let earlier = EarlierOutputs::single(out_dir);
    staged
        .commit(&|name| earlier.contains(name))
        .map_err(write_error)?;
    Ok(summary)
}

/// Writes every output of `rendered` into `staged`, a folder of an output set that becomes
/// `out_dir` when the set is committed, and returns the summary.
pub fn stage_outputs(
    scene: &Scene,
    rendered: &Rendered,
    staged: &StagedDir,
    out_dir: &Path,
    started: Instant,
) -> Result<RenderSummary, RenderError> {
    let write_start = Instant::now();
    let image = &rendered.image;
    let channels: Vec<(Channel, Vec<f32>)> = Channel::ALL
        .par_iter()
        .map(|&c| (c, image.channel(c)))
        .collect();
    let camera = camera_summary(scene);
    // Each file goes into the staging folder as soon as it is encoded (the folder is swapped in
    // as a whole at the end), so no more than a file per thread is held in memory.
    let images = ImageFiles::new(scene, rendered, &channels, &camera);
    let mut files = images.stage(staged, out_dir)?;
    files.push("summary.json".into());
    let mut timings = rendered.timings;
    let mut summary = summarize(scene, rendered, out_dir, &channels, camera, files);
    timings.write = write_start.elapsed().as_secs_f64();
    timings.total = started.elapsed().as_secs_f64();
    summary.timings_s = timings;
    let json = serde_json::to_vec_pretty(&summary).map_err(|e| RenderError::Write {
        path: out_dir.join("summary.json"),
        source: std::io::Error::other(e),
    })?;
    staged
        .write("summary.json", &json)
        .map_err(|source| RenderError::Write {
            path: out_dir.join("summary.json"),
            source,
        })?;
    Ok(summary)
}

/// One image file of a render's outputs.
enum ImageJob {
    Tiff(usize),
    StandardError,
    Truth(usize),
    Exr,
    Panel(usize),
    Composite,
    DofpError,
}

/// The image files of a render: channel and ground-truth TIFFs, `stokes.exr`, the PNG previews
/// and the composite, each with its JSON metadata.
struct ImageFiles<'a> {
    scene: &'a Scene,
    image: &'a StokesImage,
    dofp: Option<&'a DofpImages>,
    channels: &'a [(Channel, Vec<f32>)],
    camera: &'a CameraSummary,
    truth: Vec<TruthImage>,
    previews: figure::Previews,
}

impl<'a> ImageFiles<'a> {
    fn new(
        scene: &'a Scene,
        rendered: &'a Rendered,
        channels: &'a [(Channel, Vec<f32>)],
        camera: &'a CameraSummary,
    ) -> ImageFiles<'a> {
        let image = &rendered.image;
        let previews = figure::Previews::new(scene, image);
        let mut truth = truth_images(scene, image);
        if let Some(dofp) = &rendered.dofp {
            truth.extend(dofp_images(dofp));
        }
        ImageFiles {
            scene,
            image,
            dofp: rendered.dofp.as_ref(),
            channels,
            camera,
            truth,
            previews,
        }
    }

    fn jobs(&self) -> Vec<ImageJob> {
        let mut jobs: Vec<ImageJob> = (0..self.channels.len()).map(ImageJob::Tiff).collect();
        jobs.push(ImageJob::StandardError);
        jobs.extend((0..self.truth.len()).map(ImageJob::Truth));
        jobs.push(ImageJob::Exr);
        jobs.extend((0..self.previews.len()).map(ImageJob::Panel));
        jobs.push(ImageJob::Composite);
        if self.dofp.is_some() {
            jobs.push(ImageJob::DofpError);
        }
        jobs
    }

    /// Encodes every file in memory, in parallel, each written into `staged` as soon as it is
    /// encoded; the names written, in job order.
    fn stage(&self, staged: &StagedDir, out_dir: &Path) -> Result<Vec<String>, RenderError> {
        self.jobs()
            .par_iter()
            .map(|job| {
                let (name, bytes) = self.encode(job);
                bytes
                    .and_then(|b| staged.write(&name, &b))
                    .map(|()| name.clone())
                    .map_err(|source| RenderError::Write {
                        path: out_dir.join(&name),
                        source,
                    })
            })
            .collect()
    }

    fn metadata(&self, file: &str, unit: &str) -> String {
        FileMetadata::new(self.scene, self.camera, file, unit).json()
    }

    /// A file's name and bytes.
    fn encode(&self, job: &ImageJob) -> (String, std::io::Result<Vec<u8>>) {
        let (w, h) = (self.image.width, self.image.height);
        match job {
            ImageJob::Tiff(i) => {
                let (channel, data) = &self.channels[*i];
                let name = format!("{}.tif", channel.name());
                let description = self.metadata(&name, channel.unit());
                let bytes = encode_tiff(w, h, &TruthData::Float(data.clone()), &description);
                (name, bytes)
            }
            ImageJob::StandardError => {
                let data: Vec<f32> = self
                    .image
                    .standard_error
                    .iter()
                    .map(|e| e[0] as f32)
                    .collect();
                let description = self.metadata("stderr_S0.tif", Channel::S0.unit());
                let bytes = encode_tiff(w, h, &TruthData::Float(data), &description);
                ("stderr_S0.tif".to_owned(), bytes)
            }
            ImageJob::Truth(i) => {
                let t = &self.truth[*i];
                let bytes = encode_tiff(w, h, &t.data, &self.metadata(t.file, t.unit));
                (t.file.to_owned(), bytes)
            }
            ImageJob::Exr => {
                let description = self.metadata("stokes.exr", "per channel as in the TIFFs");
                let bytes = encode_exr(w, h, self.channels, &description);
                ("stokes.exr".to_owned(), bytes)
            }
            ImageJob::Panel(i) => (
                self.previews.file_name(*i).to_owned(),
                self.previews.panel_png(*i),
            ),
            ImageJob::Composite => ("composite.png".to_owned(), self.previews.composite_png()),
            ImageJob::DofpError => {
                let dofp = self.dofp.expect("a DoFP job has DoFP images");
                let bytes = figure::dofp_error_png(self.scene, self.image, dofp);
                ("dofp_error.png".to_owned(), bytes)
            }
        }
    }
}

/// `summary.json` of a render whose files are `files` (timings as the render measured them).
fn summarize(
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

/// The manifest of a render series (`render --times`): its frames and every entry it wrote.
pub const SERIES_MANIFEST: &str = "series.json";

/// The entries of an output folder that an earlier output set of the same kind wrote: a single
/// render's (listed in its `summary.json`) or a series' (listed in [`SERIES_MANIFEST`], and
/// frame folders `NNN_<t>s/` with a `summary.json`). They are replaced as a set; the other
/// kind's set (a single instant rendered beside a series) and anything else in the folder, the
/// user's, are kept.
pub struct EarlierOutputs {
    dir: std::path::PathBuf,
    listed: Vec<String>,
    frames: bool,
}

impl EarlierOutputs {
    /// What an earlier single render into `out_dir` wrote.
    pub fn single(out_dir: &Path) -> EarlierOutputs {
        EarlierOutputs {
            dir: out_dir.to_owned(),
            listed: listed_files(&out_dir.join("summary.json")),
            frames: false,
        }
    }

    /// What an earlier series into `out_dir` wrote.
    pub fn series(out_dir: &Path) -> EarlierOutputs {
        EarlierOutputs {
            dir: out_dir.to_owned(),
            listed: listed_files(&out_dir.join(SERIES_MANIFEST)),
            frames: true,
        }
    }

    pub fn contains(&self, name: &str) -> bool {
        self.listed.iter().any(|f| f == name)
            || (self.frames
                && is_frame_folder_name(name)
                && self.dir.join(name).join("summary.json").is_file())
    }
}

/// Whether `name` is how a series names a frame's folder, `NNN_<t>s` (a series written before
/// series had a manifest is still recognised).
fn is_frame_folder_name(name: &str) -> bool {
    let Some((index, time)) = name.split_once('_') else {
        return false;
    };
    let digits = |t: &str| !t.is_empty() && t.bytes().all(|b| b.is_ascii_digit());
    let time = time.strip_suffix('s').unwrap_or("");
    index.len() >= 3 && digits(index) && digits(time.strip_prefix('-').unwrap_or(time))
}

/// The `files` a summary or manifest at `path` lists (none if it is missing or unreadable).
fn listed_files(path: &Path) -> Vec<String> {
    let Ok(text) = std::fs::read(path) else {
        return Vec::new();
    };
    let summary: serde_json::Value = serde_json::from_slice(&text).unwrap_or_default();
    summary["files"]
        .as_array()
        .map(|files| {
            files
                .iter()
                .filter_map(|f| f.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}

/// `[sensor.dofp]`: the raw division-of-focal-plane mosaic and the Stokes, DoLP and AoP images
/// demosaicked from it (`render::camera`).
fn dofp_images(dofp: &DofpImages) -> Vec<TruthImage> {
    // The images are single precision; the camera works in double.
    let raw = dofp.mosaic.iter().map(|&v| v as f32).collect();
    let stokes: Vec<[f32; 3]> = dofp.stokes.iter().map(|s| s.map(|v| v as f32)).collect();
    let derived = |f: fn([f64; 4]) -> f64| {
        stokes
            .iter()
            .map(|s| f([s[0] as f64, s[1] as f64, s[2] as f64, 0.0]) as f32)
            .collect()
    };
    let radiance = "W m-2 sr-1";
    let image_of = |file, unit, data| TruthImage {
        file,
        unit,
        data: TruthData::Float(data),
    };
    vec![
        image_of("dofp_mosaic.tif", radiance, raw),
        image_of(
            "dofp_S0.tif",
            radiance,
            stokes.iter().map(|s| s[0]).collect(),
        ),
        image_of(
            "dofp_S1.tif",
            radiance,
            stokes.iter().map(|s| s[1]).collect(),
        ),
        image_of(
            "dofp_S2.tif",
            radiance,
            stokes.iter().map(|s| s[2]).collect(),
        ),
        image_of("dofp_DoLP.tif", "1", derived(|s| dolp_aop(s).0)),
        image_of("dofp_AoP.tif", "rad", derived(|s| dolp_aop(s).1)),
    ]
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

impl StokesImage {
    /// Mean, median and 99th percentile of the standard error of Stokes component `j` relative to S0,
    /// over object pixels with S0 > 0.
    pub fn relative_error(&self, j: usize) -> Option<ErrorSummary> {
        let mut values: Vec<f64> = self
            .stokes
            .iter()
            .zip(&self.standard_error)
            .zip(&self.surface)
            .filter(|((s, _), &o)| o != BACKGROUND && s[0] > 0.0)
            .map(|((s, e), _)| e[j] / s[0])
            .filter(|v| v.is_finite())
            .collect();
        if values.is_empty() {
            return None;
        }
        values.sort_by(f64::total_cmp);
        let mean = values.iter().sum::<f64>() / values.len() as f64;
        let quantile = |p: f64| values[((values.len() - 1) as f64 * p).round() as usize];
        Some(ErrorSummary {
            mean,
            median: quantile(0.5),
            p99: quantile(0.99),
        })
    }
}

/// Single-channel 32-bit IEEE float TIFF (SampleFormat = 3), uncompressed.
/// An uncompressed TIFF of `data` (32-bit float gray, float RGB for vectors, 32-bit unsigned for
/// IDs) with `description` (JSON metadata) in its ImageDescription tag.
fn encode_tiff(
    width: usize,
    height: usize,
    data: &TruthData,
    description: &str,
) -> std::io::Result<Vec<u8>> {
    use tiff::encoder::colortype::{ColorType, Gray32, Gray32Float, RGB32Float};
    use tiff::encoder::{TiffEncoder, TiffValue};
    use tiff::tags::Tag;
    fn write<C: ColorType>(
        encoder: &mut TiffEncoder<&mut Cursor<Vec<u8>>>,
        (width, height): (u32, u32),
        data: &[C::Inner],
        description: &str,
    ) -> tiff::TiffResult<()>
    where
        [C::Inner]: TiffValue,
    {
        let mut image = encoder.new_image::<C>(width, height)?;
        image
            .encoder()
            .write_tag(Tag::ImageDescription, description)?;
        image.write_data(data)
    }
    let mut bytes = Cursor::new(Vec::new());
    let mut encoder = TiffEncoder::new(&mut bytes).map_err(std::io::Error::other)?;
    let size = (width as u32, height as u32);
    match data {
        TruthData::Float(v) => write::<Gray32Float>(&mut encoder, size, v, description),
        TruthData::Vector(v) => write::<RGB32Float>(&mut encoder, size, v, description),
        TruthData::Id(v) => write::<Gray32>(&mut encoder, size, v, description),
    }
    .map_err(std::io::Error::other)?;
    Ok(bytes.into_inner())
}

/// One OpenEXR layer "stokes" with a 32-bit float channel per [`Channel`], uncompressed.
fn encode_exr(
    width: usize,
    height: usize,
    channels: &[(Channel, Vec<f32>)],
    description: &str,
) -> std::io::Result<Vec<u8>> {
    use exr::prelude::*;
    let list: SmallVec<[AnyChannel<FlatSamples>; 4]> = channels
        .iter()
        .map(|(c, data)| AnyChannel::new(c.name(), FlatSamples::F32(data.clone())))
        .collect();
    let layer = Layer::new(
        (width, height),
        LayerAttributes::named("stokes"),
        // Noisy float data does not compress; uncompressed is as small and fastest.
        Encoding::UNCOMPRESSED,
        AnyChannels::sort(list),
    );
    let mut bytes = Cursor::new(Vec::new());
    let mut image = Image::from_layer(layer);
    image.attributes.other.insert(
        Text::from("irpol"),
        AttributeValue::Text(Text::from(description)),
    );
    image
        .write()
        .to_buffered(&mut bytes)
        .map_err(std::io::Error::other)?;
    Ok(bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiff_and_exr_round_trip() {
        let (w, h) = (5, 3);
        let data: Vec<f32> = (0..15).map(|i| i as f32 * 0.25 - 1.0).collect();
        let tiff = encode_tiff(w, h, &TruthData::Float(data.clone()), "{\"a\": 1}").unwrap();
        let mut decoder = tiff::decoder::Decoder::new(Cursor::new(tiff)).unwrap();
        assert_eq!(decoder.dimensions().unwrap(), (5, 3));
        let description = decoder
            .get_tag_ascii_string(tiff::tags::Tag::ImageDescription)
            .unwrap();
        assert_eq!(description, "{\"a\": 1}");
        match decoder.read_image().unwrap() {
            tiff::decoder::DecodingResult::F32(back) => assert_eq!(back, data),
            _ => panic!("not a float TIFF"),
        }
        let ids = TruthData::Id((0..15).collect());
        let mut decoder =
            tiff::decoder::Decoder::new(Cursor::new(encode_tiff(w, h, &ids, "").unwrap())).unwrap();
        match decoder.read_image().unwrap() {
            tiff::decoder::DecodingResult::U32(back) => {
                assert_eq!(back, (0..15).collect::<Vec<_>>())
            }
            _ => panic!("not a 32-bit unsigned TIFF"),
        }
        let channels = vec![(Channel::S0, data.clone()), (Channel::Dolp, vec![0.5; 15])];
        let exr_bytes = encode_exr(w, h, &channels, "{}").unwrap();
        use exr::prelude::{ReadChannels, ReadLayers};
        let image = exr::prelude::read()
            .no_deep_data()
            .largest_resolution_level()
            .all_channels()
            .first_valid_layer()
            .all_attributes()
            .from_buffered(Cursor::new(exr_bytes))
            .unwrap();
        let layer = &image.layer_data;
        assert_eq!(layer.size, exr::math::Vec2(5, 3));
        let names: Vec<String> = layer
            .channel_data
            .list
            .iter()
            .map(|c| c.name.to_string())
            .collect();
        assert_eq!(names, vec!["DoLP", "S0"]);
        let key = exr::prelude::Text::from("irpol");
        let irpol = image
            .attributes
            .other
            .get(&key)
            .or(layer.attributes.other.get(&key));
        assert!(
            matches!(irpol, Some(exr::meta::attribute::AttributeValue::Text(t)) if t.as_slice() == b"{}"),
            "{irpol:?}"
        );
        let s0: Vec<f32> = layer.channel_data.list[1]
            .sample_data
            .values_as_f32()
            .collect();
        assert_eq!(s0, data);
    }
}
