//! PNG previews with colour bars (S0 as apparent temperature, S1/S2 diverging about zero, DoLP
//! sequential, AoP cyclic and masked where DoLP is below the scene's threshold) and a composite
//! figure in the layout of the paper's Fig. 5. Colour ranges follow `[render.preview]`: by default
//! the 0.1th–99.9th percentiles over the object pixels (symmetric for S1/S2/S3), reaching past them
//! to take in values just beyond (noise), so a few glints do not wash out the image and noise does
//! not speckle it; object pixels outside are drawn in the map's under/over colours, capped on the
//! colour bar and counted in the title, never silently clipped. Sky and environment ground take
//! the map's end colours. A time series is coloured over one range ([`SeriesPreview`]).
//! Text is drawn with plotters using the embedded DejaVu Sans font.

mod canvas;
mod colouring;
mod dofp_error;
mod series;

pub use dofp_error::dofp_error_png;
pub use series::{animated_preview, PreviewError, SeriesPreview};

use super::colormap::{cyclic, ColorMap, DIVERGING, GRAY, MASKED, SEQUENTIAL, THERMAL};
use crate::optics::TemperatureLookup;
use crate::plot_style::{register_fonts, FONT};
use crate::render::film::{dolp_aop, StokesImage, BACKGROUND};
use crate::scene::config::S0Colormap;
use crate::scene::{Scene, Transport};
use canvas::{draw_error, draw_panel, Canvas};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use rayon::prelude::*;
use std::io;

/// How a panel's colour bar is drawn: its colours bottom to top and labelled ticks.
enum Bar {
    Linear {
        map: &'static ColorMap,
        lo: f64,
        hi: f64,
        /// Tick labels carry their sign (S1, S2, S3, errors).
        signed: bool,
        clipped: Clipped,
    },
    Cyclic,
}

/// Fractions of the panel's pixels below and above its colour range, drawn in the map's
/// under/over colours (a clip is shown, never silent).
#[derive(Clone, Copy, Default)]
struct Clipped {
    below: f64,
    above: f64,
}

struct Panel {
    file: &'static str,
    title: String,
    colors: Vec<[u8; 3]>,
    bar: Bar,
}

/// The five preview panels of a render, coloured once at full resolution.
pub struct Previews {
    width: usize,
    height: usize,
    panels: Vec<Panel>,
    caption: String,
    /// "LWIR", "MWIR", "SWIR" or the band in µm: the composite's title follows the sensor.
    band_name: String,
}

/// How a linear panel is coloured: the value of each pixel, how its range is chosen, the map.
struct LinearPanel {
    file: &'static str,
    title: String,
    /// Each pixel's value (NaN for none).
    values: Vec<f64>,
    fixed: Option<[f64; 2]>,
    /// Symmetric about zero (S1, S2, S3).
    symmetric: bool,
    map: &'static ColorMap,
}

impl Previews {
    pub fn new(scene: &Scene, image: &StokesImage) -> Previews {
        let ranged = ranged_pixels(image);
        let mut panels: Vec<Panel> = linear_panels(scene, image)
            .into_iter()
            .map(|spec| spec.panel(&ranged, &scene.preview))
            .collect();
        // The composite shows the first five: S0, S1, S2, DoLP, AoP (the paper's Fig. 5).
        panels.insert(4, aop_panel(image, scene.aop_mask_dolp));
        Previews {
            width: image.width,
            height: image.height,
            panels,
            caption: caption(scene, image),
            band_name: band_name(scene.sensor.band.limits_um()),
        }
    }

    /// Number of preview panels.
    pub fn len(&self) -> usize {
        self.panels.len()
    }

    pub fn is_empty(&self) -> bool {
        self.panels.is_empty()
    }

    /// File name of panel `i` ("S0.png", …).
    pub fn file_name(&self, i: usize) -> &'static str {
        self.panels[i].file
    }

    /// Panel `i` at full resolution, PNG encoded.
    pub fn panel_png(&self, i: usize) -> io::Result<Vec<u8>> {
        draw_panel(
            &self.panels[i],
            self.width,
            self.height,
            self.width,
            self.height,
        )?
        .png()
    }

    /// The five panels in a 3 × 2 grid (the sixth cell holds the caption), each image at most
    /// 480 pixels wide and tall.
    pub fn composite_png(&self) -> io::Result<Vec<u8>> {
        register_fonts();
        let (img_w, img_h) = cell_size(self.width, self.height);
        // S0, S1, S2, DoLP, AoP (the paper's Fig. 5); S3 has its own preview only.
        let cells: Vec<Canvas> = self
            .panels
            .iter()
            .take(5)
            .map(|p| draw_panel(p, self.width, self.height, img_w, img_h))
            .collect::<io::Result<_>>()?;
        let (cell_w, cell_h) = (cells[0].width, cells[0].height);
        let header = 36;
        let mut sheet = Canvas::white(3 * cell_w, 2 * cell_h + header);
        for (i, cell) in cells.iter().enumerate() {
            sheet.blit(cell, (i % 3) * cell_w, header + (i / 3) * cell_h);
        }
        let (w, h) = (sheet.width as u32, sheet.height as u32);
        {
            let root = BitMapBackend::with_buffer(&mut sheet.rgb, (w, h)).into_drawing_area();
            let title = (FONT, 22.0)
                .into_font()
                .style(FontStyle::Bold)
                .color(&BLACK);
            root.draw_text(
                &format!("{} polarimetric simulation (Stokes images)", self.band_name),
                &title.pos(Pos::new(HPos::Center, VPos::Top)),
                (w as i32 / 2, 6),
            )
            .map_err(draw_error)?;
            let text = (FONT, 15.0).into_font().color(&BLACK);
            let (x0, y0) = (2 * cell_w as i32 + 20, header as i32 + cell_h as i32 + 30);
            for (k, line) in self.caption.split(", ").enumerate() {
                root.draw_text(line, &text, (x0, y0 + 22 * k as i32))
                    .map_err(draw_error)?;
            }
            root.present().map_err(draw_error)?;
        }
        sheet.png()
    }
}

/// A sheet cell's image size: at most 480 pixels wide and tall, so an extreme aspect ratio
/// (20 × 200000) does not make a sheet of hundreds of megabytes.
fn cell_size(width: usize, height: usize) -> (usize, usize) {
    let scale = (480.0 / width as f64).min(480.0 / height as f64).min(1.0);
    (
        ((width as f64 * scale).round() as usize).max(1),
        ((height as f64 * scale).round() as usize).max(1),
    )
}

/// S0 (as apparent temperature), S1, S2, DoLP and, with transport between surfaces, S3.
fn linear_panels(scene: &Scene, image: &StokesImage) -> Vec<LinearPanel> {
    let settings = &scene.preview;
    let temperature = apparent_temperature(scene, image);
    let per_pixel = |f: &(dyn Fn([f64; 4]) -> f64 + Sync)| -> Vec<f64> {
        image.stokes.par_iter().map(|&s| f(s)).collect()
    };
    let stokes = |j: usize, fixed| LinearPanel {
        file: ["S0.png", "S1.png", "S2.png", "S3.png"][j],
        title: format!("S{j} (W·m⁻²·sr⁻¹)"),
        values: per_pixel(&|s| s[j]),
        fixed,
        symmetric: true,
        map: &DIVERGING,
    };
    let mut panels = vec![
        LinearPanel {
            file: "S0.png",
            title: "S0 — apparent temperature (K)".into(),
            values: per_pixel(&|s| temperature.at(s[0])),
            fixed: settings.s0_k,
            symmetric: false,
            map: match settings.s0_colormap {
                S0Colormap::Thermal => &THERMAL,
                S0Colormap::Gray => &GRAY,
            },
        },
        stokes(1, settings.s1),
        stokes(2, settings.s2),
        LinearPanel {
            file: "DoLP.png",
            title: "DoLP (%)".into(),
            values: per_pixel(&|s| 100.0 * dolp_aop(s).0),
            // From 0 unless fixed (NaN: the automatic high end).
            fixed: settings.dolp_percent.or(Some([0.0, f64::NAN])),
            symmetric: false,
            map: &SEQUENTIAL,
        },
    ];
    // S3 only where light was transported between surfaces (the open world has none).
    if matches!(scene.transport, Transport::Path(_)) {
        panels.push(stokes(3, settings.s3));
    }
    panels
}

/// The usual name of an infrared band (ISO 20473 style ranges), else the band in µm.
fn band_name((lo, hi): (f64, f64)) -> String {
    if lo >= 7.0 && hi <= 15.0 {
        "LWIR".into()
    } else if lo >= 3.0 && hi <= 5.5 {
        "MWIR".into()
    } else if lo >= 0.9 && hi <= 2.5 {
        "SWIR".into()
    } else {
        format!("{lo}–{hi} µm")
    }
}

/// Which pixels set the automatic colour ranges: the object pixels, or all when none is seen.
fn ranged_pixels(image: &StokesImage) -> Vec<bool> {
    let any_object = image.surface.iter().any(|&o| o != BACKGROUND);
    image
        .surface
        .iter()
        .map(|&s| s != BACKGROUND || !any_object)
        .collect()
}

/// S0 → apparent temperature, through a lookup over the radiance range of the image.
fn apparent_temperature(scene: &Scene, image: &StokesImage) -> TemperatureLookup {
    let (lo, hi) = image
        .stokes
        .iter()
        .fold((f64::INFINITY, 0.0f64), |(lo, hi), s| {
            (lo.min(s[0]), hi.max(s[0]))
        });
    TemperatureLookup::new(&scene.sensor.band, lo.max(0.0).min(hi), hi)
}

/// AoP on the cyclic map, grey where DoLP is below the scene's threshold.
fn aop_panel(image: &StokesImage, mask: f64) -> Panel {
    let colors = image
        .stokes
        .par_iter()
        .map(|&s| {
            let (d, a) = dolp_aop(s);
            if d < mask || d == 0.0 {
                MASKED
            } else {
                cyclic(a / std::f64::consts::PI + 0.5)
            }
        })
        .collect();
    Panel {
        file: "AoP.png",
        title: format!(
            "AoP (° from image right; grey: DoLP < {:.2} %)",
            mask * 100.0
        ),
        colors,
        bar: Bar::Cyclic,
    }
}

/// The composite's caption: scene, size, shading, band, air, transport and sun.
fn caption(scene: &Scene, image: &StokesImage) -> String {
    let mut stem = scene
        .path
        .file_stem()
        .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
    if let Some(instant) = &scene.thermal_instant {
        stem += &format!(" at {}", instant.time_utc);
    }
    let (lo_um, hi_um) = scene.sensor.band.limits_um();
    let shading = scene.shading.describe();
    let mut caption = format!(
        "{stem}: {}×{}, {shading} shading, {lo_um}–{hi_um} µm, air {:.2} K",
        image.width, image.height, scene.air_temperature_k
    );
    if let Transport::Path(settings) = scene.transport {
        caption += &format!(
            ", occlusion: {} bounces, {} paths/pixel",
            settings.bounces, settings.samples
        );
        if let Some(sun) = scene.sun {
            let p = sun.position();
            caption += &format!(
                ", sun at {:.0}° elevation, {:.0}° azimuth",
                p.elevation_deg, p.azimuth_deg
            );
        }
    }
    caption
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn titles_follow_the_band() {
        assert_eq!(band_name((8.0, 14.0)), "LWIR");
        assert_eq!(band_name((3.0, 5.0)), "MWIR");
        assert_eq!(band_name((1.0, 1.7)), "SWIR");
        assert_eq!(band_name((2.0, 12.0)), "2–12 µm");
    }
}
