//! Fit reports (docs/design.md §4, `irpol fit … --reports`, `irpol report`): one 3000 × 1800 figure per
//! material, as PNG and SVG, that a researcher can put in a paper, and each panel as its own PNG
//! (`<material>/<panel>.png`). It recomputes every model curve
//! from the material's pBRDF, so the same (material, measurement) always gives the same figure.
//!
//! Panels: (a) m00 in the plane of incidence, (b) m00 on the out-of-plane rings, (c) the
//! parameter table, (d) the linear-polarization block normalized by m00, (e) the DoLP for
//! unpolarized illumination, (f) the polarized emissivity, (g) normalized residuals, (h) their
//! histogram, (i) the optimizer's convergence, (j) the parameters' correlation matrix. The competing distribution's best fit is dashed.

mod correlation;
mod data;
mod diagnostics;
mod profile_panels;
mod profiles;
mod residuals;
mod source;
pub(crate) mod style;
mod table;
#[cfg(test)]
mod test_records;
mod validation;

pub use source::rebuild_report;
pub(crate) use source::source_unchanged;
use table::format_angle;
pub(crate) use table::{
    fitted_cells, format_plain, format_with_uncertainty, is_free, parameters, preference,
    sha_prefix, FOOTNOTE_BOUND, FOOTNOTE_PROFILE,
};
pub use validation::encode_validation_report;

use super::ReportError;
use crate::atomic::write_atomically;
use crate::material::Material;
use crate::measure::MeasurementSet;
use crate::plot_style::{encode_png, register_fonts};
use data::ReportData;
use plotters::coord::Shift;
use plotters::prelude::*;
use profile_panels::{draw_dolp, draw_in_plane_m00, draw_linear_block, draw_rings_m00};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use style::{draw_legend_row, incidence_color, DrawResult, LegendEntry, LineKind, Marker};

/// Pixel size of the report figure: five columns of panels in three rows.
pub const REPORT_SIZE: (u32, u32) = (3000, 1800);
const HEADER_HEIGHT: i32 = 100;
const COLUMN_WIDTH: i32 = 600;

/// A fit report encoded in memory, not yet written: the PNG and SVG files and their bytes, the
/// composite figure's PNG first.
pub struct EncodedReport {
    pub files: Vec<(PathBuf, Vec<u8>)>,
}

/// The panels: what each draws, its file name and its place in the grid (column, row, columns
/// spanned).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PanelKind {
    InPlane,
    Rings,
    Table,
    LinearBlock,
    Dolp,
    Emissivity,
    Correlation,
    Residuals,
    Histogram,
    Convergence,
}

pub struct PanelSpec {
    pub kind: PanelKind,
    /// The panel's own file, `<material>/<name>.png`.
    pub name: &'static str,
    pub column: i32,
    pub row: i32,
    pub span: i32,
}

pub const PANELS: [PanelSpec; 10] = {
    use PanelKind::*;
    const fn at(
        kind: PanelKind,
        name: &'static str,
        column: i32,
        row: i32,
        span: i32,
    ) -> PanelSpec {
        PanelSpec {
            kind,
            name,
            column,
            row,
            span,
        }
    }
    [
        at(InPlane, "a_in_plane_m00", 0, 0, 2),
        at(Rings, "b_rings_m00", 2, 0, 1),
        at(Table, "c_parameters", 3, 0, 2),
        at(LinearBlock, "d_linear_block", 0, 1, 2),
        at(Dolp, "e_dolp", 2, 1, 1),
        at(Emissivity, "f_emissivity", 3, 1, 1),
        at(Correlation, "j_correlation", 4, 1, 1),
        at(Residuals, "g_residuals", 0, 2, 3),
        at(Histogram, "h_residual_histogram", 3, 2, 1),
        at(Convergence, "i_convergence", 4, 2, 1),
    ]
};

/// Writes `<out_dir>/<material>.png` and `.svg` and each panel as `<out_dir>/<material>/<panel>.png`
/// (each file atomically); returns their paths.
pub fn write_fit_report(
    material: &Material,
    set: &MeasurementSet,
    out_dir: &Path,
) -> Result<Vec<PathBuf>, ReportError> {
    let report = encode_fit_report(material, set, out_dir)?;
    for (path, bytes) in &report.files {
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir).map_err(|source| ReportError::Write {
                path: dir.to_owned(),
                source,
            })?;
        }
        write_atomically(path, bytes).map_err(|source| ReportError::Write {
            path: path.clone(),
            source,
        })?;
    }
    Ok(report.files.into_iter().map(|(path, _)| path).collect())
}

/// Draws the report of `material` against `set` as `<out_dir>/<material>.png` and `.svg` and
/// its panels as `<out_dir>/<material>/<panel>.png`, in memory, so that a caller writing several
/// outputs can write none of them if one fails.
pub fn encode_fit_report(
    material: &Material,
    set: &MeasurementSet,
    out_dir: &Path,
) -> Result<EncodedReport, ReportError> {
    let stem = report_stem(&material.name)?;
    let png = out_dir.join(format!("{stem}.png"));
    let svg = out_dir.join(format!("{stem}.svg"));
    let data = ReportData::new(material, set)?;
    let (width, height) = REPORT_SIZE;
    // The figure, its SVG and the panels are independent drawings: encoded in parallel (PNG
    // compression dominates the report's time).
    let ((png_bytes, svg_text), panels) = rayon::join(
        || {
            rayon::join(
                || {
                    encode_bitmap(&png, (width, height), |root| {
                        draw_report(root, material, set, &data, false)
                    })
                },
                || encode_svg(&svg, (width, height), material, set, &data),
            )
        },
        || {
            PANELS
                .par_iter()
                .map(|spec| {
                    let path = out_dir.join(stem).join(format!("{}.png", spec.name));
                    let bytes = encode_bitmap(&path, panel_size(spec), |root| {
                        register_fonts();
                        root.fill(&WHITE)?;
                        draw_panel(spec.kind, root, material, &data, false)?;
                        root.present()
                    })?;
                    Ok((path, bytes))
                })
                .collect::<Result<Vec<_>, ReportError>>()
        },
    );
    let mut files = vec![(png, png_bytes?), (svg, svg_text?.into_bytes())];
    files.extend(panels?);
    Ok(EncodedReport { files })
}

/// The composite figure alone, as PNG bytes for `path` (no SVG, no panel files): for callers
/// drawing many figures, such as the spectral report's one per wavelength.
pub(crate) fn encode_fit_figure(
    material: &Material,
    set: &MeasurementSet,
    path: &Path,
) -> Result<Vec<u8>, ReportError> {
    let data = ReportData::new(material, set)?;
    encode_bitmap(path, REPORT_SIZE, |root| {
        draw_report(root, material, set, &data, false)
    })
}

/// The figure as SVG text.
fn encode_svg(
    path: &Path,
    size: (u32, u32),
    material: &Material,
    set: &MeasurementSet,
    data: &ReportData,
) -> Result<String, ReportError> {
    let mut svg_text = String::new();
    {
        let root = SVGBackend::with_string(&mut svg_text, size).into_drawing_area();
        draw_report(&root, material, set, data, true).map_err(|e| draw_error(path, &e))?;
    }
    // plotters labels embedded PNGs `data:png`, which is no media type; viewers want image/png.
    // (Text is escaped, so the attribute cannot occur in the figure's text.)
    Ok(svg_text.replace("href=\"data:png;base64,", "href=\"data:image/png;base64,"))
}

pub(crate) fn draw_error(path: &Path, e: &dyn std::fmt::Display) -> ReportError {
    ReportError::Draw {
        path: path.to_owned(),
        message: e.to_string(),
    }
}

/// Draws into an RGB bitmap of `size` and encodes it as PNG bytes for `path`.
pub(crate) fn encode_bitmap(
    path: &Path,
    (width, height): (u32, u32),
    draw: impl for<'a> FnOnce(&DrawingArea<BitMapBackend<'a>, Shift>) -> DrawResult<BitMapBackend<'a>>,
) -> Result<Vec<u8>, ReportError> {
    let mut rgb = vec![0u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (width, height)).into_drawing_area();
        draw(&root).map_err(|e| draw_error(path, &e))?;
    }
    encode_png(&rgb, width, height).map_err(|e| draw_error(path, &e))
}

/// The material name as a file stem: a plain name, no folders.
pub(crate) fn report_stem(name: &str) -> Result<&str, ReportError> {
    let plain = !name.is_empty()
        && name != "."
        && name != ".."
        && !name.contains(['/', '\\', '\0'])
        && !name.starts_with('.');
    if plain {
        Ok(name)
    } else {
        Err(ReportError::MaterialName {
            name: name.to_owned(),
        })
    }
}

/// Height of a row of panels.
const ROW_HEIGHT: i32 = (REPORT_SIZE.1 as i32 - HEADER_HEIGHT) / 3;

/// Pixel size of a panel, in the figure and as its own file.
pub fn panel_size(spec: &PanelSpec) -> (u32, u32) {
    ((spec.span * COLUMN_WIDTH) as u32, ROW_HEIGHT as u32)
}

/// The area of `spec` in the figure.
fn panel<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    spec: &PanelSpec,
) -> DrawingArea<DB, Shift> {
    let (width, height) = panel_size(spec);
    root.clone().shrink(
        (
            spec.column * COLUMN_WIDTH,
            HEADER_HEIGHT + spec.row * ROW_HEIGHT,
        ),
        (width, height),
    )
}

/// Draws one panel into `area`; `raster` (a vector figure) embeds dense scatter as an image.
fn draw_panel<DB: DrawingBackend>(
    kind: PanelKind,
    area: &DrawingArea<DB, Shift>,
    material: &Material,
    data: &ReportData,
    raster: bool,
) -> DrawResult<DB> {
    match kind {
        PanelKind::InPlane => draw_in_plane_m00(area, data),
        PanelKind::Rings => draw_rings_m00(area, data),
        PanelKind::Table => table::draw_table(area, material),
        PanelKind::LinearBlock => draw_linear_block(area, data),
        PanelKind::Dolp => draw_dolp(area, data),
        PanelKind::Emissivity => diagnostics::draw_emissivity(area, data),
        PanelKind::Correlation => correlation::draw_correlation(area, material.fit.as_ref()),
        PanelKind::Residuals => residuals::draw_residuals(area, data, raster),
        PanelKind::Histogram => diagnostics::draw_histogram(area, data),
        PanelKind::Convergence => diagnostics::draw_convergence(area, material.fit.as_ref()),
    }
}

fn draw_report<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    material: &Material,
    set: &MeasurementSet,
    data: &ReportData,
    raster: bool,
) -> DrawResult<DB> {
    register_fonts();
    root.fill(&WHITE)?;
    draw_header(root, material, set, data)?;
    for spec in &PANELS {
        draw_panel(spec.kind, &panel(root, spec), material, data, raster)?;
    }
    root.present()
}

/// Title line and the colour/line key shared by every data panel.
fn draw_header<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    material: &Material,
    set: &MeasurementSet,
    data: &ReportData,
) -> DrawResult<DB> {
    let model = &material.model;
    let title = format!(
        "Fit report: {}   —   {} slopes, {} shadowing, λ = {} µm, {} points × {} Mueller elements",
        material.name,
        model.distribution().name(),
        model.shadowing().name(),
        format_plain(set.wavelength_um),
        set.points.len(),
        set.elements.len(),
    );
    super::draw_title(root, &title, material)?;
    let mut legend = header_legend(data);
    if let Ok(spec) = material.grey_model() {
        legend.extend(critical_angle_note(spec).map(LegendEntry::text));
    }
    draw_legend_row(root, &legend, (28, 72))
}

/// Why the model's curves kink where they do, for a model with internal facets or the
/// subsurface term: light inside the material is totally reflected beyond the critical angle
/// asin(1/n) (facets) and asin(1/n_sub) (the subsurface term's interface), and the Fresnel
/// terms have a branch point there (docs/measurements.md, the PTFE fit).
fn critical_angle_note(spec: &crate::material::ModelSpec) -> Option<String> {
    let terms = spec.terms();
    let internal = terms.facet_side == crate::pbrdf::FacetSide::Internal;
    let indices: Vec<(&str, f64)> = [("n", Some(spec.n))]
        .into_iter()
        .filter(|_| internal || !spec.subsurface_lobes().is_empty())
        .chain(std::iter::once((
            "n_sub",
            spec.parameter(crate::pbrdf::Parameter::NSub),
        )))
        .filter_map(|(name, n)| n.filter(|n| *n > 1.0).map(|n| (name, n)))
        .collect();
    if indices.is_empty() {
        return None;
    }
    let angles: Vec<String> = indices
        .iter()
        .map(|(name, n)| format!("asin(1/{name}) = {:.1}°", (1.0 / n).asin().to_degrees()))
        .collect();
    Some(format!(
        "kinks in the model curves: total internal reflection inside the material beyond {}",
        angles.join(" and ")
    ))
}

/// The key shared by every data panel: the colour of each incidence angle with curves, the
/// measured points' marker, and the chosen and competing fits' lines.
fn header_legend(data: &ReportData) -> Vec<LegendEntry> {
    let mut entries: Vec<LegendEntry> = data
        .shown
        .iter()
        .enumerate()
        .map(|(slot, &incidence)| {
            LegendEntry::marker(
                format!("θi = {}°", format_angle(data.incidences[incidence])),
                incidence_color(slot),
                Marker::FilledCircle,
            )
        })
        .collect();
    if data.shown.len() < data.incidences.len() {
        // Curves at a few angles spread over the range; every point is in (g) and (h).
        entries.push(LegendEntry::text(format!(
            "(curves at {} of {} incidence angles)",
            data.shown.len(),
            data.incidences.len()
        )));
    }
    entries.push(LegendEntry::marker(
        "measured ± 1σ",
        RGBColor(60, 60, 60),
        Marker::FilledCircle,
    ));
    entries.push(LegendEntry::line(
        format!("{} fit (chosen)", data.chosen_label),
        BLACK,
        LineKind::Solid,
    ));
    if let Some(alt) = &data.alternative_label {
        entries.push(LegendEntry::line(
            format!("{alt} fit (competing distribution)"),
            BLACK,
            LineKind::Dashed,
        ));
    }
    entries
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn report_files_are_named_by_a_plain_material_name() {
        assert_eq!(report_stem("gloss paint-2").unwrap(), "gloss paint-2");
        for bad in ["", ".", "..", "../etc", "a/b", "a\\b", ".hidden"] {
            let message = report_stem(bad).unwrap_err().to_string();
            assert!(message.contains("plain file name"), "{bad}: {message}");
        }
    }
}
