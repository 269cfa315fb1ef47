//! Pictures: the paper's model figures, and (with the fitting module) fit reports and the library
//! index. Fonts, palette and PNG encoding are [`crate::plot_style`]'s.

pub mod fit_report;
pub mod index;
pub mod paper_figures;
pub mod spectral_report;

#[derive(Debug, thiserror::Error)]
pub enum ReportError {
    #[error("{path}: cannot draw the figure: {message}")]
    Draw {
        path: std::path::PathBuf,
        message: String,
    },
    #[error("{path}: cannot write")]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Model(#[from] crate::pbrdf::ModelError),
    #[error(transparent)]
    Material(#[from] crate::material::MaterialError),
    #[error(transparent)]
    Measure(#[from] crate::measure::MeasureError),
    #[error(transparent)]
    Fit(#[from] crate::fit::FitError),
    #[error("{material}: a spectral material's report is written by `irpol fit`; run it again on its measurements ({csv}, with the same options) to rebuild it", csv = crate::text::path(csv))]
    SpectralRebuild {
        material: std::path::PathBuf,
        csv: std::path::PathBuf,
    },
    #[error("{material}: the material has no fit record, so there is no measurement to report against (fit it with `irpol fit`)")]
    NoFit { material: std::path::PathBuf },
    #[error("{material}: its source CSV {csv} is missing (looked for {tried})")]
    SourceMissing {
        material: std::path::PathBuf,
        csv: std::path::PathBuf,
        tried: String,
    },
    #[error("{material}: the layout {layout} its fit read the source through is missing (looked for {tried})")]
    LayoutMissing {
        material: std::path::PathBuf,
        layout: std::path::PathBuf,
        tried: String,
    },
    #[error("{csv}: source CSV changed since the fit: its bytes are not those of sha256 {recorded} recorded in {material}, which records no fingerprint of the data to compare (written before irpol kept one); refit it with `irpol fit`")]
    SourceChanged {
        csv: std::path::PathBuf,
        recorded: String,
        material: std::path::PathBuf,
    },
    #[error("{csv}: the data changed since the fit recorded in {material}: {what}; refit it with `irpol fit`")]
    SourceDataChanged {
        csv: std::path::PathBuf,
        what: String,
        material: std::path::PathBuf,
    },
    #[error("material name '{name}' cannot name a report file: it must be a plain file name without folders")]
    MaterialName { name: String },
}

/// A report's title line at the top left, and beside it, in red, the mark of a fit that does
/// not describe its data ([`crate::material::FitRecord::misfit`]).
fn draw_title<DB: plotters::prelude::DrawingBackend>(
    root: &plotters::prelude::DrawingArea<DB, plotters::coord::Shift>,
    title: &str,
    material: &crate::material::Material,
) -> fit_report::style::DrawResult<DB> {
    use plotters::prelude::*;
    use plotters::style::text_anchor::{HPos, Pos, VPos};
    let style = |size: i32, color: &RGBColor| {
        (crate::plot_style::FONT, size, FontStyle::Bold)
            .into_font()
            .color(color)
            .pos(Pos::new(HPos::Left, VPos::Top))
    };
    let size = fit_report::style::TITLE_SIZE;
    root.draw_text(title, &style(size, &BLACK).into_text_style(root), (24, 14))?;
    let misfit = material
        .fit
        .as_ref()
        .map(|f| f.misfit())
        .unwrap_or_default();
    if misfit.is_empty() {
        return Ok(());
    }
    let (width, _) = root.estimate_text_size(title, &style(size, &BLACK).into_text_style(root))?;
    let mark = format!("   —   DOES NOT DESCRIBE ITS DATA: {}", misfit.join(", "));
    // As large as the rest of the line allows, down to 14 pt.
    let room = root.dim_in_pixel().0.saturating_sub(48 + width);
    let mut mark_size = size;
    while mark_size > 14
        && root
            .estimate_text_size(&mark, &style(mark_size, &BLACK).into_text_style(root))?
            .0
            > room
    {
        mark_size -= 2;
    }
    let red = RGBColor(200, 0, 0);
    let at = (24 + width as i32, 14 + (size - mark_size) / 2);
    root.draw_text(&mark, &style(mark_size, &red).into_text_style(root), at)
}
