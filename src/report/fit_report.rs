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
mod profiles;
pub(crate) mod style;
mod table;
#[cfg(test)]
mod test_records;
mod validation;

use table::format_angle;
pub(crate) use table::{
    fitted_cells, format_plain, format_with_uncertainty, is_free, parameters, preference,
    sha_prefix, FOOTNOTE_BOUND, FOOTNOTE_PROFILE,
};
pub use validation::encode_validation_report;

use super::ReportError;
use crate::atomic::write_atomically;
use crate::fit::FitError;
use crate::material::{FitRecord, Material};
use crate::measure::{
    hex, merge_repeat_measurements, parse_measurement_csv, Layout, MeasureError, MeasureErrorKind,
    MeasurementSet, ReadOptions, SourceData, LAYOUT_KEY,
};
use crate::plot_style::{encode_png, register_fonts, FONT};
use data::ReportData;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use profiles::{
    draw_profile, linear_axis, log_axis, profile_series, Domain, Profile, Quantity, BIN_DEGREES,
};
use rayon::prelude::*;
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};
use style::{
    draw_caption, draw_legend_column, draw_legend_row, draw_note, incidence_color, DrawResult,
    LegendEntry, LineKind, Marker, YAxis,
};

/// Pixel size of the report figure: five columns of panels in three rows.
pub const REPORT_SIZE: (u32, u32) = (3000, 1800);
const HEADER_HEIGHT: i32 = 100;
const COLUMN_WIDTH: i32 = 600;

/// The linear-polarization elements of panel (d), in reading order.
const LINEAR_BLOCK: [usize; 8] = [1, 2, 4, 5, 6, 8, 9, 10];
/// Elements that vanish in the plane of incidence by mirror symmetry (m02, m12, m20, m21): drawn
/// on the rings, where they carry information.
const ZERO_IN_PLANE: [usize; 4] = [2, 6, 8, 9];

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

/// Rebuilds the report of a library entry from its recorded source CSVs (`irpol report
/// <material.toml>`; several when the fit merged repeat measurements), refusing when the
/// material has no fit, a CSV is gone or changed since the fit, or no longer reads.
pub fn rebuild_report(
    material_path: &Path,
    reports_dir: &Path,
) -> Result<Vec<PathBuf>, ReportError> {
    let material = Material::load(material_path)?;
    let fit = material.fit.as_ref().ok_or_else(|| ReportError::NoFit {
        material: material_path.to_owned(),
    })?;
    // A spectral report shows the joint fit's per-wavelength state, which the entry does not
    // hold: `irpol fit` (deterministic) writes it.
    if material.model.spectral().is_some() {
        return Err(ReportError::SpectralRebuild {
            material: material_path.to_owned(),
            csv: fit.source.clone(),
        });
    }
    let sets = verified_source(material_path, fit)?;
    let set = merge_repeat_measurements(sets)
        .map_err(crate::fit::FitError::from)?
        .ok_or_else(|| ReportError::NoFit {
            material: material_path.to_owned(),
        })?;
    write_fit_report(&material, &set, reports_dir)
}

/// Where the fit's source CSV may be: as recorded (relative to the working directory, where
/// `irpol fit` was run), then relative to the library's parent folder (`fits/x.toml` →
/// `<project>/…`), so that a project can be rebuilt from another directory.
fn source_candidates(material_path: &Path, source: &Path) -> Vec<PathBuf> {
    let mut candidates = vec![source.to_owned()];
    if source.is_relative() {
        if let Some(project) = material_path.parent().and_then(Path::parent) {
            let beside = project.join(source);
            if !candidates.contains(&beside) {
                candidates.push(beside);
            }
        }
    }
    candidates
}

/// Finds each of the fit's source CSVs (the source, then any merged with it) and checks it holds
/// the data that was fitted; returns each one's parsed data, in that order, read as the fit read
/// it (through the recorded layout, the recorded rows only).
pub(crate) fn verified_source(
    material_path: &Path,
    fit: &FitRecord,
) -> Result<Vec<MeasurementSet>, ReportError> {
    let reading = recorded_reading(material_path, fit)?;
    let one_set = |csv: &Path, bytes: &[u8]| parse_source(csv, bytes, &reading).map(|s| vec![s]);
    Ok(verified_files(material_path, fit, one_set)?
        .into_iter()
        .flatten()
        .collect())
}

/// [`verified_source`] of a spectral material: its files may hold several wavelengths each (a
/// `wavelength_um` column), all of which it keeps; returns every set of every file, read as the
/// fit read them.
pub(crate) fn verified_spectral_source(
    material_path: &Path,
    fit: &FitRecord,
) -> Result<Vec<MeasurementSet>, ReportError> {
    let reading = recorded_reading(material_path, fit)?;
    let every_set = |csv: &Path, bytes: &[u8]| -> Result<Vec<MeasurementSet>, ReportError> {
        Ok(reading.parse(csv, bytes).map_err(FitError::from)?)
    };
    Ok(verified_files(material_path, fit, every_set)?
        .into_iter()
        .flatten()
        .collect())
}

/// How the fit read its files: the recorded layout and row selection.
fn recorded_reading(material_path: &Path, fit: &FitRecord) -> Result<ReadOptions, ReportError> {
    Ok(ReadOptions {
        layout: recorded_layout(material_path, fit)?,
        selection: fit.selection.clone().unwrap_or_default(),
        angles: fit.angles.unwrap_or_default(),
    })
}

/// Each of the fit's source files checked by [`verified_file`], read with `parse`.
fn verified_files(
    material_path: &Path,
    fit: &FitRecord,
    parse: impl Fn(&Path, &[u8]) -> Result<Vec<MeasurementSet>, ReportError>,
) -> Result<Vec<Vec<MeasurementSet>>, ReportError> {
    std::iter::once((&fit.source, &fit.source_sha256, &fit.source_data))
        .chain(
            fit.merged_sources
                .iter()
                .map(|m| (&m.source, &m.source_sha256, &m.source_data)),
        )
        .map(|(source, sha256, data)| {
            verified_file(material_path, source, sha256, data.as_ref(), &parse)
        })
        .collect()
}

/// The layout the fit was given, found where its sources are looked for.
fn recorded_layout(material_path: &Path, fit: &FitRecord) -> Result<Option<Layout>, ReportError> {
    let Some(layout) = &fit.layout else {
        return Ok(None);
    };
    let candidates = source_candidates(material_path, layout);
    match candidates.iter().find(|p| p.is_file()) {
        Some(path) => Ok(Some(Layout::read(path)?)),
        None => Err(ReportError::LayoutMissing {
            material: material_path.to_owned(),
            layout: layout.clone(),
            tried: candidates
                .iter()
                .map(|p| p.display().to_string())
                .collect::<Vec<_>>()
                .join(", "),
        }),
    }
}

/// The one set a source holds once read as the fit read it; a file of several wavelengths
/// without a recorded wavelength is refused by the one-wavelength reader's own message when it
/// is a docs/design.md §2.1 file.
fn parse_source(
    csv: &Path,
    bytes: &[u8],
    reading: &ReadOptions,
) -> Result<MeasurementSet, ReportError> {
    let mut sets = reading.parse(csv, bytes).map_err(FitError::from)?;
    if sets.len() == 1 {
        return Ok(sets.remove(0));
    }
    if reading.layout.is_none() && !sets.iter().any(|s| s.metadata.contains_key(LAYOUT_KEY)) {
        parse_measurement_csv(csv, bytes)?;
    }
    let wavelengths: Vec<String> = sets.iter().map(|s| s.wavelength_um.to_string()).collect();
    Err(FitError::Measurement {
        file: csv.to_owned(),
        message: format!(
            "holds {} wavelengths ({} µm) and the fit record selects none of them",
            sets.len(),
            wavelengths.join(", ")
        ),
    }
    .into())
}

/// One source CSV, checked against its recorded hash and data fingerprint. The bytes may differ
/// (a comment, blank lines, number spelling) when the record has the data's fingerprint and the
/// parsed data match it; a record without one (written before fingerprints, or by a spectral
/// fit) needs the very bytes. Of several candidates the first that matches wins (a same-named
/// file elsewhere is not the source); if none does, the first existing one is reported changed.
fn verified_file(
    material_path: &Path,
    source: &Path,
    recorded_sha256: &str,
    recorded_data: Option<&SourceData>,
    parse: &impl Fn(&Path, &[u8]) -> Result<Vec<MeasurementSet>, ReportError>,
) -> Result<Vec<MeasurementSet>, ReportError> {
    let candidates = source_candidates(material_path, source);
    let mut first_changed = None;
    for csv in candidates.iter().filter(|p| p.is_file()) {
        let bytes = std::fs::read(csv).map_err(|e| MeasureError {
            file: csv.clone(),
            line: 1,
            column: 1,
            kind: MeasureErrorKind::Unreadable {
                reason: e.to_string(),
            },
        })?;
        let same_bytes = hex(&Sha256::digest(&bytes)).eq_ignore_ascii_case(recorded_sha256.trim());
        let error = match (recorded_data, same_bytes) {
            (_, true) => return parse(csv, &bytes),
            (Some(recorded), false) => {
                let sets = parse(csv, &bytes)?;
                // A fingerprint is recorded for a file of one wavelength only: of several sets
                // (a hand-edited record) only the very bytes would do.
                let [set] = sets.as_slice() else {
                    first_changed.get_or_insert(ReportError::SourceChanged {
                        csv: csv.clone(),
                        recorded: recorded_sha256.to_owned(),
                        material: material_path.to_owned(),
                    });
                    continue;
                };
                let now = set.source_data(recorded.rows_per_digest);
                if now.sha256 == recorded.sha256 {
                    return Ok(sets);
                }
                ReportError::SourceDataChanged {
                    csv: csv.clone(),
                    what: recorded.describe_change(&now),
                    material: material_path.to_owned(),
                }
            }
            (None, false) => ReportError::SourceChanged {
                csv: csv.clone(),
                recorded: recorded_sha256.to_owned(),
                material: material_path.to_owned(),
            },
        };
        first_changed.get_or_insert(error);
    }
    Err(first_changed.unwrap_or_else(|| ReportError::SourceMissing {
        material: material_path.to_owned(),
        csv: source.to_owned(),
        tried: candidates
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", "),
    }))
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
        PanelKind::Residuals => diagnostics::draw_residuals(area, data, raster),
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
        .filter(|_| internal || spec.rho_s.is_some())
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

/// Panel (a): m00 against the signed detector zenith in the plane of incidence.
fn draw_in_plane_m00<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let caption = "(a) m00 in the plane of incidence";
    let (series, binned) = profile_series(data, Quantity::M00, Domain::InPlane);
    let Some(y) = log_axis(&series) else {
        return draw_note(area, caption, "no measurements in the plane of incidence");
    };
    draw_m00_profile(
        area,
        Domain::InPlane,
        &with_binning(caption, binned),
        "m00 = f00, BRDF (sr⁻¹)",
        y,
        series,
        binned,
    )
}

/// An m00 profile along `domain` on the log axis `y`: full-size text, error bars unless the
/// points are medians per bin.
fn draw_m00_profile<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    domain: Domain,
    caption: &str,
    y_desc: &str,
    y: YAxis,
    series: Vec<profiles::ProfileSeries>,
    binned: bool,
) -> DrawResult<DB> {
    draw_profile(
        area,
        &Profile {
            caption: caption.to_owned(),
            x_desc: domain.x_desc(false).into(),
            y_desc: y_desc.into(),
            x_axis: domain.axis(area.dim_in_pixel().0),
            y,
            series,
            error_bars: !binned,
            compact: false,
        },
    )
}

/// A profile panel's caption, saying when its points are medians per bin.
fn with_binning(caption: &str, binned: bool) -> String {
    if binned {
        format!("{caption} (median per {BIN_DEGREES}° bin)")
    } else {
        caption.to_owned()
    }
}

/// Width of the ring legend strip at the right of panel (b).
const RING_LEGEND_WIDTH: i32 = 150;
/// Rings listed in the legend before "+ N more".
const RING_LEGEND_ROWS: usize = 18;

/// Panel (b): m00 against φr − φi on each drawn ring, with the rings' key in a strip at the right.
fn draw_rings_m00<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let caption = "(b) m00 on out-of-plane rings";
    let (series, binned) = profile_series(data, Quantity::M00, Domain::Rings);
    let Some(y) = log_axis(&series) else {
        let note = match data.off_ring_points() {
            0 => "no out-of-plane measurements".to_owned(),
            1 => "no rings; the 1 off-plane point is in (g)".to_owned(),
            n => format!("no rings; {n} off-plane points (a raster) are in (g)"),
        };
        return draw_note(area, caption, &note);
    };
    let (width, _) = area.dim_in_pixel();
    let (chart_area, legend_area) = area.split_horizontally(width as i32 - RING_LEGEND_WIDTH);
    draw_m00_profile(
        &chart_area,
        Domain::Rings,
        &with_binning(caption, binned),
        "m00 (sr⁻¹)",
        y,
        series,
        binned,
    )?;
    draw_ring_legend(&legend_area, &ring_legend(data))
}

/// The rings' key: incidence angle → detector zenith of each ring listed (in its colour and
/// marker), then counts of the off-plane points the panel does not show.
fn ring_legend(data: &ReportData) -> Vec<LegendEntry> {
    let mut entries: Vec<LegendEntry> = data
        .rings
        .iter()
        .take(RING_LEGEND_ROWS)
        .map(|ring| {
            LegendEntry::marker(
                format!(
                    "{}° → {}°",
                    format_angle(data.incidences[ring.incidence]),
                    format_angle(ring.theta_r_deg)
                ),
                incidence_color(data.slot[ring.incidence].unwrap_or(0)),
                Marker::for_rank(ring.rank),
            )
        })
        .collect();
    if data.rings.len() > RING_LEGEND_ROWS {
        entries.push(LegendEntry::text(format!(
            "+ {} more",
            data.rings.len() - RING_LEGEND_ROWS
        )));
    }
    let off_ring = data.off_ring_points();
    if off_ring > 0 {
        // A raster around specular is not a ring; its points are among the residuals only.
        entries.push(LegendEntry::text(format!("{off_ring} raster pts")));
        entries.push(LegendEntry::text("only in (g)"));
    }
    if data.unshown_ring_points > 0 {
        // Rings beyond the drawn ones (other incidence angles, or more than MAX_RINGS).
        for line in [
            format!("{} pts on", data.unshown_ring_points),
            "other rings".to_owned(),
            "only in (g)".to_owned(),
        ] {
            entries.push(LegendEntry::text(line));
        }
    }
    entries
}

/// The ring key in its strip under a heading, moved up when it is too long for the panel.
fn draw_ring_legend<DB: DrawingBackend>(
    legend_area: &DrawingArea<DB, Shift>,
    entries: &[LegendEntry],
) -> DrawResult<DB> {
    let (_, height) = legend_area.dim_in_pixel();
    let heading = (FONT, style::LEGEND_SIZE)
        .into_font()
        .color(&BLACK)
        .pos(Pos::new(HPos::Left, VPos::Top));
    legend_area.draw_text("ring θi → θr", &heading, (4, 48))?;
    let rows = entries.len() as i32;
    let top = (48 + 24).min(height as i32 - rows * (style::LEGEND_SIZE + 7) - 10);
    draw_legend_column(legend_area, entries, (4, top))
}

/// Said by the profile panels when the geometry has neither an in-plane sweep nor a ring.
const NO_PROFILE_NOTE: &str = "no in-plane sweep or ring to draw along: see the residuals (g)";

/// Panel (d): m_ij/m00 for the linear-polarization elements present, as a grid of small plots.
fn draw_linear_block<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let caption = "(d) Linear-polarization block normalized by m00: data vs model";
    let elements: Vec<usize> = LINEAR_BLOCK
        .into_iter()
        .filter(|&e| data.has_element(e))
        .collect();
    if elements.is_empty() {
        return draw_note(
            area,
            caption,
            "only m00 was measured: no polarization elements to compare",
        );
    }
    let has_in_plane = data.in_plane.iter().any(Option::is_some);
    if !has_in_plane && data.rings.is_empty() {
        return draw_note(area, caption, NO_PROFILE_NOTE);
    }
    draw_caption(area, caption)?;
    let (width, _) = area.dim_in_pixel();
    let grid = area
        .clone()
        .shrink((0, 40), (width, area.dim_in_pixel().1 - 40));
    let columns = elements.len().min(4);
    let rows = elements.len().div_ceil(4);
    let cells = grid.split_evenly((rows, columns));
    for (cell, &element) in cells.iter().zip(&elements) {
        draw_ratio(cell, data, element, has_in_plane)?;
    }
    Ok(())
}

/// One small plot of panel (d): m_ij/m00 of `element` in the plane of incidence, or on the rings
/// when it vanishes in the plane by symmetry or the measurement has no in-plane sweep.
fn draw_ratio<DB: DrawingBackend>(
    cell: &DrawingArea<DB, Shift>,
    data: &ReportData,
    element: usize,
    has_in_plane: bool,
) -> DrawResult<DB> {
    let on_rings = !data.rings.is_empty() && (ZERO_IN_PLANE.contains(&element) || !has_in_plane);
    let domain = if on_rings {
        Domain::Rings
    } else {
        Domain::InPlane
    };
    let quantity = Quantity::Ratio(element);
    let (series, binned) = profile_series(data, quantity, domain);
    draw_profile(
        cell,
        &Profile {
            caption: format!(
                "{}{}{}",
                quantity.label(),
                if on_rings { " (rings)" } else { "" },
                if binned { ", medians" } else { "" }
            ),
            x_desc: domain.x_desc(true).into(),
            y_desc: String::new(),
            x_axis: domain.axis(cell.dim_in_pixel().0),
            y: linear_axis(&series, 1.5),
            series,
            error_bars: false,
            compact: true,
        },
    )
}

/// Panel (e): DoLP for unpolarized illumination, √(m10² + m20²)/m00 (docs/design.md §1.6).
fn draw_dolp<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    data: &ReportData,
) -> DrawResult<DB> {
    let measured = data.has_element(4) && data.has_element(8);
    let caption = if measured {
        "(e) DoLP, unpolarized illumination".to_owned()
    } else {
        "(e) DoLP, model only (m10, m20 not both measured)".to_owned()
    };
    let domain = if data.in_plane.iter().any(Option::is_some) {
        Domain::InPlane
    } else if !data.rings.is_empty() {
        Domain::Rings
    } else {
        return draw_note(area, &caption, NO_PROFILE_NOTE);
    };
    let (series, binned) = profile_series(data, Quantity::Dolp, domain);
    let caption = with_binning(&caption, binned);
    let y = match linear_axis(&series, 1.0) {
        YAxis::Linear { high, .. } => YAxis::Linear { low: 0.0, high },
        other => other,
    };
    draw_profile(
        area,
        &Profile {
            caption,
            x_desc: domain.x_desc(true).into(),
            y_desc: "DoLP = √(m10² + m20²)/m00".into(),
            x_axis: domain.axis(area.dim_in_pixel().0),
            y,
            series,
            error_bars: false,
            compact: false,
        },
    )
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

    #[test]
    fn the_source_is_looked_for_as_recorded_then_beside_the_library() {
        let fits = Path::new("/project/fits/paint.toml");
        assert_eq!(
            source_candidates(fits, Path::new("measurements/paint.csv")),
            [
                PathBuf::from("measurements/paint.csv"),
                PathBuf::from("/project/measurements/paint.csv")
            ]
        );
        assert_eq!(
            source_candidates(fits, Path::new("/data/paint.csv")),
            [PathBuf::from("/data/paint.csv")]
        );
        // fits/paint.toml relative to the working directory: both readings coincide.
        assert_eq!(
            source_candidates(Path::new("fits/paint.toml"), Path::new("m/p.csv")),
            [PathBuf::from("m/p.csv")]
        );
    }
}
