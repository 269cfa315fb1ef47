//! What the `irpol` subcommands do, as library functions the thin `main.rs` calls: model
//! selection from flags or a material file, angle sweeps, geometry CSVs and CSV output.

pub mod error;
pub mod evaluate;
pub mod export;
pub mod fit;
pub mod render;
pub mod render_cost;
pub mod saved_thermal;
pub mod scene_init;
pub mod selection;
pub mod sun;
pub mod thermal;
mod thermal_instant;
pub mod validate;
pub mod weather;

pub use error::{one_line, AppError};
pub use selection::{MeasurementArgs, SelectionArgs};

use crate::material::{Material, MaterialError};
use crate::optics::RefractiveIndex;
use crate::pbrdf::{
    DistributionError, DistributionKind, FacetSide, LobeKeys, LobeKeysWithoutReflectance,
    ModelError, Pbrdf, Shadowing,
};
use crate::text::shown;
use std::path::{Path, PathBuf};

/// A pBRDF chosen on the command line: a material file, or parameters (the flags of `eval` and
/// `emissivity`).
#[derive(Clone, Debug, Default)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct ModelArgs {
    /// A material TOML from the library (instead of the parameters below).
    #[cfg_attr(feature = "cli", arg(long))]
    pub material: Option<PathBuf>,
    /// Slope distribution: cauchy or gaussian.
    #[cfg_attr(feature = "cli", arg(long))]
    pub distribution: Option<String>,
    /// Slope parameter σ (rms slope per axis for the Gaussian; a = 2σ² for the Cauchy).
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub sigma: Option<f64>,
    /// Cauchy exponent q (> 1).
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub q: Option<f64>,
    /// Real part of the refractive index.
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub n: Option<f64>,
    /// Extinction coefficient (≥ 0).
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub k: Option<f64>,
    /// Diffuse (unpolarized) reflectance ρ_d.
    #[cfg_attr(feature = "cli", arg(long, allow_negative_numbers = true))]
    pub rho: Option<f64>,
    /// Which side of the facets reflects: external (relative index N, default) or internal
    /// (1/N, inside grains; docs/design.md §1.10).
    #[cfg_attr(feature = "cli", arg(long))]
    pub facet: Option<String>,
    /// The subsurface lobes' parameters (`--rho-s`, `--d`, `--n-sub`, `--d-c`, `--d1`: one flag
    /// per lobe parameter of the registry, docs/design.md §1.10).
    #[cfg_attr(feature = "cli", command(flatten))]
    pub lobes: LobeFlags,
    /// Shadowing: none, torrance-sparrow or smith (default smith, as `fit`; with --material,
    /// the material's own).
    #[cfg_attr(feature = "cli", arg(long))]
    pub shadowing: Option<String>,
    /// Wavelength (µm) at which to evaluate a spectral --material (n, k, ρ_d interpolated in its
    /// table; outside it is refused). A grey material is the same at every wavelength.
    #[cfg_attr(feature = "cli", arg(long = "wavelength", value_name = "UM"))]
    pub wavelength_um: Option<f64>,
}

/// The subsurface lobes' flags of [`ModelArgs`]: one `--flag` per lobe parameter of the
/// registry ([`crate::pbrdf::ParameterInfo::flag`]), so that a new lobe term brings its flags.
#[derive(Clone, Debug, Default)]
pub struct LobeFlags(pub LobeKeys<f64>);

#[cfg(feature = "cli")]
impl clap::FromArgMatches for LobeFlags {
    fn from_arg_matches(matches: &clap::ArgMatches) -> Result<LobeFlags, clap::Error> {
        let mut keys = LobeKeys::default();
        for parameter in crate::pbrdf::lobe_parameters() {
            keys.set(parameter, matches.get_one::<f64>(parameter.name()).copied());
        }
        Ok(LobeFlags(keys))
    }

    fn update_from_arg_matches(&mut self, matches: &clap::ArgMatches) -> Result<(), clap::Error> {
        *self = LobeFlags::from_arg_matches(matches)?;
        Ok(())
    }
}

#[cfg(feature = "cli")]
impl clap::Args for LobeFlags {
    fn augment_args(command: clap::Command) -> clap::Command {
        crate::pbrdf::lobe_parameters().fold(command, |command, parameter| {
            let info = parameter.info();
            let lobe = info.term.lobe().expect("a lobe parameter");
            let mut comment = info.comment.chars();
            let mut help: String = comment
                .next()
                .into_iter()
                .flat_map(char::to_uppercase)
                .collect();
            help.extend(comment);
            if parameter != lobe.reflectance {
                help.push_str(&format!("; needs --{}", lobe.reflectance.info().flag));
            }
            command.arg(
                clap::Arg::new(parameter.name())
                    .long(info.flag)
                    .value_name("VALUE")
                    .value_parser(clap::value_parser!(f64))
                    .allow_negative_numbers(true)
                    .help(help),
            )
        })
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        LobeFlags::augment_args(command)
    }
}

/// Why the model of [`ModelArgs`] or of a material cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum ModelArgsError {
    #[error(
        "unknown shadowing '{}': use none, torrance-sparrow or smith",
        crate::text::shown(.0)
    )]
    UnknownShadowing(String),
    #[error("unknown facet side '{}': use external or internal", crate::text::shown(.0))]
    UnknownFacet(String),
    #[error("{}", .0.message(|p| format!("--{}", p.info().flag)))]
    PolarizationWithoutSubsurface(LobeKeysWithoutReflectance),
    #[error(
        "give either --material or model parameters (--distribution --sigma --q --n --k \
         --rho), not both (got {0} with --material)"
    )]
    MaterialAndParameters(String),
    #[error(
        "--wavelength selects where a --material is evaluated; model parameters are one \
         wavelength's already"
    )]
    WavelengthWithoutMaterial,
    #[error("missing --{0} (or give --material FILE)")]
    Missing(&'static str),
    /// A distribution name or q that does not fit (`--q` for the Gaussian).
    #[error("{}", flag_message(.0))]
    Distribution(DistributionError),
    #[error(
        "material '{name}' is spectral ({}–{} µm): give --wavelength UM",
        crate::text::number(*.first_um),
        crate::text::number(*.last_um)
    )]
    SpectralNeedsWavelength {
        name: String,
        first_um: f64,
        last_um: f64,
    },
    /// A spectral material evaluated outside its table: the material file is named, and the
    /// measurement file whose wavelength it was.
    #[error("{}: {error} ({origin})", crate::text::path(path))]
    AtWavelength {
        path: PathBuf,
        origin: WavelengthOrigin,
        error: MaterialError,
    },
    #[error(transparent)]
    Material(#[from] MaterialError),
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// Where the wavelength a material is evaluated at comes from, as a message names it.
#[derive(Debug, Clone)]
pub enum WavelengthOrigin {
    /// `--wavelength`.
    Flag,
    /// The wavelength of a measurement set of this file.
    Data(PathBuf),
}

impl std::fmt::Display for WavelengthOrigin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            WavelengthOrigin::Flag => write!(f, "given by --wavelength"),
            WavelengthOrigin::Data(file) => {
                write!(f, "the wavelength of {}", crate::text::path(file))
            }
        }
    }
}

/// A distribution error as the command line says it: of `--q`, not of the file key `q`.
fn flag_message(error: &DistributionError) -> String {
    match error {
        DistributionError::StrayQ(_) => format!("--{error}"),
        other => other.to_string(),
    }
}

impl ModelArgs {
    /// The model: the material's, with `--shadowing` overriding it, or one built from the flags.
    pub fn build(&self) -> Result<Pbrdf, ModelArgsError> {
        let shadowing = match &self.shadowing {
            Some(name) => Some(
                Shadowing::parse(name)
                    .ok_or_else(|| ModelArgsError::UnknownShadowing(name.clone()))?,
            ),
            None => None,
        };
        if let Some(path) = &self.material {
            self.refuse_parameters()?;
            let material = Material::load(path)?;
            let at = self.wavelength_um.map(|um| (um, WavelengthOrigin::Flag));
            return material_pbrdf_from(&material, path, at, shadowing);
        }
        if self.wavelength_um.is_some() {
            return Err(ModelArgsError::WavelengthWithoutMaterial);
        }
        let sigma = self.sigma.ok_or(ModelArgsError::Missing("sigma"))?;
        let kind = match &self.distribution {
            Some(name) => DistributionKind::parse(name).map_err(ModelArgsError::Distribution)?,
            None => DistributionKind::Cauchy,
        };
        let distribution = kind.with(sigma, self.q).map_err(|error| match error {
            DistributionError::NeedsQ(_) => ModelArgsError::Missing("q"),
            other => ModelArgsError::Distribution(other),
        })?;
        let index = RefractiveIndex::new(
            self.n.ok_or(ModelArgsError::Missing("n"))?,
            self.k.ok_or(ModelArgsError::Missing("k"))?,
        );
        let model = Pbrdf::new(
            distribution,
            // One default everywhere (fit, eval, emissivity, inline scene materials): Smith, the
            // energy-conserving choice.
            shadowing.unwrap_or(Shadowing::Smith),
            index,
            self.rho.unwrap_or(0.0),
        )?;
        self.with_volume_terms(model)
    }

    /// `--facet` and the lobes' flags applied to `model` (docs/design.md §1.10).
    fn with_volume_terms(&self, model: Pbrdf) -> Result<Pbrdf, ModelArgsError> {
        let subsurface = self
            .lobes
            .0
            .lobes()
            .map_err(ModelArgsError::PolarizationWithoutSubsurface)?;
        if self.facet.is_none() && subsurface.is_empty() {
            return Ok(model);
        }
        let facet = match &self.facet {
            Some(name) => {
                FacetSide::parse(name).ok_or_else(|| ModelArgsError::UnknownFacet(name.clone()))?
            }
            None => FacetSide::External,
        };
        Ok(model.with_volume(facet, subsurface)?)
    }

    /// The material defines every model parameter: a flag beside it would be silently ignored
    /// (only --shadowing overrides the material's, by design).
    fn refuse_parameters(&self) -> Result<(), ModelArgsError> {
        let given: Vec<String> = [
            ("distribution", self.distribution.is_some()),
            ("sigma", self.sigma.is_some()),
            ("q", self.q.is_some()),
            ("n", self.n.is_some()),
            ("k", self.k.is_some()),
            ("rho", self.rho.is_some()),
            ("facet", self.facet.is_some()),
        ]
        .into_iter()
        .filter_map(|(flag, set)| set.then_some(flag))
        .chain(self.lobes.0.iter().map(|(p, _)| p.info().flag))
        .map(|flag| format!("--{flag}"))
        .collect();
        if given.is_empty() {
            Ok(())
        } else {
            Err(ModelArgsError::MaterialAndParameters(given.join(" ")))
        }
    }
}

/// The pBRDF of a loaded material as `eval` and `emissivity` use it: at `wavelength_um` (required
/// for a spectral material, interpolated in its table), with `shadowing` overriding the
/// material's own when given.
pub fn material_pbrdf(
    material: &Material,
    wavelength_um: Option<f64>,
    shadowing: Option<Shadowing>,
) -> Result<Pbrdf, ModelArgsError> {
    let mut spec = match (wavelength_um, material.model.spectral()) {
        (Some(wavelength), _) => material.at(wavelength)?,
        (None, None) => material.grey_model()?.clone(),
        (None, Some(table)) => {
            let (first_um, last_um) = table.range_um();
            return Err(ModelArgsError::SpectralNeedsWavelength {
                name: material.name.clone(),
                first_um,
                last_um,
            });
        }
    };
    if let Some(shadowing) = shadowing {
        spec.shadowing = shadowing;
    }
    Ok(spec.pbrdf()?)
}

/// [`material_pbrdf`] of the material in file `path`, at a wavelength from `origin`: a
/// wavelength outside a spectral table is refused naming the material's file and where the
/// wavelength came from (the flag, or the measurement file).
pub fn material_pbrdf_from(
    material: &Material,
    path: &Path,
    wavelength_um: Option<(f64, WavelengthOrigin)>,
    shadowing: Option<Shadowing>,
) -> Result<Pbrdf, ModelArgsError> {
    let (wavelength, origin) = match wavelength_um {
        Some((um, origin)) => (Some(um), Some(origin)),
        None => (None, None),
    };
    material_pbrdf(material, wavelength, shadowing).map_err(|error| match (error, origin) {
        (ModelArgsError::Material(error @ MaterialError::OutsideTable { .. }), Some(origin)) => {
            ModelArgsError::AtWavelength {
                path: path.to_owned(),
                origin,
                error,
            }
        }
        (error, _) => error,
    })
}

/// `#` lines stating the model a table was computed with (`eval`, `emissivity` output): the
/// distribution and its parameters, the index, ρ_d and the shadowing.
pub fn model_header(model: &Pbrdf) -> String {
    let slopes = model.distribution();
    let mut distribution = format!("{} slopes", slopes.kind());
    for &parameter in slopes.kind().parameters() {
        if let Some(value) = slopes.parameter(parameter) {
            distribution.push_str(&format!(", {parameter} = {value}"));
        }
    }
    let index = model.index();
    let mut header = format!(
        "# irpol {}: {distribution}\n# N = n + ik: n = {}, k = {}; rho_d = {}; shadowing = {}\n",
        env!("CARGO_PKG_VERSION"),
        index.n,
        index.k,
        model.rho_d(),
        model.shadowing().name()
    );
    // Only models with the volume terms say so, so that other tables read as before.
    if model.facet_side() != FacetSide::External || model.subsurface_lobes().next().is_some() {
        header.push_str(&format!("# facet = {}", model.facet_side().name()));
        for lobe in model.subsurface_lobes() {
            let keys: Vec<String> = lobe.keys().map(|(p, v)| format!("{p} = {v}")).collect();
            header.push_str(&format!("; {}", keys.join(", ")));
        }
        header.push('\n');
    }
    header
}

/// Most values one `START:STOP:STEP` sweep may hold.
pub const MAX_SWEEP_VALUES: usize = 1_000_000;

/// Parses `START:STOP:STEP` (inclusive of STOP within rounding) or a single value. A sweep holds
/// at least one value and at most [`MAX_SWEEP_VALUES`].
pub fn parse_sweep(text: &str, name: &str) -> Result<Vec<f64>, AppError> {
    let parts: Vec<&str> = text.split(':').collect();
    let number = |s: &str| -> Result<f64, AppError> {
        let value: f64 = s
            .trim()
            .parse()
            .map_err(|_| AppError::invalid(format!("--{name}: '{}' is not a number", shown(s))))?;
        if value.is_finite() {
            Ok(value)
        } else {
            Err(AppError::invalid(format!(
                "--{name}: '{}' is not finite",
                shown(s)
            )))
        }
    };
    match parts.as_slice() {
        [single] => Ok(vec![number(single)?]),
        [start, stop, step] => {
            let (start, stop, step) = (number(start)?, number(stop)?, number(step)?);
            if step <= 0.0 || stop < start {
                return Err(AppError::invalid(format!(
                    "--{name}: need STEP > 0 and STOP ≥ START in START:STOP:STEP, got '{}'",
                    shown(text)
                )));
            }
            // Counted in floating point first: a tiny step (1e-300) makes the quotient overflow
            // any integer, and a saturated count + 1 would wrap to an empty sweep.
            let steps = ((stop - start) / step + 1e-9).floor();
            if !steps.is_finite() || steps >= MAX_SWEEP_VALUES as f64 {
                return Err(AppError::invalid(format!(
                    "--{name}: '{}' asks for {} values; at most {MAX_SWEEP_VALUES}",
                    shown(text),
                    if steps.is_finite() {
                        crate::text::number(steps + 1.0)
                    } else {
                        "infinitely many".to_owned()
                    }
                )));
            }
            let count = steps as usize + 1;
            Ok((0..count).map(|i| start + i as f64 * step).collect())
        }
        _ => Err(AppError::invalid(format!(
            "--{name}: expected a number or START:STOP:STEP, got '{}'",
            shown(text)
        ))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sweeps_parse_and_refuse_nonsense() {
        assert_eq!(
            parse_sweep("0:10:5", "theta").unwrap(),
            vec![0.0, 5.0, 10.0]
        );
        assert_eq!(parse_sweep("0:89:1", "theta").unwrap().len(), 90);
        assert_eq!(parse_sweep("42", "theta").unwrap(), vec![42.0]);
        for bad in [
            "0:10:0",
            "10:0:1",
            "a:1:1",
            "1:2",
            "nan",
            "0:1e9:1e-3",
            "0:89:1e-300",
            "-1e308:1e308:1",
        ] {
            assert!(parse_sweep(bad, "theta").is_err(), "{bad}");
        }
    }

    #[test]
    fn model_args_need_all_parameters_and_refuse_mixing() {
        let mut args = ModelArgs {
            sigma: Some(0.1),
            q: Some(1.8),
            n: Some(1.2),
            ..Default::default()
        };
        assert!(args.build().unwrap_err().to_string().contains("--k"));
        args.k = Some(0.2);
        assert!(args.build().is_ok());
        args.shadowing = Some("smyth".into());
        assert!(args.build().unwrap_err().to_string().contains("smyth"));
        args.shadowing = None;
        args.material = Some("x.toml".into());
        assert!(args.build().unwrap_err().to_string().contains("not both"));
        for flags in [
            ModelArgs {
                rho: Some(0.5),
                ..Default::default()
            },
            ModelArgs {
                distribution: Some("gaussian".into()),
                ..Default::default()
            },
        ] {
            let args = ModelArgs {
                material: Some("x.toml".into()),
                ..flags
            };
            let message = args.build().unwrap_err().to_string();
            assert!(message.contains("not both"), "{message}");
        }
    }
}
