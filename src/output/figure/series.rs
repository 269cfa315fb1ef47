//! The animated preview of a time series (`render --times`, its `preview.gif`): each frame's S0
//! and DoLP panels coloured over one range for the whole series, under a caption strip with the
//! frame's instant.

use super::canvas::draw_panel;
use super::{linear_panels, ranged_pixels, LinearPanel, Panel};
use crate::plot_style::{register_fonts, FONT};
use crate::render::film::StokesImage;
use crate::scene::config::PreviewConfig;
use crate::scene::Scene;
use image::codecs::gif::{GifEncoder, Repeat};
use image::{Delay, DynamicImage, Frame, RgbImage, RgbaImage};
use std::io;

/// The S0 and DoLP previews of a time series (`render --times`, its `preview.gif`), coloured
/// over one range for the whole series, so midnight looks colder than noon. Each frame keeps
/// only the two panels' values until [`SeriesPreview::frames`] colours them.
#[derive(Default)]
pub struct SeriesPreview {
    width: usize,
    height: usize,
    settings: PreviewConfig,
    frames: Vec<SeriesFrame>,
}

struct SeriesFrame {
    ranged: Vec<bool>,
    s0: LinearPanel,
    dolp: LinearPanel,
}

impl SeriesPreview {
    pub fn new() -> SeriesPreview {
        SeriesPreview::default()
    }

    /// Adds the next frame: `image` rendered from `scene` (one instant of the series).
    pub fn push(&mut self, scene: &Scene, image: &StokesImage) {
        let mut panels = linear_panels(scene, image).into_iter();
        let (Some(s0), Some(dolp)) = (panels.next(), panels.nth(2)) else {
            unreachable!("linear_panels gives S0, S1, S2, DoLP first")
        };
        self.settings = scene.preview.clone();
        (self.width, self.height) = (image.width, image.height);
        self.frames.push(SeriesFrame {
            ranged: ranged_pixels(image),
            s0,
            dolp,
        });
    }

    /// The S0 and DoLP ranges over every frame's ranged pixels (fixed ranges where the scene
    /// gives them).
    pub fn ranges(&self) -> [(f64, f64); 2] {
        let Some(first) = self.frames.first() else {
            return [(0.0, 1.0); 2];
        };
        let pooled = |panel: fn(&SeriesFrame) -> &LinearPanel| -> Vec<f64> {
            self.frames
                .iter()
                .flat_map(|f| panel(f).ranging_values(&f.ranged))
                .collect()
        };
        [
            first.s0.range(pooled(|f| &f.s0), &self.settings),
            first.dolp.range(pooled(|f| &f.dolp), &self.settings),
        ]
    }

    /// Each frame's S0 and DoLP panels (title, image, colour bar) over the series' [`ranges`].
    ///
    /// [`ranges`]: SeriesPreview::ranges
    pub fn frames(self) -> io::Result<Vec<[image::RgbImage; 2]>> {
        let [s0_range, dolp_range] = self.ranges();
        let (width, height) = (self.width, self.height);
        let image_of = |panel: Panel| -> io::Result<image::RgbImage> {
            let canvas = draw_panel(&panel, width, height, width, height)?;
            image::RgbImage::from_raw(canvas.width as u32, canvas.height as u32, canvas.rgb)
                .ok_or_else(|| io::Error::other("a preview panel has the wrong buffer size"))
        };
        self.frames
            .into_iter()
            .map(|f| {
                Ok([
                    image_of(f.s0.coloured(&f.ranged, s0_range))?,
                    image_of(f.dolp.coloured(&f.ranged, dolp_range))?,
                ])
            })
            .collect()
    }
}

/// Why the animated preview could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PreviewError {
    #[error("cannot draw the animated preview: {0}")]
    Caption(String),
    #[error("caption buffer has the wrong size")]
    CaptionBuffer,
    #[error(transparent)]
    Encode(#[from] image::ImageError),
}

/// The looping animated GIF of a series, one frame per instant: `labels[i]` (the instant) above
/// frame i's S0 and DoLP panels, coloured over one range for the whole series
/// ([`SeriesPreview`]), so frames compare by colour.
pub fn animated_preview(
    labels: &[String],
    previews: SeriesPreview,
) -> Result<Vec<u8>, PreviewError> {
    let panels = previews
        .frames()
        .map_err(|e| PreviewError::Caption(e.to_string()))?;
    let frames = labels
        .iter()
        .zip(panels)
        .map(|(label, [s0, dolp])| preview_frame(label, s0, dolp))
        .collect::<Result<Vec<_>, _>>()?;
    let mut bytes = Vec::new();
    {
        let mut encoder = GifEncoder::new_with_speed(&mut bytes, 10);
        encoder.set_repeat(Repeat::Infinite)?;
        encoder.encode_frames(frames)?;
    }
    Ok(bytes)
}

/// One frame of the preview, one second long: `label` above the S0 and DoLP panels.
fn preview_frame(label: &str, s0: RgbImage, dolp: RgbImage) -> Result<Frame, PreviewError> {
    let (s0, dolp) = (
        DynamicImage::ImageRgb8(s0).to_rgba8(),
        DynamicImage::ImageRgb8(dolp).to_rgba8(),
    );
    let width = s0.width() + dolp.width();
    let header = caption_strip(label, width)?;
    let top = i64::from(header.height());
    let mut frame = RgbaImage::from_pixel(
        width,
        header.height() + s0.height().max(dolp.height()),
        image::Rgba([255, 255, 255, 255]),
    );
    image::imageops::overlay(&mut frame, &header, 0, 0);
    image::imageops::overlay(&mut frame, &s0, 0, top);
    image::imageops::overlay(&mut frame, &dolp, i64::from(s0.width()), top);
    Ok(Frame::from_parts(
        frame,
        0,
        0,
        Delay::from_numer_denom_ms(1000, 1),
    ))
}

/// A white strip `width` pixels wide with `text` on it.
fn caption_strip(text: &str, width: u32) -> Result<RgbaImage, PreviewError> {
    use plotters::prelude::*;
    const HEIGHT: u32 = 26;
    register_fonts();
    let mut rgb = vec![255u8; (width * HEIGHT * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, HEIGHT)).into_drawing_area();
        let style = (FONT, 17).into_font().color(&BLACK);
        root.draw(&Text::new(text.to_owned(), (8, 4), style))
            .map_err(|e| PreviewError::Caption(e.to_string()))?;
        root.present()
            .map_err(|e| PreviewError::Caption(e.to_string()))?;
    }
    let strip = RgbImage::from_raw(width, HEIGHT, rgb).ok_or(PreviewError::CaptionBuffer)?;
    Ok(DynamicImage::ImageRgb8(strip).to_rgba8())
}

#[cfg(test)]
mod tests {
    use super::super::canvas::PanelLayout;
    use super::super::{Bar, Clipped, LinearPanel};
    use super::*;
    use crate::output::colormap::{Lut, THERMAL};

    fn series_frame(values: Vec<f64>) -> SeriesFrame {
        let panel = |values: Vec<f64>, fixed| LinearPanel {
            file: "S0.png",
            title: "S0".into(),
            values,
            fixed,
            symmetric: false,
            map: &THERMAL,
        };
        let dolp: Vec<f64> = values.iter().map(|t| (t - 280.0) / 10.0).collect();
        SeriesFrame {
            ranged: vec![true; values.len()],
            s0: panel(values, None),
            dolp: panel(dolp, Some([0.0, f64::NAN])),
        }
    }

    #[test]
    fn a_time_series_is_coloured_over_one_range() {
        // Midnight at 284…290 K, noon at 295…325 K (16 × 16 pixels each).
        let ramp = |lo: f64, hi: f64| -> Vec<f64> {
            (0..256)
                .map(|i| lo + (hi - lo) * f64::from(i) / 255.0)
                .collect()
        };
        let series = SeriesPreview {
            width: 16,
            height: 16,
            settings: PreviewConfig::default(),
            frames: vec![
                series_frame(ramp(284.0, 290.0)),
                series_frame(ramp(295.0, 325.0)),
            ],
        };
        let [s0, dolp] = series.ranges();
        assert_eq!(s0, (284.0, 325.0));
        assert_eq!(dolp, (0.0, 4.5));
        // Each frame alone would span its own range; together the midnight frame is the cold end.
        let frames = series.frames().unwrap();
        let layout = PanelLayout::new(
            &Bar::Linear {
                map: &THERMAL,
                lo: 0.0,
                hi: 1.0,
                signed: false,
                clipped: Clipped::default(),
            },
            16,
            16,
        );
        let pixel = |image: &image::RgbImage, i: u32| {
            image
                .get_pixel(
                    layout.margin as u32 + i % 16,
                    layout.title_h as u32 + i / 16,
                )
                .0
        };
        assert_eq!(pixel(&frames[0][0], 0), THERMAL.at(0.0));
        assert_eq!(pixel(&frames[1][0], 255), THERMAL.at(1.0));
        let midnight_top = pixel(&frames[0][0], 255);
        assert_eq!(midnight_top, Lut::new(&THERMAL).at(6.0 / 41.0));
        assert_eq!(frames[0][0].dimensions(), frames[1][0].dimensions());
    }
}
