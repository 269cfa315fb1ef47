//! PNG previews with colour bars (S0 as apparent temperature, S1/S2 diverging about zero, DoLP
//! sequential, AoP cyclic and masked where DoLP is below the scene's threshold) and a composite
//! figure in the layout of the paper's Fig. 5. Colour ranges are robust: 1st–99th percentiles over
//! the object pixels (symmetric for S1/S2), so a few glints do not wash out the image.
//! Text is drawn with plotters using the embedded DejaVu Sans font.

use super::colormap::{cyclic, ColorMap, Lut, DIVERGING, MASKED, SEQUENTIAL, THERMAL};
use crate::render::film::{dolp_aop, StokesImage, BACKGROUND};
use crate::report::{register_fonts, FONT};
use crate::scene::config::Shading;
use crate::scene::{Scene, Transport};
use crate::transport::tables::TemperatureLookup;
use image::ImageEncoder;
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
        format: fn(f64) -> String,
    },
    Cyclic,
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
}

impl Previews {
    pub fn new(scene: &Scene, image: &StokesImage) -> Previews {
        let any_object = image.surface.iter().any(|&o| o != BACKGROUND);
        let pick = |f: &(dyn Fn([f64; 4]) -> f64 + Sync)| -> Vec<f64> {
            image
                .stokes
                .par_iter()
                .zip(&image.surface)
                .filter(|&(_, &surface)| surface != BACKGROUND || !any_object)
                .map(|(&s, _)| f(s))
                .filter(|v| v.is_finite())
                .collect()
        };
        let band = &scene.sensor.band;

        // S0 as apparent temperature: percentiles in radiance map to percentiles in temperature.
        let s0 = pick(&|s| s[0]);
        let (r_lo, r_hi) = robust_range(s0, 0.01, 0.99);
        let t_of = |r: f64| band.brightness_temperature(r.max(0.0)).unwrap_or(0.0);
        let (t_lo, t_hi) = widen(t_of(r_lo), t_of(r_hi));
        let temperature = TemperatureLookup::new(band, r_lo.min(r_hi), r_hi.max(r_lo));
        let thermal = Lut::new(&THERMAL);
        let s0_colors = image
            .stokes
            .par_iter()
            .map(|s| thermal.at((temperature.at(s[0]) - t_lo) / (t_hi - t_lo)))
            .collect();

        let diverging = Lut::new(&DIVERGING);
        let symmetric = |j: usize| {
            let magnitudes = pick(&|s| s[j].abs());
            let (_, hi) = robust_range(magnitudes, 0.0, 0.99);
            let m = if hi > 0.0 { hi } else { 1.0 };
            let colors = image
                .stokes
                .par_iter()
                .map(|s| diverging.at(0.5 + 0.5 * s[j] / m))
                .collect();
            (colors, m)
        };
        let (s1_colors, s1_max) = symmetric(1);
        let (s2_colors, s2_max) = symmetric(2);
        // S3 only where light was transported between surfaces (the open world has none).
        let s3_panel = matches!(scene.transport, Transport::Path(_)).then(|| {
            let (colors, m) = symmetric(3);
            Panel {
                file: "S3.png",
                title: "S3 (W·m⁻²·sr⁻¹)".into(),
                colors,
                bar: Bar::Linear {
                    map: &DIVERGING,
                    lo: -m,
                    hi: m,
                    format: format_signed,
                },
            }
        });

        let dolp = pick(&|s| dolp_aop(s).0);
        let (_, d_hi) = robust_range(dolp, 0.0, 0.99);
        let d_hi = if d_hi > 0.0 { d_hi } else { 1e-3 };
        let sequential = Lut::new(&SEQUENTIAL);
        let dolp_colors = image
            .stokes
            .par_iter()
            .map(|&s| sequential.at(dolp_aop(s).0 / d_hi))
            .collect();

        let mask = scene.aop_mask_dolp;
        let aop_colors = image
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

        let mut stem = scene
            .path
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        if let Some(instant) = &scene.thermal_instant {
            stem += &format!(" at {}", instant.time_utc);
        }
        let (lo_um, hi_um) = band.limits_um();
        let shading = match scene.shading {
            Shading::Pixel => "per-pixel",
            Shading::Gouraud => "Gouraud",
        };
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
        Previews {
            width: image.width,
            height: image.height,
            panels: [
                Panel {
                    file: "S0.png",
                    title: "S0 — apparent temperature (K)".into(),
                    colors: s0_colors,
                    bar: Bar::Linear {
                        map: &THERMAL,
                        lo: t_lo,
                        hi: t_hi,
                        format: |v| format!("{v:.1}"),
                    },
                },
                Panel {
                    file: "S1.png",
                    title: "S1 (W·m⁻²·sr⁻¹)".into(),
                    colors: s1_colors,
                    bar: Bar::Linear {
                        map: &DIVERGING,
                        lo: -s1_max,
                        hi: s1_max,
                        format: format_signed,
                    },
                },
                Panel {
                    file: "S2.png",
                    title: "S2 (W·m⁻²·sr⁻¹)".into(),
                    colors: s2_colors,
                    bar: Bar::Linear {
                        map: &DIVERGING,
                        lo: -s2_max,
                        hi: s2_max,
                        format: format_signed,
                    },
                },
                Panel {
                    file: "DoLP.png",
                    title: "DoLP (%)".into(),
                    colors: dolp_colors,
                    bar: Bar::Linear {
                        map: &SEQUENTIAL,
                        lo: 0.0,
                        hi: d_hi * 100.0,
                        format: |v| format!("{v:.2}"),
                    },
                },
                Panel {
                    file: "AoP.png",
                    title: format!(
                        "AoP (° from image right; grey: DoLP < {:.2} %)",
                        mask * 100.0
                    ),
                    colors: aop_colors,
                    bar: Bar::Cyclic,
                },
            ]
            .into_iter()
            .chain(s3_panel)
            .collect(),
            caption,
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
        // At most 480 pixels wide and tall per panel, so an extreme aspect ratio (20 × 200000)
        // does not make a sheet of hundreds of megabytes.
        let scale = (480.0 / self.width as f64)
            .min(480.0 / self.height as f64)
            .min(1.0);
        let (img_w, img_h) = (
            ((self.width as f64 * scale).round() as usize).max(1),
            ((self.height as f64 * scale).round() as usize).max(1),
        );
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
                "LWIR polarimetric simulation (Stokes images)",
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
    let font = (img_h as f64 / 24.0).clamp(11.0, 26.0);
    let margin = 8usize;
    let title_h = (font * 1.9).round() as usize;
    let bar_w = ((img_w as f64 / 40.0).round() as usize).max(12);
    let label_w = (font * 5.0).round() as usize;
    let (width, height) = (
        margin + img_w + margin + bar_w + 6 + label_w,
        title_h + img_h + margin,
    );
    let mut canvas = Canvas::white(width, height);
    for y in 0..img_h {
        let sy = (y * src_h / img_h).min(src_h - 1);
        for x in 0..img_w {
            let sx = (x * src_w / img_w).min(src_w - 1);
            canvas.set(margin + x, title_h + y, panel.colors[sy * src_w + sx]);
        }
    }
    let bar_x = margin + img_w + margin;
    for y in 0..img_h {
        // Top of the bar is the high end.
        let t = 1.0 - (y as f64 + 0.5) / img_h as f64;
        let color = match &panel.bar {
            Bar::Linear { map, .. } => map.at(t),
            Bar::Cyclic => cyclic(t),
        };
        for x in 0..bar_w {
            canvas.set(bar_x + x, title_h + y, color);
        }
    }

    let (w, h) = (width as u32, height as u32);
    {
        let root = BitMapBackend::with_buffer(&mut canvas.rgb, (w, h)).into_drawing_area();
        let title = (FONT, font * 1.05)
            .into_font()
            .style(FontStyle::Bold)
            .color(&BLACK);
        root.draw_text(
            &panel.title,
            &title.pos(Pos::new(HPos::Left, VPos::Center)),
            (margin as i32, title_h as i32 / 2),
        )
        .map_err(draw_error)?;
        let ticks: Vec<(f64, String)> = match &panel.bar {
            Bar::Linear { lo, hi, format, .. } => (0..5)
                .map(|k| {
                    let t = k as f64 / 4.0;
                    (t, format(lo + t * (hi - lo)))
                })
                .collect(),
            Bar::Cyclic => [-90, -45, 0, 45, 90]
                .iter()
                .enumerate()
                .map(|(k, d)| (k as f64 / 4.0, format!("{d}°")))
                .collect(),
        };
        let label = (FONT, font * 0.85)
            .into_font()
            .color(&BLACK)
            .pos(Pos::new(HPos::Left, VPos::Center));
        let x = (bar_x + bar_w) as i32;
        for (t, text) in ticks {
            let y = title_h as i32 + ((1.0 - t) * (img_h as f64 - 1.0)).round() as i32;
            root.draw(&PathElement::new(vec![(x, y), (x + 4, y)], BLACK))
                .map_err(draw_error)?;
            root.draw_text(&text, &label, (x + 6, y))
                .map_err(draw_error)?;
        }
        root.draw(&Rectangle::new(
            [
                (bar_x as i32, title_h as i32),
                (x, (title_h + img_h) as i32),
            ],
            BLACK.stroke_width(1),
        ))
        .map_err(draw_error)?;
        root.present().map_err(draw_error)?;
    }
    Ok(canvas)
}

fn draw_error<E: std::fmt::Debug>(e: E) -> io::Error {
    io::Error::other(format!("drawing the preview failed: {e:?}"))
}

fn format_signed(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 0.1 {
        format!("{v:+.3}")
    } else {
        format!("{v:+.2e}")
    }
}

/// (p_lo, p_hi) quantiles of the values (0, 1 when empty).
fn robust_range(mut values: Vec<f64>, p_lo: f64, p_hi: f64) -> (f64, f64) {
    if values.is_empty() {
        return (0.0, 1.0);
    }
    let mut quantile = |p: f64| {
        let k = ((values.len() - 1) as f64 * p).round() as usize;
        *values.select_nth_unstable_by(k, f64::total_cmp).1
    };
    (quantile(p_lo), quantile(p_hi))
}

/// A non-empty display range.
fn widen(lo: f64, hi: f64) -> (f64, f64) {
    if hi - lo > 1e-6 {
        (lo, hi)
    } else {
        (lo - 0.5, hi + 0.5)
    }
}
