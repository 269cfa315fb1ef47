//! A scene's `[materials]` and the material names its objects use (docs/design.md §2.3), resolved
//! into pBRDFs over the sensor band: inline pBRDF parameters, a material file, or a library name.

use super::{find_material, BandModelError, Material, MaterialError, MaterialModel, SpectralModel};
use crate::optics::{Band, RefractiveIndex, TableMissesBand};
use crate::pbrdf::{
    read_table, slope_distribution, table_fields, DistributionError, FacetSide, LobeKeys,
    LobeKeysWithoutReflectance, MaterialOptics, ModelError, Pbrdf,
};
use serde::de::{Deserializer, Error as _, MapAccess, Visitor};
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

/// pBRDF parameters given directly in the scene (docs/design.md §1.3); wavelength is not needed to render.
#[derive(Debug, Clone)]
pub struct InlineMaterialConfig {
    pub distribution: String,
    pub sigma: f64,
    pub q: Option<f64>,
    pub n: f64,
    pub k: f64,
    pub rho_d: f64,
    /// Default Smith, as everywhere in irpol.
    pub shadowing: crate::pbrdf::Shadowing,
    /// The volume-scattering terms of docs/design.md §1.10, as in a material file: the facet
    /// side and the subsurface lobes' keys.
    pub facet: FacetSide,
    pub lobe_keys: LobeKeys<f64>,
}

/// The keys of [`InlineMaterialConfig`] besides the lobes'.
const INLINE_KEYS: [&str; 8] = [
    "distribution",
    "sigma",
    "q",
    "n",
    "k",
    "rho_d",
    "shadowing",
    "facet",
];

/// Read key by key, as a material file's `[model]` (`material::raw`): the lobe terms' keys come
/// from the registry, every other key is refused by name.
impl<'de> Deserialize<'de> for InlineMaterialConfig {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        deserializer.deserialize_map(InlineMaterialVisitor)
    }
}

struct InlineMaterialVisitor;

impl<'de> Visitor<'de> for InlineMaterialVisitor {
    type Value = InlineMaterialConfig;

    fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str("an inline material table")
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<InlineMaterialConfig, A::Error> {
        static FIELDS: LazyLock<Vec<&'static str>> = LazyLock::new(|| table_fields(&INLINE_KEYS));
        let (mut distribution, mut sigma, mut q, mut n, mut k) = (None, None, None, None, None);
        let (mut rho_d, mut shadowing, mut facet) = (None, None, None);
        let lobe_keys = read_table(map, &FIELDS, |key, map| {
            match key {
                "distribution" => distribution = Some(map.next_value()?),
                "sigma" => sigma = Some(map.next_value()?),
                "q" => q = map.next_value()?,
                "n" => n = Some(map.next_value()?),
                "k" => k = Some(map.next_value()?),
                "rho_d" => rho_d = Some(map.next_value()?),
                "shadowing" => shadowing = Some(map.next_value()?),
                "facet" => facet = Some(map.next_value()?),
                _ => return Ok(false),
            }
            Ok(true)
        })?;
        let missing = A::Error::missing_field;
        Ok(InlineMaterialConfig {
            distribution: distribution.ok_or_else(|| missing("distribution"))?,
            sigma: sigma.ok_or_else(|| missing("sigma"))?,
            q,
            n: n.ok_or_else(|| missing("n"))?,
            k: k.ok_or_else(|| missing("k"))?,
            rho_d: rho_d.unwrap_or(0.0),
            shadowing: shadowing.unwrap_or(crate::pbrdf::Shadowing::Smith),
            facet: facet.unwrap_or_default(),
            lobe_keys,
        })
    }
}

/// A material used by the scene, with its validated pBRDF over the sensor band.
#[derive(Clone, Debug)]
pub struct SceneMaterial {
    /// The name given in the scene.
    pub name: String,
    /// Where it came from: the material file, or "inline".
    pub origin: String,
    /// Grey (one pBRDF), or for a spectral material its pBRDF at each wavelength node of the
    /// sensor band (docs/design.md §1.9).
    pub optics: MaterialOptics,
    /// The wavelength a grey library material was measured at (inline and spectral materials
    /// have none).
    pub wavelength_um: Option<f64>,
    /// A spectral material's table (the thermal emissivity needs wavelengths beyond the band).
    pub spectral_model: Option<SpectralModel>,
}

/// An inline material's keys do not make a pBRDF.
#[derive(Debug, thiserror::Error)]
pub enum InlineMaterialError {
    /// The distribution name, or its `q`, is wrong (the material file's words for it).
    #[error("{0}")]
    Distribution(#[from] DistributionError),
    #[error("{0}")]
    Model(ModelError),
    #[error("{0}")]
    PolarizationWithoutSubsurface(#[from] LobeKeysWithoutReflectance),
}

/// A material of a scene cannot be used. The inner errors are part of the message (not a
/// `source`), so it reads the same with `{}` and `{:#}`.
#[derive(Debug, thiserror::Error)]
pub enum SceneMaterialError {
    #[error("inline material [materials.{name}]: {error}")]
    Inline {
        name: String,
        error: InlineMaterialError,
    },
    /// A library name with no file in the library.
    #[error(
        "{error}; define it inline under [materials.{name}] in {} or set material_library",
        crate::text::path(scene)
    )]
    NotFound {
        name: String,
        scene: PathBuf,
        error: MaterialError,
    },
    /// The material file cannot be read or is not a material.
    #[error("{0}")]
    Load(MaterialError),
    /// A grey material's pBRDF is invalid.
    #[error("material '{name}' ({origin}): {error}")]
    Model {
        name: String,
        origin: String,
        error: ModelError,
    },
    /// A spectral material does not cover the band (or its nodes).
    #[error("material '{name}' ({origin}): {error}")]
    Band {
        name: String,
        origin: String,
        error: BandModelError,
    },
    /// The spectral materials' tables give no common wavelength nodes.
    #[error("{0}")]
    Nodes(TableMissesBand),
}

impl SceneMaterial {
    /// The thermal hemispherical emissivity of docs/design.md §1.8's default: the grey pBRDF's ε_h, or a
    /// spectral table's Planck-weighted one ([`SpectralModel::thermal_emissivity`]).
    pub fn thermal_emissivity(&self) -> Result<f64, SceneMaterialError> {
        match (&self.optics, &self.spectral_model) {
            (_, Some(model)) => model
                .thermal_emissivity()
                .map_err(|error| self.band_error(error)),
            (optics, None) => Ok(optics.sampling_pbrdf().hemispherical_emissivity()),
        }
    }

    fn band_error(&self, error: BandModelError) -> SceneMaterialError {
        SceneMaterialError::Band {
            name: self.name.clone(),
            origin: self.origin.clone(),
            error,
        }
    }
}

/// Resolves material references: an inline name, a file path (ends in .toml or has a /), or a
/// library name (`<library>/<name>.toml`). Each distinct material is loaded once.
pub struct MaterialResolver<'a> {
    /// The scene file (named in messages).
    pub scene: &'a Path,
    /// The sensor band spectral materials are integrated over.
    band: &'a Band,
    /// Material paths are relative to this folder (the scene's).
    pub dir: &'a Path,
    library: PathBuf,
    inline: &'a BTreeMap<String, InlineMaterialConfig>,
    resolved: Vec<SceneMaterial>,
    index_of: HashMap<String, usize>,
}

impl<'a> MaterialResolver<'a> {
    /// `library` is the folder of library names (`material_library`, default `fits`, under `dir`).
    pub fn new(
        scene: &'a Path,
        band: &'a Band,
        dir: &'a Path,
        library: PathBuf,
        inline: &'a BTreeMap<String, InlineMaterialConfig>,
    ) -> MaterialResolver<'a> {
        MaterialResolver {
            scene,
            band,
            dir,
            library,
            inline,
            resolved: Vec::new(),
            index_of: HashMap::new(),
        }
    }

    /// The materials resolved so far, in index order.
    pub fn resolved(&self) -> &[SceneMaterial] {
        &self.resolved
    }

    /// Every material resolved, on shared wavelength nodes ([`share_wavelength_nodes`]).
    pub fn finish(mut self) -> Result<Vec<SceneMaterial>, SceneMaterialError> {
        share_wavelength_nodes(&mut self.resolved, self.band)?;
        Ok(self.resolved)
    }

    /// The index of the material `reference` names, loading it on first use.
    pub fn resolve(&mut self, reference: &str) -> Result<usize, SceneMaterialError> {
        let (key, material) = if let Some(inline) = self.inline.get(reference) {
            let key = format!("inline:{reference}");
            if let Some(&i) = self.index_of.get(&key) {
                return Ok(i);
            }
            let pbrdf = inline_pbrdf(inline).map_err(|error| SceneMaterialError::Inline {
                name: reference.to_owned(),
                error,
            })?;
            (
                key,
                SceneMaterial {
                    name: reference.to_owned(),
                    origin: "inline".into(),
                    optics: MaterialOptics::Grey(pbrdf),
                    wavelength_um: None,
                    spectral_model: None,
                },
            )
        } else {
            let path = if reference.ends_with(".toml") || reference.contains('/') {
                self.dir.join(reference)
            } else {
                find_material(&self.library, reference).map_err(|error| {
                    SceneMaterialError::NotFound {
                        name: reference.to_owned(),
                        scene: self.scene.to_owned(),
                        error,
                    }
                })?
            };
            let key = format!("file:{}", path.display());
            if let Some(&i) = self.index_of.get(&key) {
                return Ok(i);
            }
            let loaded = Material::load(&path).map_err(SceneMaterialError::Load)?;
            (key, self.library_material(reference, &path, &loaded)?)
        };
        self.resolved.push(material);
        self.index_of.insert(key, self.resolved.len() - 1);
        Ok(self.resolved.len() - 1)
    }

    /// A material from the library or a file: grey, or spectral and integrated over the band's
    /// wavelength nodes (refused when its table does not span the band).
    fn library_material(
        &self,
        reference: &str,
        path: &Path,
        loaded: &Material,
    ) -> Result<SceneMaterial, SceneMaterialError> {
        let origin = path.display().to_string();
        let (optics, wavelength_um, spectral_model) = match &loaded.model {
            MaterialModel::Grey(model) => (
                MaterialOptics::Grey(model.pbrdf().map_err(|error| SceneMaterialError::Model {
                    name: reference.to_owned(),
                    origin: origin.clone(),
                    error,
                })?),
                Some(model.wavelength_um),
                None,
            ),
            MaterialModel::Spectral(model) => (
                MaterialOptics::Band(model.band_pbrdf(self.band).map_err(|error| {
                    SceneMaterialError::Band {
                        name: reference.to_owned(),
                        origin: origin.clone(),
                        error,
                    }
                })?),
                None,
                Some(model.clone()),
            ),
        };
        Ok(SceneMaterial {
            name: reference.to_owned(),
            origin,
            optics,
            wavelength_um,
            spectral_model,
        })
    }
}

/// Puts every spectral material of a scene on one set of wavelength nodes (docs/design.md §1.9,
/// [`crate::optics::WavelengthNodes::for_tables`]): the band split at the table wavelengths of
/// all of them, so that light passed from one to another keeps its spectrum node by node.
pub fn share_wavelength_nodes(
    materials: &mut [SceneMaterial],
    band: &Band,
) -> Result<(), SceneMaterialError> {
    let tables: Vec<&[f64]> = materials
        .iter()
        .filter_map(|m| m.spectral_model.as_ref())
        .map(|model| model.wavelength_um.as_slice())
        .collect();
    if tables.len() < 2 {
        return Ok(());
    }
    let nodes = crate::optics::WavelengthNodes::for_tables(band, &tables)
        .map_err(SceneMaterialError::Nodes)?;
    for material in materials.iter_mut() {
        if let Some(model) = &material.spectral_model {
            let band_pbrdf = model
                .band_pbrdf_on(nodes.clone())
                .map_err(|error| material.band_error(error))?;
            material.optics = MaterialOptics::Band(band_pbrdf);
        }
    }
    Ok(())
}

pub fn inline_pbrdf(m: &InlineMaterialConfig) -> Result<Pbrdf, InlineMaterialError> {
    let distribution = slope_distribution(&m.distribution, m.sigma, m.q)?;
    let subsurface = m.lobe_keys.lobes()?;
    Pbrdf::new(
        distribution,
        m.shadowing,
        RefractiveIndex::new(m.n, m.k),
        m.rho_d,
    )
    .and_then(|model| model.with_volume(m.facet, subsurface))
    .map_err(InlineMaterialError::Model)
}
