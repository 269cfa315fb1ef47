//! Render outputs (docs/design.md §4 `irpol render`): one 32-bit float single-channel TIFF per channel,
//! `stokes.exr` with every channel, PNG previews with colour bars, `composite.png` (the paper's
//! Fig. 5 layout) and `summary.json`. Every file is encoded in memory first; the set is then
//! written into a staging folder and swapped with the output folder in one step
//! ([`StagedFolder`]), so the folder holds the complete old set or the complete new one.
//!
//! This file stages the set. Each other job has its own file: the channels (`channel`), the
//! encoders (`encode`), the `summary.json` schema ([`summary`]), which entries of an earlier set
//! the new one replaces ([`earlier_outputs`]), and the previews and animated GIF ([`figure`]).

mod channel;
pub mod colormap;
pub mod earlier_outputs;
mod encode;
pub mod figure;
pub mod ground_truth;
pub mod summary;
pub mod thermal;
pub mod thermal_plot;

pub use channel::{Channel, ErrorSummary, Stats};

use crate::atomic::{StagedDir, StagedFolder};
use crate::render::film::{dolp_aop, StokesImage};
use crate::render::instrument::DofpImages;
use crate::render::{RenderError, Rendered};
use crate::scene::Scene;
use earlier_outputs::EarlierOutputs;
use encode::{encode_exr, encode_tiff};
use ground_truth::{
    camera_summary, truth_images, CameraSummary, FileMetadata, TruthData, TruthImage,
};
use rayon::prelude::*;
use std::path::Path;
use std::time::Instant;
use summary::{summarize, RenderSummary};

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

/// `[sensor.dofp]`: the raw division-of-focal-plane mosaic and the Stokes, DoLP and AoP images
/// demosaicked from it (`render::instrument`).
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
