//! The report of a spectral fit (docs/design.md §1.9): n(λ) and k(λ) with their errors, the fit at each
//! wavelength, and the directional emissivity over wavelength and angle.
//!
//! One 3000 × 1700 figure, `<material>.png` and `.svg`: (a) n(λ), (b) k(λ) (1-σ error bars at the
//! measured wavelengths; a Lorentz law, when one was fitted, drawn densely over the range), (d) χ²
//! per observation at each wavelength, (c) the directional emissivity ε0(λ, θe) of the fitted
//! model as a heat map, and (e) the shared parameters, the dispersion's AIC comparison and the
//! per-wavelength values. Beside it, `<material>/<λ>um.png`: the grey fit report of each
//! wavelength's measurement against the joint model at that wavelength.

mod emissivity;
mod panels;
mod per_wavelength;
mod summary;

pub use emissivity::{emissivity_grid, EmissivityGrid};

use super::fit_report::style::{DrawResult, LEGEND_SIZE};
use super::fit_report::{draw_error, encode_bitmap, report_stem, EncodedReport};
use super::ReportError;
use crate::fit::SpectralFitOutcome;
use crate::material::SpectralModel;
use crate::plot_style::{register_fonts, FONT};
use crate::text::number;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::{Path, PathBuf};

/// Pixel size of the spectral report figure: a header, then two rows of panels.
pub const SPECTRAL_REPORT_SIZE: (u32, u32) = (3000, 1700);
const HEADER_HEIGHT: i32 = 100;
const ROW_HEIGHT: i32 = 800;
/// Cells of the emissivity map: wavelengths spread evenly over the table (its nodes are added),
/// and emission angles 0…85°.
pub const MAP_WAVELENGTHS: usize = 60;
pub const MAP_ANGLES: usize = 35;

/// Where each panel lies in the figure: (x, y, width, height) in pixels.
const INDEX_N: (i32, i32, i32, i32) = (0, HEADER_HEIGHT, 1000, ROW_HEIGHT);
const INDEX_K: (i32, i32, i32, i32) = (1000, HEADER_HEIGHT, 1000, ROW_HEIGHT);
const CHI2: (i32, i32, i32, i32) = (2000, HEADER_HEIGHT, 1000, ROW_HEIGHT);
const MAP: (i32, i32, i32, i32) = (0, HEADER_HEIGHT + ROW_HEIGHT, 1800, ROW_HEIGHT);
const TABLE: (i32, i32, i32, i32) = (1800, HEADER_HEIGHT + ROW_HEIGHT, 1200, ROW_HEIGHT);

/// Draws the report of a spectral fit under `out_dir`, in memory: `<material>.png` (first) and
/// `.svg`, then `<material>/<λ>um.png` for each wavelength, ascending.
pub fn encode_spectral_report(
    outcome: &SpectralFitOutcome,
    out_dir: &Path,
) -> Result<EncodedReport, ReportError> {
    let stem = report_stem(&outcome.material.name)?;
    let png = out_dir.join(format!("{stem}.png"));
    let svg = out_dir.join(format!("{stem}.svg"));
    let model = spectral_model(outcome, &png)?;
    let grid = emissivity_grid(&outcome.material, MAP_WAVELENGTHS, MAP_ANGLES)?;
    let figure = Figure {
        outcome,
        model,
        grid: &grid,
    };
    // The figure, its SVG and the per-wavelength reports are independent drawings.
    let ((png_bytes, svg_text), pages) = rayon::join(
        || {
            rayon::join(
                || encode_bitmap(&png, SPECTRAL_REPORT_SIZE, |root| figure.draw(root)),
                || figure.encode_svg(&svg),
            )
        },
        || per_wavelength::encode_wavelength_reports(outcome, &out_dir.join(stem)),
    );
    let mut files = vec![(png, png_bytes?), (svg, svg_text?.into_bytes())];
    files.extend(pages?);
    Ok(EncodedReport { files })
}

/// The per-wavelength report's path: `<dir>/<λ>um.png` ("9.5um.png").
pub fn wavelength_report_path(dir: &Path, wavelength_um: f64) -> PathBuf {
    dir.join(format!("{}um.png", number(wavelength_um)))
}

/// The outcome's spectral model, checked to hold one entry per measured wavelength.
fn spectral_model<'a>(
    outcome: &'a SpectralFitOutcome,
    path: &Path,
) -> Result<&'a SpectralModel, ReportError> {
    let refuse = |message: String| Err(draw_error(path, &message));
    let Some(model) = outcome.material.model.spectral() else {
        return refuse("the material of a spectral fit is not spectral".into());
    };
    let count = model.wavelength_um.len();
    let fit = &outcome.chosen;
    let lengths = [
        outcome.measurements.len(),
        model.n.len(),
        model.k.len(),
        fit.n_errors.len(),
        fit.k_errors.len(),
        fit.rho_d_errors.len(),
        fit.chi2_per_wavelength.len(),
        fit.model_muellers.len(),
    ];
    if count < 2 || lengths.iter().any(|&l| l != count) {
        return refuse(format!(
            "the spectral fit's per-wavelength results disagree in length ({count} wavelengths, \
             {lengths:?})"
        ));
    }
    Ok(model)
}

/// What the composite figure draws.
struct Figure<'a> {
    outcome: &'a SpectralFitOutcome,
    model: &'a SpectralModel,
    grid: &'a EmissivityGrid,
}

impl Figure<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        register_fonts();
        root.fill(&WHITE)?;
        self.draw_header(root)?;
        let range = x_range(self.model);
        let [n, k] = panels::index_panels(self.outcome, self.model);
        panels::draw_index(&place(root, INDEX_N), &n, range)?;
        panels::draw_index(&place(root, INDEX_K), &k, range)?;
        panels::draw_chi2(&place(root, CHI2), self.outcome, range)?;
        emissivity::draw_map(&place(root, MAP), self.grid, &self.model.wavelength_um)?;
        summary::draw_summary(&place(root, TABLE), self.outcome, self.model)?;
        root.present()
    }

    fn encode_svg(&self, path: &Path) -> Result<String, ReportError> {
        let mut text = String::new();
        {
            let root = SVGBackend::with_string(&mut text, SPECTRAL_REPORT_SIZE).into_drawing_area();
            self.draw(&root).map_err(|e| draw_error(path, &e))?;
        }
        Ok(text)
    }

    /// The title line and, below it, what the figure holds and where the per-wavelength fits are.
    fn draw_header<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult<DB> {
        let material = &self.outcome.material;
        let (first, last) = self.model.range_um();
        let points: usize = self
            .outcome
            .measurements
            .iter()
            .map(|s| s.points.len())
            .sum();
        let title = format!(
            "Spectral fit report: {}   —   {} slopes, {} shadowing, {} wavelengths {}–{} µm, \
             {} points, dispersion: {}",
            material.name,
            self.model.distribution.name(),
            self.model.shadowing.name(),
            self.model.wavelength_um.len(),
            number(first),
            number(last),
            points,
            self.outcome.chosen.dispersion,
        );
        super::draw_title(root, &title, material)?;
        let note = format!(
            "σ and q shared by every wavelength; n, k, ρd per wavelength. The fit at each \
             wavelength, against its measurement: {}/<λ>um.png",
            material.name
        );
        let style = (FONT, LEGEND_SIZE + 2)
            .into_font()
            .color(&RGBColor(70, 70, 70))
            .pos(Pos::new(HPos::Left, VPos::Top));
        root.draw_text(&note, &style, (28, 62))
    }
}

/// The area of a panel placed at (x, y, width, height).
fn place<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    (x, y, width, height): (i32, i32, i32, i32),
) -> DrawingArea<DB, Shift> {
    root.clone()
        .shrink((x, y), (width.max(1) as u32, height.max(1) as u32))
}

/// The wavelength axis of the line panels: the table's range with a margin for the end points.
fn x_range(model: &SpectralModel) -> (f64, f64) {
    let (first, last) = model.range_um();
    let margin = 0.04 * (last - first).max(1e-3);
    (first - margin, last + margin)
}
