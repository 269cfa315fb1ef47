//! PNG previews with colour bars (S0 as apparent temperature, S1/S2 diverging about zero, DoLP
//! sequential, AoP cyclic and masked where DoLP is below the scene's threshold) and a composite
//! figure in the layout of the paper's Fig. 5. Colour ranges follow `[render.preview]`: by default
//! the 0.1th–99.9th percentiles over the object pixels (symmetric for S1/S2/S3), reaching past them
//! to take in values just beyond (noise), so a few glints do not wash out the image and noise does
//! not speckle it; object pixels outside are drawn in the map's under/over colours, capped on the
//! colour bar and counted in the title, never silently clipped. Sky and environment ground take
//! the map's end colours. A time series is coloured over one range ([`SeriesPreview`]).
//! Text is drawn with plotters using the embedded DejaVu Sans font.

use super::colormap::{cyclic, ColorMap, Lut, DIVERGING, GRAY, MASKED, SEQUENTIAL, THERMAL};
use crate::optics::TemperatureLookup;
use crate::plot_style::{register_fonts, FONT};
use crate::render::camera::metrics::{aop_difference, AOP_DOLP_THRESHOLD};
use crate::render::camera::DofpImages;
use crate::render::film::{dolp_aop, StokesImage, BACKGROUND};
use crate::scene::config::{PreviewConfig, PreviewRange, S0Colormap};
use crate::scene::{Scene, Transport};
use image::ImageEncoder;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use rayon::prelude::*;
use std::io;

/// Default percentile range of the previews: wide enough that a hot hood or a strongly
/// polarizing windshield (a few % of the pixels) stays inside the colour bar, narrow enough that
/// a handful of glint or noise pixels does not wash the image out; what falls outside is drawn in
/// the map's under/over colours and counted in the title.
const DEFAULT_PERCENTILES: [f64; 2] = [0.1, 99.9];

/// How far past the default percentiles (a fraction of their distance) the range reaches to
/// take in the values just beyond them. Pure Gaussian noise (a flat scene under NETD) has its
/// 0.1/99.9 % points at ±3.09σ and its extremes near ±4.9σ over a megapixel, ±5.3σ over ten:
/// 0.4 × 6.18σ reaches ±5.56σ, so noise alone is not drawn clipped.
const DEFAULT_MARGIN: f64 = 0.4;

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

/// A sheet cell's image size: at most 480 pixels wide and tall, so an extreme aspect ratio
/// (20 × 200000) does not make a sheet of hundreds of megabytes.
fn cell_size(width: usize, height: usize) -> (usize, usize) {
    let scale = (480.0 / width as f64).min(480.0 / height as f64).min(1.0);
    (
        ((width as f64 * scale).round() as usize).max(1),
        ((height as f64 * scale).round() as usize).max(1),
    )
}

impl LinearPanel {
    /// The panel: its range (fixed, else by `settings.range` over the `ranged` pixels), each
    /// pixel's colour, ranged pixels out of range in the map's under/over colours, the clip
    /// stated in the title.
    fn panel(self, ranged: &[bool], settings: &PreviewConfig) -> Panel {
        let range = self.range(self.ranging_values(ranged).collect(), settings);
        self.coloured(ranged, range)
    }

    /// The values of the `ranged` pixels that set an automatic range (|value| when symmetric).
    fn ranging_values<'a>(&'a self, ranged: &'a [bool]) -> impl Iterator<Item = f64> + 'a {
        self.values
            .iter()
            .zip(ranged)
            .filter(|&(v, &r)| r && v.is_finite())
            .map(|(&v, _)| if self.symmetric { v.abs() } else { v })
    }

    /// The display range: fixed, or automatic over `chosen` ([`Self::ranging_values`], of one
    /// image or of a whole time series).
    fn range(&self, chosen: Vec<f64>, settings: &PreviewConfig) -> (f64, f64) {
        let auto = || {
            let (percentiles, margin) = match (settings.range, settings.percentiles) {
                (PreviewRange::Minmax, _) => ([0.0, 100.0], 0.0),
                (PreviewRange::Percentile, Some(given)) => (given, 0.0),
                (PreviewRange::Percentile, None) => (DEFAULT_PERCENTILES, DEFAULT_MARGIN),
            };
            let [p_lo, p_hi] = percentiles;
            let p_lo = if self.symmetric { 0.0 } else { p_lo };
            robust_range(chosen, p_lo / 100.0, p_hi / 100.0, margin)
        };
        let (lo, hi) = match self.fixed {
            // DoLP's default: from 0 to the automatic high end.
            Some([lo, hi]) if hi.is_nan() => (lo, auto().1),
            Some([lo, hi]) => (lo, hi),
            None if self.symmetric => {
                let m = auto().1;
                let m = if m > 0.0 { m } else { 1.0 };
                (-m, m)
            }
            None => auto(),
        };
        widen(lo, hi)
    }

    /// The panel coloured over `(lo, hi)`. A ranged pixel outside it takes the map's under/over
    /// colour and is counted in the title; the others (sky and the environment's ground beside
    /// objects, which do not set the range) take the map's end colour: a sky colder than every
    /// object is the map's cold end, not an alarm.
    fn coloured(self, ranged: &[bool], (lo, hi): (f64, f64)) -> Panel {
        let lut = Lut::new(self.map);
        let colors: Vec<[u8; 3]> = self
            .values
            .par_iter()
            .zip(ranged)
            .map(|(&v, &r)| match v {
                v if v.is_nan() => MASKED,
                v if v < lo && r => self.map.under,
                v if v > hi && r => self.map.over,
                v if v < lo => lut.at(0.0),
                v if v > hi => lut.at(1.0),
                v => lut.at((v - lo) / (hi - lo)),
            })
            .collect();
        let ranged_count = ranged.iter().filter(|&&r| r).count().max(1) as f64;
        let count = |f: &dyn Fn(f64) -> bool| {
            self.values
                .iter()
                .zip(ranged)
                .filter(|&(&v, &r)| r && f(v))
                .count() as f64
                / ranged_count
        };
        let clipped = Clipped {
            below: count(&|v| v < lo),
            above: count(&|v| v > hi),
        };
        let mut title = self.title;
        let sides: Vec<String> = [(clipped.below, "below"), (clipped.above, "above")]
            .iter()
            .filter(|(fraction, _)| *fraction > 0.0)
            .map(|(fraction, side)| format!("{} {side}", percent(*fraction)))
            .collect();
        if !sides.is_empty() {
            title += &format!(" — pixels clipped: {}", sides.join(", "));
        }
        Panel {
            file: self.file,
            title,
            colors,
            bar: Bar::Linear {
                map: self.map,
                lo,
                hi,
                signed: self.symmetric,
                clipped,
            },
        }
    }
}

/// A clipped fraction (> 0) as a percentage: one decimal, but never "0.0 %" for a few pixels.
fn percent(fraction: f64) -> String {
    match 100.0 * fraction {
        p if p < 0.05 => "< 0.1 %".into(),
        p => format!("{p:.1} %"),
    }
}

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

/// RGB image buffer.
struct Canvas {
    width: usize,
    height: usize,
    rgb: Vec<u8>,
}

impl Canvas {
    fn white(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            rgb: vec![255; width * height * 3],
        }
    }

    fn set(&mut self, x: usize, y: usize, c: [u8; 3]) {
        let i = 3 * (y * self.width + x);
        self.rgb[i..i + 3].copy_from_slice(&c);
    }

    fn blit(&mut self, other: &Canvas, x0: usize, y0: usize) {
        for y in 0..other.height {
            let src = &other.rgb[3 * y * other.width..3 * (y + 1) * other.width];
            let start = 3 * ((y0 + y) * self.width + x0);
            self.rgb[start..start + src.len()].copy_from_slice(src);
        }
    }

    fn png(&self) -> io::Result<Vec<u8>> {
        let mut bytes = Vec::new();
        // Fast deflate: previews are large and rewritten on every render.
        image::codecs::png::PngEncoder::new_with_quality(
            &mut bytes,
            image::codecs::png::CompressionType::Fast,
            image::codecs::png::FilterType::Adaptive,
        )
        .write_image(
            &self.rgb,
            self.width as u32,
            self.height as u32,
            image::ExtendedColorType::Rgb8,
        )
        .map_err(io::Error::other)?;
        Ok(bytes)
    }
}

/// One panel: title on top, the image (resampled to img_w × img_h by nearest neighbour), and a
/// colour bar with ticks on the right.
fn draw_panel(
    panel: &Panel,
    src_w: usize,
    src_h: usize,
    img_w: usize,
    img_h: usize,
) -> io::Result<Canvas> {
    register_fonts();
    let layout = PanelLayout::new(&panel.bar, img_w, img_h);
    let mut canvas = Canvas::white(layout.width, layout.height);
    draw_resampled(&mut canvas, panel, (src_w, src_h), &layout);
    draw_colour_bar(&mut canvas, &panel.bar, &layout);
    draw_panel_text(&mut canvas, panel, &layout)?;
    Ok(canvas)
}

/// Where everything of a panel goes, in pixels, for an image of img_w × img_h.
struct PanelLayout {
    /// Text size (px) the title and tick labels are scaled from.
    font: f64,
    margin: usize,
    title_h: usize,
    img_w: usize,
    img_h: usize,
    bar_x: usize,
    bar_w: usize,
    /// Heights of the under/over caps at the top and bottom of the bar (0 without clipping).
    cap_top: usize,
    cap_bottom: usize,
    gradient_h: usize,
    width: usize,
    height: usize,
}

impl PanelLayout {
    fn new(bar: &Bar, img_w: usize, img_h: usize) -> PanelLayout {
        let font = (img_h as f64 / 24.0).clamp(11.0, 26.0);
        let margin = 8usize;
        let title_h = (font * 1.9).round() as usize;
        let bar_w = ((img_w as f64 / 40.0).round() as usize).max(12);
        let label_w = (font * 5.0).round() as usize;
        // Clipped values get a cap of the map's under/over colour at that end of the bar.
        let cap = (img_h / 14).max(6).min(img_h / 4);
        let (cap_top, cap_bottom) = match bar {
            Bar::Linear { clipped, .. } => (
                if clipped.above > 0.0 { cap } else { 0 },
                if clipped.below > 0.0 { cap } else { 0 },
            ),
            Bar::Cyclic => (0, 0),
        };
        PanelLayout {
            font,
            margin,
            title_h,
            img_w,
            img_h,
            bar_x: margin + img_w + margin,
            bar_w,
            cap_top,
            cap_bottom,
            gradient_h: img_h - cap_top - cap_bottom,
            width: margin + img_w + margin + bar_w + 6 + label_w,
            height: title_h + img_h + margin,
        }
    }
}

/// The panel's image, resampled from src_w × src_h by nearest neighbour.
fn draw_resampled(
    canvas: &mut Canvas,
    panel: &Panel,
    (src_w, src_h): (usize, usize),
    layout: &PanelLayout,
) {
    let (img_w, img_h) = (layout.img_w, layout.img_h);
    for y in 0..img_h {
        let sy = (y * src_h / img_h).min(src_h - 1);
        for x in 0..img_w {
            let sx = (x * src_w / img_w).min(src_w - 1);
            canvas.set(
                layout.margin + x,
                layout.title_h + y,
                panel.colors[sy * src_w + sx],
            );
        }
    }
}

/// The colour bar beside the image: the gradient, high end on top, between the caps.
fn draw_colour_bar(canvas: &mut Canvas, bar: &Bar, layout: &PanelLayout) {
    let (img_h, cap_top, cap_bottom) = (layout.img_h, layout.cap_top, layout.cap_bottom);
    for y in 0..img_h {
        let color = match bar {
            Bar::Linear { map, .. } if y < cap_top => map.over,
            Bar::Linear { map, .. } if y >= img_h - cap_bottom => map.under,
            bar => {
                // Top of the gradient is the high end.
                let t = 1.0 - ((y - cap_top) as f64 + 0.5) / layout.gradient_h as f64;
                match bar {
                    Bar::Linear { map, .. } => map.at(t),
                    Bar::Cyclic => cyclic(t),
                }
            }
        };
        for x in 0..layout.bar_w {
            canvas.set(layout.bar_x + x, layout.title_h + y, color);
        }
    }
}

/// The colour bar's ticks, as fractions of its range with their labels: round values (multiples
/// of a 1-2-5 step, 3–6 of them) for a linear bar, every 45° for the cyclic one.
fn bar_ticks(bar: &Bar) -> Vec<(f64, String)> {
    match *bar {
        Bar::Linear { lo, hi, signed, .. } => {
            let step = tick_step(hi - lo);
            let first = (lo / step - 1e-6).ceil() as i64;
            let last = (hi / step + 1e-6).floor() as i64;
            (first..=last)
                .map(|k| {
                    let v = k as f64 * step;
                    let t = ((v - lo) / (hi - lo)).clamp(0.0, 1.0);
                    (t, tick_label(v, step, signed))
                })
                .collect()
        }
        Bar::Cyclic => [-90, -45, 0, 45, 90]
            .iter()
            .enumerate()
            .map(|(k, &d)| {
                (
                    k as f64 / 4.0,
                    format!("{}°", tick_label(d.into(), 45.0, false)),
                )
            })
            .collect(),
    }
}

/// The smallest step of 1, 2 or 5 times a power of ten that cuts `span` into at most 5 parts.
fn tick_step(span: f64) -> f64 {
    let raw = span / 5.0;
    let decade = 10f64.powf(raw.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * decade)
        .find(|&step| step >= raw * (1.0 - 1e-9))
        .unwrap_or(10.0 * decade)
}

/// A tick value with the digits its `step` needs (scientific below 1e-4), the minus as '−' and,
/// when `signed`, a '+' on positive values.
fn tick_label(v: f64, step: f64, signed: bool) -> String {
    if v.abs() < step * 1e-6 {
        return "0".into();
    }
    let step_exponent = step.log10().floor() as i32;
    let digits = if step_exponent >= -4 {
        format!("{:.*}", (-step_exponent).max(0) as usize, v.abs())
    } else {
        let v_exponent = v.abs().log10().floor() as i32;
        format!(
            "{:.*e}",
            (v_exponent - step_exponent).max(0) as usize,
            v.abs()
        )
    };
    let sign = match (v < 0.0, signed) {
        (true, _) => "−",
        (false, true) => "+",
        (false, false) => "",
    };
    format!("{sign}{digits}")
}

/// The title, the colour bar's ticks and labels, and its frame, drawn with plotters.
fn draw_panel_text(canvas: &mut Canvas, panel: &Panel, layout: &PanelLayout) -> io::Result<()> {
    let (w, h) = (canvas.width as u32, canvas.height as u32);
    let (font, title_h) = (layout.font, layout.title_h);
    let root = BitMapBackend::with_buffer(&mut canvas.rgb, (w, h)).into_drawing_area();
    let title = (FONT, font * 1.05)
        .into_font()
        .style(FontStyle::Bold)
        .color(&BLACK);
    root.draw_text(
        &panel.title,
        &title.pos(Pos::new(HPos::Left, VPos::Center)),
        (layout.margin as i32, title_h as i32 / 2),
    )
    .map_err(draw_error)?;
    let label = (FONT, font * 0.85)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Center));
    let x = (layout.bar_x + layout.bar_w) as i32;
    let top = (title_h + layout.cap_top) as i32;
    for (t, text) in bar_ticks(&panel.bar) {
        let y = top + ((1.0 - t) * (layout.gradient_h as f64 - 1.0)).round() as i32;
        // The mark on the bar's other side from its label, so that it cannot read as a minus.
        let left = layout.bar_x as i32;
        root.draw(&PathElement::new(vec![(left - 5, y), (left - 1, y)], BLACK))
            .map_err(draw_error)?;
        root.draw_text(&text, &label, (x + 5, y))
            .map_err(draw_error)?;
    }
    root.draw(&Rectangle::new(
        [
            (layout.bar_x as i32, title_h as i32),
            (x, (title_h + layout.img_h) as i32),
        ],
        BLACK.stroke_width(1),
    ))
    .map_err(draw_error)?;
    root.present().map_err(draw_error)
}

fn draw_error<E: std::fmt::Debug>(e: E) -> io::Error {
    io::Error::other(format!("drawing the preview failed: {e:?}"))
}

/// (p_lo, p_hi) quantiles of the values (0, 1 when empty), each moved out by `margin` times
/// their distance but not past the values' own extremes: noise that straddles a cut-off stays in
/// range (it would paint speckle in the under/over colours), outliers far beyond it do not.
fn robust_range(mut values: Vec<f64>, p_lo: f64, p_hi: f64, margin: f64) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 1.0);
    }
    let mut quantile = |p: f64| {
        let k = ((values.len() - 1) as f64 * p).round() as usize;
        *values.select_nth_unstable_by(k, f64::total_cmp).1
    };
    let (lo, hi) = (quantile(p_lo), quantile(p_hi));
    if margin == 0.0 {
        return (lo, hi);
    }
    let (min, max) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let reach = margin * (hi - lo);
    ((lo - reach).max(min), (hi + reach).min(max))
}

/// A non-empty display range.
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if hi - lo > 1e-6 {
        (lo, hi)
    } else {
        (lo - 0.5, hi + 0.5)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ramp_panel(fixed: Option<[f64; 2]>, range: PreviewRange) -> Panel {
        // 0, 1, …, 999 with every pixel ranged.
        let ranged = vec![true; 1000];
        let settings = PreviewConfig {
            range,
            ..PreviewConfig::default()
        };
        LinearPanel {
            file: "x.png",
            title: "x".into(),
            values: (0..1000).map(f64::from).collect(),
            fixed,
            symmetric: false,
            map: &THERMAL,
        }
        .panel(&ranged, &settings)
    }

    fn clipped(panel: &Panel) -> (f64, f64, f64, f64) {
        match &panel.bar {
            Bar::Linear {
                lo, hi, clipped, ..
            } => (*lo, *hi, clipped.below, clipped.above),
            Bar::Cyclic => unreachable!(),
        }
    }

    fn ticks(lo: f64, hi: f64, signed: bool) -> Vec<String> {
        let bar = Bar::Linear {
            map: &THERMAL,
            lo,
            hi,
            signed,
            clipped: Clipped::default(),
        };
        let ticks = bar_ticks(&bar);
        assert!(ticks.iter().all(|(t, _)| (-1e-9..=1.0 + 1e-9).contains(t)));
        ticks.into_iter().map(|(_, label)| label).collect()
    }

    #[test]
    fn colour_bar_ticks_are_round_values_of_a_1_2_5_step() {
        assert_eq!(ticks(288.37, 319.62, false), ["290", "300", "310"]);
        assert_eq!(ticks(0.0, 3.7, false), ["0", "1", "2", "3"]);
        assert_eq!(
            ticks(-0.0417, 0.0417, true),
            ["−0.04", "−0.02", "0", "+0.02", "+0.04"]
        );
        assert_eq!(ticks(-45.0, 45.0, true), ["−40", "−20", "0", "+20", "+40"]);
        assert_eq!(
            ticks(0.0, 2.4e-6, false),
            ["0", "5e-7", "1.0e-6", "1.5e-6", "2.0e-6"]
        );
        for (lo, hi) in [(0.0, 1.0), (287.1, 287.3), (-3e-3, 3e-3), (0.0, 97.3)] {
            let n = ticks(lo, hi, false).len();
            assert!((3..=6).contains(&n), "{lo}…{hi}: {n} ticks");
        }
    }

    #[test]
    fn titles_follow_the_band() {
        assert_eq!(band_name((8.0, 14.0)), "LWIR");
        assert_eq!(band_name((3.0, 5.0)), "MWIR");
        assert_eq!(band_name((1.0, 1.7)), "SWIR");
        assert_eq!(band_name((2.0, 12.0)), "2–12 µm");
    }

    #[test]
    fn out_of_range_pixels_are_marked_and_counted() {
        let panel = ramp_panel(Some([100.0, 899.0]), PreviewRange::Percentile);
        assert_eq!(clipped(&panel), (100.0, 899.0, 0.1, 0.1));
        assert_eq!(panel.colors[50], THERMAL.under);
        assert_eq!(panel.colors[950], THERMAL.over);
        assert_eq!(panel.colors[100], THERMAL.at(0.0));
        assert!(
            panel
                .title
                .contains("pixels clipped: 10.0 % below, 10.0 % above"),
            "{}",
            panel.title
        );

        let minmax = ramp_panel(None, PreviewRange::Minmax);
        assert_eq!(clipped(&minmax), (0.0, 999.0, 0.0, 0.0));
        assert_eq!(minmax.title, "x");

        // The default percentiles (1 and 998) reach out to the ramp's ends: nothing clipped.
        let auto = ramp_panel(None, PreviewRange::Percentile);
        assert_eq!(clipped(&auto), (0.0, 999.0, 0.0, 0.0));
        assert_eq!(auto.title, "x");
    }

    /// `n` standard normal values (Box–Muller over a seeded generator).
    fn gaussian(n: usize, seed: u64) -> Vec<f64> {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        (0..n)
            .map(|_| {
                let (u, v): (f64, f64) = (rng.random(), rng.random());
                (-2.0 * (1.0 - u).ln()).sqrt() * (std::f64::consts::TAU * v).cos()
            })
            .collect()
    }

    fn panel_of(values: Vec<f64>, ranged: &[bool], settings: &PreviewConfig) -> Panel {
        LinearPanel {
            file: "S0.png",
            title: "S0".into(),
            values,
            fixed: None,
            symmetric: false,
            map: &THERMAL,
        }
        .panel(ranged, settings)
    }

    #[test]
    fn detector_noise_alone_is_not_drawn_clipped_but_a_glint_is() {
        // A flat 300 K scene with 20 mK of noise over a megapixel: its extremes lie beyond the
        // 0.1/99.9 % points, which used to paint ~2000 speckles in the under/over colours.
        let values: Vec<f64> = gaussian(1 << 20, 7)
            .into_iter()
            .map(|z| 300.0 + 0.02 * z)
            .collect();
        let ranged = vec![true; values.len()];
        let settings = PreviewConfig::default();
        let panel = panel_of(values.clone(), &ranged, &settings);
        let (lo, hi, below, above) = clipped(&panel);
        assert_eq!((below, above), (0.0, 0.0), "{lo} … {hi}");
        assert!(!panel.title.contains("clipped"), "{}", panel.title);

        // A glint of 20 pixels at 340 K is far beyond the noise: it is clipped and counted.
        let mut glinting = values;
        glinting[..20].fill(340.0);
        let panel = panel_of(glinting, &ranged, &settings);
        let (_, hi, below, above) = clipped(&panel);
        assert!(hi < 300.2 && below == 0.0 && above > 0.0, "{hi} {above}");
        assert_eq!(panel.colors[0], THERMAL.over);
        assert!(
            panel.title.ends_with(" — pixels clipped: < 0.1 % above"),
            "{}",
            panel.title
        );

        // Percentiles the scene gives are taken as they are.
        let given = PreviewConfig {
            percentiles: Some([5.0, 95.0]),
            ..PreviewConfig::default()
        };
        let ramp: Vec<f64> = (0..1000).map(f64::from).collect();
        let panel = panel_of(ramp, &[true; 1000], &given);
        assert_eq!(clipped(&panel), (50.0, 949.0, 0.05, 0.05));
    }

    #[test]
    fn sky_outside_the_range_takes_the_maps_end_colour_and_is_not_counted_as_clipped() {
        // Objects at 290…300 K in the first 100 pixels, a 230 K sky and a 320 K patch of the
        // environment's ground in the others: neither sets the range nor is drawn as a clip.
        let mut values: Vec<f64> = (0..100).map(|i| 290.0 + 0.1 * f64::from(i)).collect();
        values.extend([230.0; 50]);
        values.extend([320.0; 50]);
        let ranged: Vec<bool> = (0..200).map(|i| i < 100).collect();
        let panel = panel_of(values, &ranged, &PreviewConfig::default());
        let (lo, hi, below, above) = clipped(&panel);
        assert_eq!((lo, hi, below, above), (290.0, 299.9, 0.0, 0.0));
        assert_eq!(panel.colors[120], THERMAL.at(0.0));
        assert_eq!(panel.colors[170], THERMAL.at(1.0));
        assert!(!panel.title.contains("clipped"), "{}", panel.title);
    }

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
