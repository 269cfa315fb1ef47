//! Pictures: the paper's model figures, and (with the fitting module) fit reports and the library
//! index. Plot text uses the DejaVu Sans font embedded in the binary, so figures render on a machine
//! without any system fonts.

pub mod fit_report;
pub mod index;
pub mod paper_figures;
pub mod spectral_report;

use std::sync::Once;

/// Font family name under which the embedded DejaVu Sans is registered with plotters.
pub const FONT: &str = "sans-serif";

/// Registers the embedded fonts with plotters once per process.
pub fn register_fonts() {
    static REGISTER: Once = Once::new();
    REGISTER.call_once(|| {
        use plotters::style::FontStyle;
        // DejaVu ships valid TrueType data; a failure here would be a build defect, not user input.
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular())
            .unwrap_or_else(|_| panic!("embedded DejaVu Sans font is invalid"));
        plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold())
            .unwrap_or_else(|_| panic!("embedded DejaVu Sans Bold font is invalid"));
    });
}

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
    #[error("{material}: a spectral material's report is written by `irpol fit`; run it again on its measurements ({csv}, with the same options) to rebuild it", csv = .csv.display())]
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

/// Tableau 20: the ten Tableau 10 colours (readable on white and in grey print), then their light
/// companions. Series colours of every plot.
pub const TABLEAU20: [plotters::style::RGBColor; 20] = {
    use plotters::style::RGBColor as C;
    [
        C(31, 119, 180),
        C(255, 127, 14),
        C(44, 160, 44),
        C(214, 39, 40),
        C(148, 103, 189),
        C(140, 86, 75),
        C(227, 119, 194),
        C(127, 127, 127),
        C(188, 189, 34),
        C(23, 190, 207),
        C(174, 199, 232),
        C(255, 187, 120),
        C(152, 223, 138),
        C(255, 152, 150),
        C(197, 176, 213),
        C(196, 156, 148),
        C(247, 182, 210),
        C(199, 199, 199),
        C(219, 219, 141),
        C(158, 218, 229),
    ]
};
