//! `irpol export MATERIAL.toml --to mitsuba --out F.pbsdf`: a material as the table Mitsuba 3's
//! `measured_polarized` plugin renders (docs/design.md §2.10), written atomically (a failed or
//! refused export leaves nothing at `--out`).

use super::AppError;
use crate::atomic::write_atomically;
use crate::material::Material;
use crate::material::{export_material, ExportOptions};
use std::path::{Path, PathBuf};

/// What was written, for the caller to print.
pub struct ExportSummary {
    pub path: PathBuf,
    pub bytes: u64,
    /// (N_φd, N_θd, N_θh).
    pub grid: [usize; 3],
    pub wavelengths_nm: Vec<u16>,
    pub notes: Vec<String>,
}

/// `--grid NPHI,NTD,NTH`: three node counts (range checked by the export).
pub fn parse_grid(text: &str) -> Result<[usize; 3], AppError> {
    let refuse = || {
        AppError::invalid(format!(
            "--grid '{}': expected three node counts NPHI,NTD,NTH, e.g. 49,41,65",
            crate::text::shown(text)
        ))
    };
    let counts: Vec<usize> = text
        .split(',')
        .map(|part| part.trim().parse::<usize>().map_err(|_| refuse()))
        .collect::<Result<_, _>>()?;
    <[usize; 3]>::try_from(counts).map_err(|_| refuse())
}

/// `--wavelengths-nm LIST`: whole nanometres, comma-separated (count and order checked by the
/// export, which explains the plugin's limit of five).
pub fn parse_wavelengths(text: &str) -> Result<Vec<u16>, AppError> {
    text.split(',')
        .map(|part| {
            let part = part.trim();
            part.parse::<u16>().ok().filter(|&w| w > 0).ok_or_else(|| {
                AppError::invalid(format!(
                    "--wavelengths-nm: '{}' is not a whole number of nanometres in 1..=65535 \
                     (Mitsuba stores wavelengths as uint16 nm)",
                    crate::text::shown(part)
                ))
            })
        })
        .collect()
}

/// Exports the material file `material` to `out` (a file; an existing folder is refused).
pub fn export_to_mitsuba(
    material: &Path,
    out: &Path,
    options: &ExportOptions,
) -> Result<ExportSummary, AppError> {
    check_request(out, options)?;
    let loaded = Material::load(material)?;
    export_material_to(&loaded, out, options).map_err(|e| e.named(&crate::text::path(material)))
}

/// The refusals that need no material: `out` a folder, options no table can have.
fn check_request(out: &Path, options: &ExportOptions) -> Result<(), AppError> {
    if out.is_dir() {
        return Err(AppError::invalid(format!(
            "--out {}: is a folder; give the table's file name, e.g. {}",
            crate::text::path(out),
            crate::text::path(&out.join("material.pbsdf"))
        )));
    }
    options
        .check()
        .map_err(|e| AppError::invalid(e.to_string()))
}

/// [`export_to_mitsuba`] of a material in memory (the Python `irpol.export_pbsdf`).
pub fn export_loaded(
    material: &Material,
    out: &Path,
    options: &ExportOptions,
) -> Result<ExportSummary, AppError> {
    check_request(out, options)?;
    export_material_to(material, out, options)
        .map_err(|e| e.named(&format!("material '{}'", material.name)))
}

/// Why an export of a checked request failed: the material cannot be tabulated, or the write.
enum ExportFailure {
    Export(crate::material::ExportError),
    Write(AppError),
}

impl ExportFailure {
    /// The application error, a refusal prefixed by what names the material.
    fn named(self, material: &str) -> AppError {
        match self {
            ExportFailure::Export(e) => AppError::invalid(format!("{material}: {e}")),
            ExportFailure::Write(e) => e,
        }
    }
}

fn export_material_to(
    material: &Material,
    out: &Path,
    options: &ExportOptions,
) -> Result<ExportSummary, ExportFailure> {
    let export = export_material(material, options).map_err(ExportFailure::Export)?;
    let bytes = export.table.to_bytes();
    write_atomically(out, &bytes).map_err(|source| {
        ExportFailure::Write(AppError::Write {
            path: out.to_owned(),
            source,
        })
    })?;
    Ok(ExportSummary {
        path: out.to_owned(),
        bytes: bytes.len() as u64,
        grid: export.table.grid.counts(),
        wavelengths_nm: export.table.wavelengths_nm.clone(),
        notes: export.notes,
    })
}
