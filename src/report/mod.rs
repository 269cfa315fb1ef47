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
