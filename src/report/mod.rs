//! Pictures: the paper's model figures, and (with the fitting module) fit reports and the library
//! index. Plot text uses the DejaVu Sans font embedded in the binary, so figures render on a machine
//! without any system fonts.

pub mod paper_figures;

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
    #[error("{path}: cannot write: {source}")]
    Write {
        path: std::path::PathBuf,
        source: std::io::Error,
    },
    #[error(transparent)]
    Model(#[from] crate::pbrdf::ModelError),
}
