//! The `[model]` table as written in a material file, the one schema both a grey model
//! ([`ModelSpec`], e.g. `[fit.alternative.model]`) and a material's model ([`MaterialModel`]) are
//! read through: flat, every key known (serde cannot deny unknown keys on a struct with a
//! flattened field, and a typo such as `rho = 0.5` must not silently give ρ_d = 0), then checked
//! into the typed model.

use super::{MaterialModel, ModelSpec, SpectralModel};
use crate::measure::SAME_WAVELENGTH_UM;
use crate::optics::{LorentzDispersion, MAX_WAVELENGTH_UM, MIN_WAVELENGTH_UM};
use crate::pbrdf::{
    DistributionError, DistributionKind, FacetSide, Shadowing, Subsurface,
    SubsurfaceKeysWithoutRhoS,
};
use crate::text::number;
use serde::Deserialize;

/// `[model]` as written: `V` is `f64` where only a grey model is allowed, [`OneOrMany`] where a
/// spectral table is too.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawModel<V> {
    distribution: DistributionKind,
    sigma: f64,
    q: Option<f64>,
    shadowing: Shadowing,
    n: V,
    k: V,
    rho_d: Option<V>,
    #[serde(default)]
    facet: FacetSide,
    rho_s: Option<f64>,
    d: Option<f64>,
    n_sub: Option<f64>,
    d_c: Option<f64>,
    wavelength_um: V,
    dispersion: Option<LorentzDispersion>,
}

/// A number or a list of numbers (a grey or a spectral key of `[model]`).
#[derive(Deserialize)]
#[serde(untagged)]
pub(super) enum OneOrMany {
    One(f64),
    Many(Vec<f64>),
}

/// Why a `[model]` table is refused (the message follows the file's path and line).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ModelTableError {
    #[error(transparent)]
    Distribution(#[from] DistributionError),
    #[error(
        "wavelength_um = {} is outside 0.1–1000 µm, the wavelengths irpol models",
        number(*.0)
    )]
    Wavelength(f64),
    #[error("a dispersion law needs tables: wavelength_um, n and k as arrays")]
    GreyDispersion,
    #[error(
        "wavelength_um, n and k must be all numbers (a grey material) or all arrays of equal \
         length (a spectral one)"
    )]
    MixedShapes,
    #[error("a spectral table needs at least two wavelengths (write numbers for a grey material)")]
    ShortTable,
    #[error("{name} has {len} values for {count} wavelengths (wavelength_um)")]
    Length {
        name: &'static str,
        len: usize,
        count: usize,
    },
    #[error(
        "wavelength_um must be strictly ascending ({} µm then {} µm)",
        number(*.0),
        number(*.1)
    )]
    NotAscending(f64, f64),
    #[error(
        "wavelength_um lists one wavelength twice: {} µm and {} µm are within {} µm, the \
         tolerance of one wavelength; keep one",
        number(*.0),
        number(*.1),
        number(SAME_WAVELENGTH_UM)
    )]
    DuplicateWavelength(f64, f64),
    #[error("dispersion: {0}")]
    Dispersion(#[source] crate::optics::LorentzError),
    #[error("{0}")]
    PolarizationWithoutSubsurface(#[from] SubsurfaceKeysWithoutRhoS),
    #[error(
        "facet = \"internal\", rho_s and d are grey-model terms: a spectral table cannot use \
         them yet (fit each wavelength as a grey material)"
    )]
    SpectralVolume,
}

/// Refuses a wavelength irpol does not model.
pub(super) fn check_wavelength(lambda: f64) -> Result<f64, ModelTableError> {
    if lambda.is_finite() && (MIN_WAVELENGTH_UM..=MAX_WAVELENGTH_UM).contains(&lambda) {
        Ok(lambda)
    } else {
        Err(ModelTableError::Wavelength(lambda))
    }
}

impl TryFrom<RawModel<f64>> for ModelSpec {
    type Error = ModelTableError;

    fn try_from(raw: RawModel<f64>) -> Result<ModelSpec, ModelTableError> {
        let distribution = raw.distribution.with(raw.sigma, raw.q)?;
        if raw.dispersion.is_some() {
            return Err(ModelTableError::GreyDispersion);
        }
        // Refuses d, n_sub, d_c without rho_s; the spec keeps the keys as written.
        Subsurface::from_keys(raw.rho_s, raw.d, raw.n_sub, raw.d_c)?;
        Ok(ModelSpec {
            distribution,
            shadowing: raw.shadowing,
            n: raw.n,
            k: raw.k,
            rho_d: raw.rho_d.unwrap_or(0.0),
            facet: raw.facet,
            rho_s: raw.rho_s,
            d: raw.rho_s.map(|_| raw.d.unwrap_or(0.0)),
            n_sub: raw.n_sub,
            d_c: raw.d_c,
            wavelength_um: check_wavelength(raw.wavelength_um)?,
        })
    }
}

impl TryFrom<RawModel<OneOrMany>> for MaterialModel {
    type Error = ModelTableError;

    fn try_from(raw: RawModel<OneOrMany>) -> Result<MaterialModel, ModelTableError> {
        use OneOrMany::{Many, One};
        let RawModel {
            distribution,
            sigma,
            q,
            shadowing,
            n,
            k,
            rho_d,
            facet,
            rho_s,
            d,
            n_sub,
            d_c,
            wavelength_um,
            dispersion,
        } = raw;
        let rho_d = rho_d.unwrap_or(One(0.0));
        let volume = facet != FacetSide::External
            || rho_s.is_some()
            || d.is_some()
            || n_sub.is_some()
            || d_c.is_some();
        match (wavelength_um, n, k, rho_d) {
            (One(wavelength_um), One(n), One(k), One(rho_d)) => {
                let grey = RawModel {
                    distribution,
                    sigma,
                    q,
                    shadowing,
                    n,
                    k,
                    rho_d: Some(rho_d),
                    facet,
                    rho_s,
                    d,
                    n_sub,
                    d_c,
                    wavelength_um,
                    dispersion,
                };
                Ok(MaterialModel::Grey(ModelSpec::try_from(grey)?))
            }
            (Many(_), Many(_), Many(_), _) if volume => Err(ModelTableError::SpectralVolume),
            (Many(wavelength_um), Many(n), Many(k), rho_d) => {
                let rho_d = match rho_d {
                    One(r) => vec![r; wavelength_um.len()],
                    Many(r) => r,
                };
                let model = SpectralModel {
                    distribution: distribution.with(sigma, q)?,
                    shadowing,
                    wavelength_um,
                    n,
                    k,
                    rho_d,
                    dispersion,
                };
                check_table(&model)?;
                Ok(MaterialModel::Spectral(model))
            }
            _ => {
                distribution.with(sigma, q)?;
                Err(ModelTableError::MixedShapes)
            }
        }
    }
}

/// Refuses a table that is not one: fewer than two nodes, unequal lengths, wavelengths out of
/// range or not strictly ascending, an unphysical dispersion law.
fn check_table(model: &SpectralModel) -> Result<(), ModelTableError> {
    let count = model.wavelength_um.len();
    if count < 2 {
        return Err(ModelTableError::ShortTable);
    }
    for (name, len) in [
        ("n", model.n.len()),
        ("k", model.k.len()),
        ("rho_d", model.rho_d.len()),
    ] {
        if len != count {
            return Err(ModelTableError::Length { name, len, count });
        }
    }
    for &w in &model.wavelength_um {
        check_wavelength(w)?;
    }
    if let Some(pair) = model
        .wavelength_um
        .windows(2)
        .find(|p| p[1] - p[0] <= SAME_WAVELENGTH_UM)
    {
        return Err(if (pair[1] - pair[0]).abs() <= SAME_WAVELENGTH_UM {
            ModelTableError::DuplicateWavelength(pair[0], pair[1])
        } else {
            ModelTableError::NotAscending(pair[0], pair[1])
        });
    }
    if let Some(law) = &model.dispersion {
        law.validate().map_err(ModelTableError::Dispersion)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_schema_reads_grey_and_spectral_models() {
        let grey = "distribution = \"cauchy\"\nsigma = 0.1\nq = 2.0\nshadowing = \"smith\"\n\
                    n = 1.5\nk = 0.1\nwavelength_um = 10.0\n";
        let spec: ModelSpec = toml::from_str(grey).unwrap();
        let model: MaterialModel = toml::from_str(grey).unwrap();
        assert_eq!(model, MaterialModel::Grey(spec));
        let spectral = grey
            .replace("n = 1.5", "n = [1.5, 1.6]")
            .replace("k = 0.1", "k = [0.1, 0.2]")
            .replace("wavelength_um = 10.0", "wavelength_um = [9.0, 10.0]");
        let model: MaterialModel = toml::from_str(&spectral).unwrap();
        assert!(matches!(model, MaterialModel::Spectral(_)));
        assert!(toml::from_str::<ModelSpec>(&spectral).is_err());
        let message = |text: &str| {
            toml::from_str::<MaterialModel>(text)
                .unwrap_err()
                .to_string()
        };
        let mixed = message(&grey.replace("n = 1.5", "n = [1.5, 1.6]"));
        assert!(mixed.contains("must be all numbers"), "{mixed}");
        let stray_q = message(&grey.replace("\"cauchy\"", "\"gaussian\""));
        assert!(stray_q.contains("q applies to the cauchy distribution only"));
        let dispersion = message(&format!(
            "{grey}[dispersion]\neps_inf = 2.0\noscillators = []\n"
        ));
        assert!(
            dispersion.contains("a dispersion law needs tables"),
            "{dispersion}"
        );
    }
}
