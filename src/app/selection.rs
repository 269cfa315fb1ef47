//! The flags of every command that reads measurement files (`irpol fit`, and the commands that
//! predict measurements): the instrument layout to read them through and the rows to keep
//! (docs/design.md §2.8). One clap struct, flattened into each command, so that all refuse the
//! same input with the same message.

use std::path::PathBuf;

use super::AppError;
use crate::measure::{AngleReading, Layout, MeasurementSet, ReadOptions, RowSelection};

/// How to read the measurement files: `--layout`, `--wavelength`, `--theta-i`.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct MeasurementArgs {
    /// Instrument layout (TOML, docs/design.md §2.8) to read the files through, for files in
    /// an instrument's own columns and conventions; a file may name its own with a
    /// '# layout: FILE' line instead.
    #[cfg_attr(feature = "cli", arg(long, value_name = "L.toml"))]
    pub layout: Option<PathBuf>,
    #[cfg_attr(feature = "cli", command(flatten))]
    pub selection: SelectionArgs,
    /// How to read the files' angle columns: auto (as declared; angles that look like radians
    /// declared as degrees are refused), degrees (even if they look like radians), or radians
    /// (a CSV whose _deg columns hold radians, converted).
    #[cfg_attr(feature = "cli", arg(long, value_name = "auto|degrees|radians"))]
    pub angles: Option<String>,
}

/// Which rows of each file to keep: `--wavelength`, `--theta-i`.
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct SelectionArgs {
    /// Keep only the rows at this wavelength (µm) of a file that holds several.
    #[cfg_attr(feature = "cli", arg(long = "wavelength", value_name = "UM"))]
    pub wavelength_um: Option<f64>,
    /// Keep only the rows at these incidence angles, degrees, comma-separated (a row within
    /// 0.05° of one is kept), e.g. 0,30,60,75.
    #[cfg_attr(
        feature = "cli",
        arg(long = "theta-i", value_name = "LIST", value_delimiter = ',')
    )]
    pub theta_i_deg: Vec<f64>,
}

impl SelectionArgs {
    /// The selection, its values checked.
    pub fn selection(&self) -> Result<RowSelection, AppError> {
        let selection = RowSelection {
            wavelength_um: self.wavelength_um,
            theta_i_deg: self.theta_i_deg.clone(),
        };
        selection.check()?;
        Ok(selection)
    }

    /// The selected rows of one file's sets (one per wavelength, as a reader returns them).
    pub fn apply(&self, sets: Vec<MeasurementSet>) -> Result<Vec<MeasurementSet>, AppError> {
        Ok(self.selection()?.apply(sets)?)
    }
}

impl MeasurementArgs {
    /// The layout read and the selection checked: what [`ReadOptions::read`] reads each file with.
    pub fn read_options(&self) -> Result<ReadOptions, AppError> {
        let layout = match &self.layout {
            Some(path) => Some(Layout::read(path)?),
            None => None,
        };
        Ok(ReadOptions {
            layout,
            selection: self.selection.selection()?,
            angles: match &self.angles {
                Some(text) => AngleReading::parse(text).ok_or_else(|| {
                    AppError::invalid(format!(
                        "unknown --angles '{}': use auto, degrees or radians",
                        crate::text::shown(text)
                    ))
                })?,
                None => AngleReading::Auto,
            },
        })
    }
}
