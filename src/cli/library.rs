//! `irpol library`: the library folder's materials as a table.

use super::terminal::warn_once;
use irpol::material::MaterialModel;
use std::path::Path;

pub(crate) fn print_library(dir: &Path) -> anyhow::Result<()> {
    let library = irpol::material::list_library(dir)?;
    warn_once(&library.warnings());
    let misfits: Vec<String> = library
        .materials
        .iter()
        .filter_map(|(_, m)| irpol::app::fit::misfit_warning(m))
        .collect();
    warn_once(&misfits);
    let materials = library.materials;
    if materials.is_empty() {
        say!("no materials in {}", dir.display());
        return Ok(());
    }
    say!(
        "{:<18} {:<9} {:<17} {:>9} {:>6} {:>6} {:>11} {:>11} {:>7} {:>8}",
        "material",
        "dist",
        "shadowing",
        "λ µm",
        "σ",
        "q",
        "n",
        "k",
        "ρ_d",
        "χ²_red"
    );
    // A spectral material shows the range of its table: λ first–last, n, k, ρ_d min–max.
    let span = |values: &[f64], digits: usize| {
        let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let (lo, hi) = (format!("{lo:.digits$}"), format!("{hi:.digits$}"));
        if lo == hi {
            lo
        } else {
            format!("{lo}–{hi}")
        }
    };
    for (_, m) in materials {
        let (wavelengths, n, k, rho_d) = match &m.model {
            MaterialModel::Grey(s) => (vec![s.wavelength_um], vec![s.n], vec![s.k], vec![s.rho_d]),
            MaterialModel::Spectral(s) => (
                s.wavelength_um.clone(),
                s.n.clone(),
                s.k.clone(),
                s.rho_d.clone(),
            ),
        };
        let q = m
            .model
            .distribution()
            .parameter(irpol::pbrdf::Parameter::Q)
            .map_or("—".into(), |q| format!("{q:.3}"));
        // A fit that does not describe its data is marked, and said below the table.
        let chi2 = m.fit.as_ref().map_or("—".into(), |f| {
            let mark = if f.misfit().is_empty() { "" } else { " !" };
            format!("{:.3}{mark}", f.reduced_chi2)
        });
        say!(
            "{:<18} {:<9} {:<17} {:>9} {:>6.3} {:>6} {:>11} {:>11} {:>7} {:>8}",
            m.name,
            m.model.distribution().name(),
            m.model.shadowing().name(),
            span(&wavelengths, if wavelengths.len() > 1 { 1 } else { 3 }),
            m.model.distribution().sigma(),
            q,
            span(&n, 3),
            span(&k, 3),
            span(&rho_d, 4),
            chi2
        );
    }
    Ok(())
}
