//! The page of `irpol validate` (docs/design.md §4): how a material's model predicts a
//! measurement it was not fitted to, drawn with the fit report's own panels (the in-plane m00,
//! the linear block, the residual map and its histogram) under a title naming both and a line of
//! the prediction errors.

use super::data::ReportData;
use super::style::incidence_color;
use super::table::format_angle;
use super::{draw_panel, encode_bitmap, report_stem, EncodedReport, PanelKind};
use crate::material::Material;
use crate::measure::MeasurementSet;
use crate::plot_style::{register_fonts, FONT};
use crate::report::ReportError;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use plotters::style::FontStyle;
use std::path::Path;

/// Size of the validation page, pixels.
const PAGE: (u32, u32) = (2400, 1560);
/// Height of the title block, pixels.
const TITLE_BLOCK: u32 = 110;

/// Where the key of the incidences' colours starts on the summary line, pixels from the left
/// (the page has no ring panel, whose legend keys them in the fit report).
const KEY_LEFT: i32 = 1560;

/// "θ_i:" and each incidence angle in the colour its points and curves have in every panel.
fn draw_incidence_key<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    data: &ReportData,
    (mut x, y): (i32, i32),
) -> Result<(), DrawingAreaErrorKind<DB::ErrorType>> {
    let font = |color: RGBColor| {
        (FONT, 26.0)
            .into_font()
            .color(&color)
            .pos(Pos::new(HPos::Left, VPos::Top))
    };
    area.draw_text("colours: θi =", &font(BLACK), (x, y))?;
    x += 175;
    for (incidence, slot) in data.incidences.iter().zip(&data.slot) {
        let Some(slot) = slot else { continue };
        let label = format!("● {}°", format_angle(*incidence));
        area.draw_text(&label, &font(incidence_color(*slot)), (x, y))?;
        x += 20 + 16 * label.chars().count() as i32;
    }
    Ok(())
}

/// The data part of a validation page's name: the file stem of `set`'s source, and
/// `_<λ>um` when that file gave several sets (one per wavelength: a spectral CSV or a Mitsuba
/// table), so that their pages do not overwrite each other.
pub fn validation_data_name(set: &MeasurementSet, sets_of_file: usize) -> String {
    let stem = set
        .source
        .file_stem()
        .map_or_else(|| "data".into(), |s| s.to_string_lossy().into_owned());
    match sets_of_file {
        0 | 1 => stem,
        _ => format!("{stem}_{}um", set.wavelength_um),
    }
}

/// Encodes `<out_dir>/<material>_validation_<data name>.png`; `summary` is the line of errors
/// printed under the title; `data_name` is the data file's stem, with the wavelength when the
/// file holds several ([`validation_data_name`]).
pub fn encode_validation_report(
    material: &Material,
    set: &MeasurementSet,
    summary: &str,
    out_dir: &Path,
    data_stem: &str,
) -> Result<EncodedReport, ReportError> {
    let stem = report_stem(&material.name)?;
    let png = out_dir.join(format!("{stem}_validation_{data_stem}.png"));
    let data = ReportData::new(material, set)?;
    let title = format!(
        "Validation: {} predicting {} ({} rows × {} Mueller elements, λ = {} µm)",
        material.name,
        set.source.display(),
        set.points.len(),
        set.elements.len(),
        set.wavelength_um
    );
    let bytes = encode_bitmap(&png, PAGE, |root| {
        register_fonts();
        root.fill(&WHITE)?;
        let (header, body) = root.split_vertically(TITLE_BLOCK);
        let style = |size: f64, bold: bool| {
            let font = if bold {
                (FONT, size, FontStyle::Bold)
            } else {
                (FONT, size, FontStyle::Normal)
            };
            font.into_font()
                .color(&BLACK)
                .pos(Pos::new(HPos::Left, VPos::Top))
        };
        header.draw_text(
            &title,
            &style(34.0, true).into_text_style(&header),
            (24, 14),
        )?;
        header.draw_text(
            summary,
            &style(26.0, false).into_text_style(&header),
            (24, 62),
        )?;
        draw_incidence_key(&header, &data, (KEY_LEFT, 62))?;
        let panels = body.split_evenly((2, 2));
        let kinds = [
            PanelKind::InPlane,
            PanelKind::LinearBlock,
            PanelKind::Residuals,
            PanelKind::Histogram,
        ];
        for (area, kind) in panels.iter().zip(kinds) {
            draw_panel(kind, area, material, &data, true)?;
        }
        root.present()
    })?;
    Ok(EncodedReport {
        files: vec![(png, bytes)],
    })
}
