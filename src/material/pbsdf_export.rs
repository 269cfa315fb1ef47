//! A material as a `.pbsdf` table for Mitsuba 3 (docs/design.md §2.10): the wavelengths it is
//! tabulated at, its grid ([`crate::interop::grid`]) and its values
//! ([`crate::interop::tabulate`]).

use super::{Material, MaterialModel};
use crate::interop::grid::{material_grid, MAX_NODES};
use crate::interop::tabulate::tabulate;
use crate::interop::PbsdfTable;
use crate::pbrdf::Pbrdf;
use crate::text::number;

/// Wavelengths stock Mitsuba reads from a `.pbsdf` (≤ 3.9.1: a table with more or fewer is
/// misread, docs/design.md §2.10).
pub const MITSUBA_WAVELENGTHS: usize = 5;

/// A grey material's default wavelengths, nm: the LWIR window.
pub const GREY_WAVELENGTHS_NM: [u16; MITSUBA_WAVELENGTHS] = [8000, 9000, 10000, 11000, 12000];

/// Why a material cannot be exported as asked (one line).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct ExportError(pub String);

/// What to export: the wavelengths (default: [`default_wavelengths`]) and the grid's node
/// counts (N_φd, N_θd, N_θh; default: chosen by [`material_grid`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ExportOptions {
    pub wavelengths_nm: Option<Vec<u16>>,
    pub grid: Option<[usize; 3]>,
}

impl ExportOptions {
    /// Refuses what no material could be exported with ([`check_wavelengths`], [`check_grid`]).
    pub fn check(&self) -> Result<(), ExportError> {
        if let Some(wavelengths_nm) = &self.wavelengths_nm {
            check_wavelengths(wavelengths_nm)?;
        }
        self.grid.map_or(Ok(()), check_grid)
    }
}

/// An exported table and what the user should know about it.
pub struct Export {
    pub table: PbsdfTable,
    pub notes: Vec<String>,
}

/// The wavelengths a table of `model` holds by default: a grey model's
/// [`GREY_WAVELENGTHS_NM`], a spectral one's five evenly across its table (whole nm inside it).
pub fn default_wavelengths(model: &MaterialModel) -> Vec<u16> {
    match model.spectral() {
        None => GREY_WAVELENGTHS_NM.to_vec(),
        Some(spectral) => {
            let (first, last) = spectral.range_um();
            let (a, b) = ((first * 1e3).ceil(), (last * 1e3).floor());
            (0..MITSUBA_WAVELENGTHS)
                .map(|i| {
                    let w = a + (b - a) * i as f64 / (MITSUBA_WAVELENGTHS - 1) as f64;
                    w.round().clamp(1.0, 65535.0) as u16
                })
                .collect()
        }
    }
}

/// Refuses wavelengths stock Mitsuba cannot read: other than five, or not increasing.
pub fn check_wavelengths(wavelengths_nm: &[u16]) -> Result<(), ExportError> {
    if wavelengths_nm.len() != MITSUBA_WAVELENGTHS {
        return Err(ExportError(format!(
            "--wavelengths-nm: {} values given; Mitsuba's measured_polarized plugin (≤ 3.9.1) \
             reads exactly {MITSUBA_WAVELENGTHS} wavelengths from a table and misreads any \
             other count: give five, e.g. 8000,9000,10000,11000,12000",
            wavelengths_nm.len()
        )));
    }
    if let Some(w) = wavelengths_nm.windows(2).find(|w| w[1] <= w[0]) {
        return Err(ExportError(format!(
            "--wavelengths-nm: {} nm follows {} nm: give the wavelengths in increasing order",
            w[1], w[0]
        )));
    }
    Ok(())
}

/// Refuses node counts below 2 or above [`MAX_NODES`].
pub fn check_grid(counts: [usize; 3]) -> Result<(), ExportError> {
    match counts
        .iter()
        .zip(["NPHI", "NTD", "NTH"])
        .find(|(&n, _)| !(2..=MAX_NODES).contains(&n))
    {
        Some((n, name)) => Err(ExportError(format!(
            "--grid: {name} = {n} is outside 2..={MAX_NODES} (nodes along the axis)"
        ))),
        None => Ok(()),
    }
}

/// The model at each wavelength: a spectral model's outside its table is its value at the
/// nearer end, with a note.
fn models_at(
    material: &Material,
    wavelengths_nm: &[u16],
) -> Result<(Vec<Pbrdf>, Vec<String>), ExportError> {
    let mut notes = Vec::new();
    let mut models = Vec::with_capacity(wavelengths_nm.len());
    for &nm in wavelengths_nm {
        let mut um = f64::from(nm) * 1e-3;
        if let Some(spectral) = material.model.spectral() {
            let (first, last) = spectral.range_um();
            if !(first..=last).contains(&um) {
                let end = um.clamp(first, last);
                notes.push(format!(
                    "{nm} nm is outside the table of '{}' ({}–{} µm): its values at {} µm are \
                     exported there",
                    material.name,
                    number(first),
                    number(last),
                    number(end)
                ));
                um = end;
            }
        }
        let spec = material.at(um).map_err(|e| ExportError(e.to_string()))?;
        models.push(
            spec.pbrdf()
                .map_err(|e| ExportError(format!("material '{}': {e}", material.name)))?,
        );
    }
    Ok((models, notes))
}

/// The `.pbsdf` table of `material`.
pub fn export_material(
    material: &Material,
    options: &ExportOptions,
) -> Result<Export, ExportError> {
    let wavelengths_nm = options
        .wavelengths_nm
        .clone()
        .unwrap_or_else(|| default_wavelengths(&material.model));
    options.check()?;
    check_wavelengths(&wavelengths_nm)?;
    let (models, notes) = models_at(material, &wavelengths_nm)?;
    let grid = material_grid(&models, options.grid);
    Ok(Export {
        table: tabulate(&models, wavelengths_nm, grid),
        notes,
    })
}
