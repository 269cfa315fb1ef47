//! Drawing a panel onto an RGB canvas: the title, the image resampled to its cell, the colour
//! bar with round-valued ticks, and PNG encoding. Text is drawn with plotters using the embedded
//! DejaVu Sans font.

use super::{Bar, Panel};
use crate::output::colormap::cyclic;
use crate::plot_style::{register_fonts, FONT};
use image::ImageEncoder;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use std::io;

/// RGB image buffer.
pub(super) struct Canvas {
    pub(super) width: usize,
    pub(super) height: usize,
    pub(super) rgb: Vec<u8>,
}

impl Canvas {
    pub(super) fn white(width: usize, height: usize) -> Canvas {
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

    pub(super) fn blit(&mut self, other: &Canvas, x0: usize, y0: usize) {
        for y in 0..other.height {
            let src = &other.rgb[3 * y * other.width..3 * (y + 1) * other.width];
            let start = 3 * ((y0 + y) * self.width + x0);
            self.rgb[start..start + src.len()].copy_from_slice(src);
        }
    }

    pub(super) fn png(&self) -> io::Result<Vec<u8>> {
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
pub(super) fn draw_panel(
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
pub(super) struct PanelLayout {
    /// Text size (px) the title and tick labels are scaled from.
    font: f64,
    pub(super) margin: usize,
    pub(super) title_h: usize,
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
    pub(super) fn new(bar: &Bar, img_w: usize, img_h: usize) -> PanelLayout {
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

pub(super) fn draw_error<E: std::fmt::Debug>(e: E) -> io::Error {
    io::Error::other(format!("drawing the preview failed: {e:?}"))
}

#[cfg(test)]
mod tests {
    use super::super::{Bar, Clipped};
    use super::*;
    use crate::output::colormap::THERMAL;

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
}
