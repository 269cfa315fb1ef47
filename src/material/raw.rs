//! The `[model]` table as written in a material file, the one schema both a grey model
//! ([`ModelSpec`], e.g. `[fit.alternative.model]`) and a material's model ([`MaterialModel`]) are
//! read through: flat, every key known (serde cannot deny unknown keys on a struct with a
//! flattened field, and a typo such as `rho = 0.5` must not silently give ρ_d = 0), then checked
//! into the typed model.

use super::spectral::{PerWavelength, SpectralVolume};
use super::{MaterialModel, ModelSpec, SpectralModel};
use crate::measure::SAME_WAVELENGTH_UM;
use crate::optics::{LorentzDispersion, MAX_WAVELENGTH_UM, MIN_WAVELENGTH_UM};
use crate::pbrdf::{
    read_table, table_fields, DistributionError, DistributionKind, FacetSide, LobeKeys,
    LobeKeysWithoutReflectance, Shadowing,
};
use crate::text::number;
use serde::de::{Deserializer, Error as _, MapAccess, Visitor};
use serde::Deserialize;
use std::marker::PhantomData;
use std::sync::LazyLock;

/// `[model]` as written: `V` is `f64` where only a grey model is allowed, [`PerWavelength`] where
/// a spectral table is too. Read key by key ([`RawModel::deserialize`]): the lobe terms' keys
/// come from the registry, and every other key is refused by name.
pub(super) struct RawModel<V> {
    distribution: DistributionKind,
    sigma: f64,
    q: Option<f64>,
    shadowing: Shadowing,
    n: V,
    k: V,
    rho_d: Option<V>,
    facet: FacetSide,
    lobe_keys: LobeKeys<V>,
    wavelength_um: V,
    dispersion: Option<LorentzDispersion>,
}

/// The keys of [`RawModel`] besides the lobes'.
const MODEL_KEYS: [&str; 10] = [
    "distribution",
    "sigma",
    "q",
    "shadowing",
    "n",
    "k",
    "rho_d",
    "facet",
    "wavelength_um",
    "dispersion",
];

impl<'de, V: Deserialize<'de>> Deserialize<'de> for RawModel<V> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<RawModel<V>, D::Error> {
        deserializer.deserialize_map(RawModelVisitor(PhantomData))
    }
}

struct RawModelVisitor<V>(PhantomData<V>);

impl<'de, V: Deserialize<'de>> Visitor<'de> for RawModelVisitor<V> {
    type Value = RawModel<V>;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("a [model] table")
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<RawModel<V>, A::Error> {
        static FIELDS: LazyLock<Vec<&'static str>> = LazyLock::new(|| table_fields(&MODEL_KEYS));
        let (mut distribution, mut sigma, mut q, mut shadowing) = (None, None, None, None);
        let (mut n, mut k, mut rho_d, mut facet) = (None, None, None, None);
        let (mut wavelength_um, mut dispersion) = (None, None);
        let lobe_keys = read_table(map, &FIELDS, |key, map| {
            match key {
                "distribution" => distribution = Some(map.next_value()?),
                "sigma" => sigma = Some(map.next_value()?),
                "q" => q = map.next_value()?,
                "shadowing" => shadowing = Some(map.next_value()?),
                "n" => n = Some(map.next_value()?),
                "k" => k = Some(map.next_value()?),
                "rho_d" => rho_d = map.next_value()?,
                "facet" => facet = Some(map.next_value()?),
                "wavelength_um" => wavelength_um = Some(map.next_value()?),
                "dispersion" => dispersion = map.next_value()?,
                _ => return Ok(false),
            }
            Ok(true)
        })?;
        let missing = A::Error::missing_field;
        Ok(RawModel {
            distribution: distribution.ok_or_else(|| missing("distribution"))?,
            sigma: sigma.ok_or_else(|| missing("sigma"))?,
            q,
            shadowing: shadowing.ok_or_else(|| missing("shadowing"))?,
            n: n.ok_or_else(|| missing("n"))?,
            k: k.ok_or_else(|| missing("k"))?,
            rho_d,
            facet: facet.unwrap_or_default(),
            lobe_keys,
            wavelength_um: wavelength_um.ok_or_else(|| missing("wavelength_um"))?,
            dispersion,
        })
    }
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
    #[error(
        "{name} has {len} values for {count} wavelengths (wavelength_um): {} µm has none; give \
         one number (shared by every wavelength) or one per wavelength",
        number(*.missing_um)
    )]
    Length {
        name: &'static str,
        len: usize,
        count: usize,
        /// The first table wavelength without a value (the last one given when there are too
        /// many).
        missing_um: f64,
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
    PolarizationWithoutSubsurface(#[from] LobeKeysWithoutReflectance),
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
        // Refuses d, n_sub, d_c without rho_s; the spec keeps the keys as written, with each
        // lobe's d (0 where absent).
        let lobe_keys = raw.lobe_keys.with_residuals()?;
        Ok(ModelSpec {
            distribution,
            shadowing: raw.shadowing,
            n: raw.n,
            k: raw.k,
            rho_d: raw.rho_d.unwrap_or(0.0),
            facet: raw.facet,
            lobe_keys,
            wavelength_um: check_wavelength(raw.wavelength_um)?,
        })
    }
}

impl TryFrom<RawModel<PerWavelength>> for MaterialModel {
    type Error = ModelTableError;

    fn try_from(raw: RawModel<PerWavelength>) -> Result<MaterialModel, ModelTableError> {
        if let Some(grey) = raw.grey() {
            return Ok(MaterialModel::Grey(ModelSpec::try_from(grey)?));
        }
        use PerWavelength::{Each, Shared};
        let distribution = raw.distribution.with(raw.sigma, raw.q)?;
        let (Each(wavelength_um), Each(n), Each(k)) = (raw.wavelength_um, raw.n, raw.k) else {
            return Err(ModelTableError::MixedShapes);
        };
        // One check of the subsurface keys for grey and spectral files alike.
        raw.lobe_keys.map(|_, _| 0.0).lobes()?;
        let rho_d = match raw.rho_d.unwrap_or(Shared(0.0)) {
            Shared(r) => vec![r; wavelength_um.len()],
            Each(r) => r,
        };
        let model = SpectralModel {
            distribution,
            shadowing: raw.shadowing,
            wavelength_um,
            n,
            k,
            rho_d,
            volume: SpectralVolume {
                facet: raw.facet,
                lobe_keys: raw.lobe_keys,
            },
            dispersion: raw.dispersion,
        };
        check_table(&model)?;
        Ok(MaterialModel::Spectral(model))
    }
}

impl RawModel<PerWavelength> {
    /// The model as a grey one, when every key is a single number (wavelength_um, n and k).
    fn grey(&self) -> Option<RawModel<f64>> {
        let one = |v: &PerWavelength| match v {
            PerWavelength::Shared(x) => Some(*x),
            PerWavelength::Each(_) => None,
        };
        let optional = |v: &Option<PerWavelength>| match v {
            None => Some(None),
            Some(v) => one(v).map(Some),
        };
        let mut lobe_keys = LobeKeys::default();
        for (parameter, value) in self.lobe_keys.iter() {
            lobe_keys.set(parameter, Some(one(value)?));
        }
        Some(RawModel {
            distribution: self.distribution,
            sigma: self.sigma,
            q: self.q,
            shadowing: self.shadowing,
            n: one(&self.n)?,
            k: one(&self.k)?,
            rho_d: optional(&self.rho_d)?,
            facet: self.facet,
            lobe_keys,
            wavelength_um: one(&self.wavelength_um)?,
            dispersion: self.dispersion.clone(),
        })
    }
}

/// Refuses a table that is not one: fewer than two nodes, unequal lengths, wavelengths out of
/// range or not strictly ascending, an unphysical dispersion law.
fn check_table(model: &SpectralModel) -> Result<(), ModelTableError> {
    let count = model.wavelength_um.len();
    if count < 2 {
        return Err(ModelTableError::ShortTable);
    }
    let volume = model
        .volume
        .lobe_keys
        .iter()
        .filter_map(|(parameter, value)| Some((parameter.name(), value.table_len()?)));
    for (name, len) in [
        ("n", model.n.len()),
        ("k", model.k.len()),
        ("rho_d", model.rho_d.len()),
    ]
    .into_iter()
    .chain(volume)
    {
        if len != count {
            let missing_um = model.wavelength_um[len.min(count - 1)];
            return Err(ModelTableError::Length {
                name,
                len,
                count,
                missing_um,
            });
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
