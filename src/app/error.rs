//! Why a subcommand failed: [`AppError`], the one error type of the application layer that the
//! command line and the Python bindings share. Library errors are wrapped as they are (their
//! message is the message); the application adds the context the library cannot know (which
//! file, which flag, which step) as a variant whose `source` is the library's error.
//!
//! Both front ends show an error as one line, its message followed by the message of each
//! `source` in turn, separated by `: ` ([`one_line`]; the CLI's `{error:#}` joins the chain the
//! same way). The texts are what `irpol` has always printed: tests and scripts match on them.

use crate::fit::{FitError, OptionError};
use crate::material::MaterialError;
use crate::measure::MeasureError;
use crate::output::figure::PreviewError;
use crate::pbrdf::ModelError;
use crate::render::RenderError;
use crate::report::ReportError;
use crate::scene::SceneError;
use crate::thermal_scene::ThermalRunError;
use std::error::Error;
use std::io;
use std::path::PathBuf;

/// The library's larger errors are boxed (their `From` below), so that a `Result<_, AppError>`
/// stays small on the success path.
#[derive(Debug, thiserror::Error)]
pub enum AppError {
    // --- library errors, as the library words them ---
    #[error(transparent)]
    Scene(Box<SceneError>),
    #[error(transparent)]
    Render(Box<RenderError>),
    #[error(transparent)]
    Material(#[from] MaterialError),
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A model chosen by `--material` or by parameter flags ([`super::ModelArgs`]).
    #[error(transparent)]
    ModelArgs(#[from] super::ModelArgsError),
    #[error(transparent)]
    Distribution(#[from] crate::pbrdf::DistributionError),
    #[error(transparent)]
    Measure(Box<MeasureError>),
    #[error(transparent)]
    Fit(Box<FitError>),
    /// Rows selected (`--wavelength`, `--theta-i`) that a file does not hold.
    #[error(transparent)]
    Selection(#[from] crate::measure::SelectionError),
    #[error(transparent)]
    FitOption(#[from] OptionError),
    #[error(transparent)]
    Report(Box<ReportError>),
    #[error(transparent)]
    Sun(#[from] crate::emitter::SunError),
    /// A weather file refused (`irpol weather`).
    #[error(transparent)]
    Weather(Box<crate::weather::WeatherError>),
    /// Writing a table to the output stream (stdout for the CLI); kept as the bare I/O error so
    /// that the CLI can tell a reader that went away (`irpol eval … | head`) from a failure.
    #[error(transparent)]
    Stream(#[from] io::Error),
    #[error(transparent)]
    Image(#[from] image::ImageError),

    // --- files the application reads or writes ---
    #[error("{}: cannot open", crate::text::path(path))]
    Open {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("{}: cannot read", crate::text::path(path))]
    Read {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("{}: cannot read", crate::text::path(path))]
    ReadImage {
        path: PathBuf,
        #[source]
        source: image::ImageError,
    },
    #[error("{}: cannot write", crate::text::path(path))]
    Write {
        path: PathBuf,
        #[source]
        source: io::Error,
    },
    /// The fit's library entries, reports and index could not be put in place together.
    #[error("{}: cannot write the fit's outputs", crate::text::path(dir))]
    WriteFit {
        dir: PathBuf,
        #[source]
        source: io::Error,
    },
    #[error("cannot write the CSV: {0}")]
    Csv(String),
    #[error("cannot draw the animated preview: {0}")]
    Caption(String),

    /// A fit refused by `--strict` because it does not describe its data.
    #[error("{0}; nothing written (--strict)")]
    Misfit(String),
    /// An error of a fit whose files' angles were read as `--angles` said: the readers' notes
    /// say how, since that may be the cause.
    #[error("{}; note: {notes}", one_line(error.as_ref()))]
    WithAngleNotes { error: Box<AppError>, notes: String },

    // --- input the application refuses ---
    /// A command-line argument (or the Python argument of the same name) that makes no sense.
    #[error("{0}")]
    Invalid(String),
    /// A geometry CSV of `irpol eval`, refused at its line and column.
    #[error(transparent)]
    Geometry(crate::table_text::TableError<crate::table_text::Problem>),
    /// A bad line of a `--times-file`, refused as every text table is (`path:line: why`).
    #[error(transparent)]
    TimesLine(crate::table_text::TableError<crate::emitter::SunError>),
    #[error(
        "{}: no times (expected one RFC 3339 instant per line, e.g. 2026-06-21T10:00:00Z)",
        crate::text::path(.0)
    )]
    NoTimes(PathBuf),
    #[error("--time-utc")]
    TimeFlag(#[source] crate::emitter::SunError),

    // --- thermal scenes ---
    #[error("{}: thermal run", crate::text::path(path))]
    ThermalRun {
        path: PathBuf,
        #[source]
        source: Box<ThermalRunError>,
    },
    #[error(
        "{}: has a [thermal] section: say when to render it with --time SECONDS, --time-utc \
         INSTANT or --times START:STOP:STEP (seconds from thermal.start_utc)",
        crate::text::path(.0)
    )]
    ThermalNeedsInstant(PathBuf),
    #[error(
        "{}: --time/--times need temperatures from the thermal model, but the scene has no \
         [thermal] section",
        crate::text::path(.0)
    )]
    InstantNeedsThermal(PathBuf),
    #[error("t = {} s is not an instant of the thermal run", crate::text::number(*.0))]
    NotAnInstant(f64),
    /// A saved thermal run that cannot be written, read or used for the scene.
    #[error(transparent)]
    SavedSolution(Box<crate::thermal_scene::SavedSolutionError>),
    /// The scene at an instant of its thermal run could not be built.
    #[error("{}: {message}", crate::text::path(path))]
    SceneAt { path: PathBuf, message: String },
}

/// `From` for the boxed library errors, so that `?` converts them as it does the others.
macro_rules! from_boxed {
    ($($variant:ident($error:ty)),* $(,)?) => {
        $(impl From<$error> for AppError {
            fn from(error: $error) -> AppError {
                AppError::$variant(Box::new(error))
            }
        })*
    };
}

from_boxed!(
    Scene(SceneError),
    Render(RenderError),
    Measure(MeasureError),
    Fit(FitError),
    Report(ReportError),
);

impl AppError {
    /// A refused argument.
    pub fn invalid(message: impl Into<String>) -> AppError {
        AppError::Invalid(message.into())
    }

    /// Whether a file or stream could not be read or written (the Python bindings raise
    /// `OSError`), as opposed to input that is wrong (`ValueError`): an [`io::Error`] among the
    /// causes, or a measurement path that is missing or unreadable (the measurement reader names
    /// the file and line where others keep the I/O error as a source).
    pub fn is_io(&self) -> bool {
        match self {
            AppError::Stream(_) => true,
            AppError::Image(image::ImageError::IoError(_)) => true,
            AppError::WithAngleNotes { error, .. } => error.is_io(),
            _ => {
                self.measure_error()
                    .is_some_and(MeasureError::is_unreadable_path)
                    || causes(self).any(|cause| cause.is::<io::Error>())
            }
        }
    }

    /// The reader of the output stream went away: not a failure of the command.
    pub fn is_broken_pipe(&self) -> bool {
        let broken = |e: &io::Error| e.kind() == io::ErrorKind::BrokenPipe;
        match self {
            AppError::Stream(e) => broken(e),
            _ => causes(self).any(|cause| cause.downcast_ref::<io::Error>().is_some_and(broken)),
        }
    }

    /// The measurement error inside, however it is wrapped (a wrapped error displays as its own
    /// message, so it does not appear among the causes).
    fn measure_error(&self) -> Option<&MeasureError> {
        fn in_fit(error: &FitError) -> Option<&MeasureError> {
            match error {
                FitError::Read(e) => Some(e),
                _ => None,
            }
        }
        match self {
            AppError::Measure(e) => Some(e),
            AppError::Fit(e) => in_fit(e),
            AppError::Report(e) => match &**e {
                ReportError::Measure(e) => Some(e),
                ReportError::Fit(e) => in_fit(e),
                _ => None,
            },
            _ => None,
        }
    }
}

impl From<crate::weather::WeatherError> for AppError {
    fn from(error: crate::weather::WeatherError) -> AppError {
        AppError::Weather(Box::new(error))
    }
}

impl From<crate::measure::ReadError> for AppError {
    fn from(error: crate::measure::ReadError) -> AppError {
        match error {
            crate::measure::ReadError::Measure(e) => e.into(),
            crate::measure::ReadError::Selection(e) => e.into(),
        }
    }
}

/// `error` and each of its sources in turn.
fn causes<'a>(error: &'a (dyn Error + 'static)) -> impl Iterator<Item = &'a (dyn Error + 'static)> {
    std::iter::successors(Some(error), |&e| e.source())
}

/// `error` as one line: its message and each source's, joined by `: ` (what the CLI prints after
/// `irpol: error: `).
pub fn one_line(error: &(dyn Error + 'static)) -> String {
    causes(error)
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(": ")
}

/// `message` on one line: runs of whitespace (line breaks of a parser's message) as one space.
pub(crate) fn single_line(message: &str) -> String {
    message.split_whitespace().collect::<Vec<_>>().join(" ")
}

impl From<PreviewError> for AppError {
    /// The animated preview's failures as the application has always reported them.
    fn from(error: PreviewError) -> AppError {
        match error {
            PreviewError::Caption(message) => AppError::Caption(message),
            PreviewError::CaptionBuffer => AppError::invalid(error.to_string()),
            PreviewError::Encode(source) => AppError::Image(source),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_line_joins_the_causes_and_io_is_told_from_bad_input() {
        let error = AppError::Write {
            path: "out/x.csv".into(),
            source: io::Error::new(io::ErrorKind::PermissionDenied, "denied"),
        };
        assert_eq!(one_line(&error), "out/x.csv: cannot write: denied");
        assert!(error.is_io() && !error.is_broken_pipe());
        let error = AppError::invalid("give --geometry FILE.csv, or --theta-i and --theta-r");
        assert!(!error.is_io());
        assert!(AppError::Stream(io::ErrorKind::BrokenPipe.into()).is_broken_pipe());
    }
}
