//! The vocabulary of the pBRDF model (docs/design.md §1.2–1.3, §1.10), declared once.
//!
//! - Its parameters ([`Parameter`]: the slope parameters, the index N = n + ik, and the body
//!   terms' ρ_d, ρ_s, d, n_sub, d_c, d1), each with one [`ParameterInfo`] entry: its key in
//!   files and on the command line, report label, unit, the values a model accepts, the default
//!   search interval, default and starting value, search map and trap rule of a fit, the `#`
//!   comment a material file carries above the key, and its role in a spectral fit.
//! - Its terms ([`Term`]: the facet term, the ideal depolarizer, the polarized subsurface term)
//!   with the parameters each one owns, and the combinations a fit chooses among
//!   ([`ModelTerms`]).
//!
//! The fit, the material files, the command line's flags and the reports read this table
//! instead of repeating it: the fit's bounds, starts, search coordinates, traps and restarts are
//! entries here, and a subsurface lobe's keys are stored by parameter ([`super::LobeKeys`]). A
//! new lobe term is a [`Term`] with its [`LobeParameters`], its parameters' entries, a [`Body`]
//! that holds it and, for the default fit to try it, a [`ModelTerms::ALL`] entry: nothing
//! outside this file.

use super::facet_side::FacetSide;
use super::limits;
pub use super::search_rules::{SearchMap, TrapRule};
use crate::text::number;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A parameter of the pBRDF model, which a fit can adjust or hold fixed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// Slope parameter σ of every slope distribution (docs/design.md §1.2).
    Sigma,
    /// Cauchy exponent q (not a parameter of the Gaussian).
    Q,
    /// Real part n of the refractive index.
    N,
    /// Extinction coefficient k.
    K,
    /// Diffuse reflectance ρ_d.
    RhoD,
    /// Subsurface reflectance ρ_s (docs/design.md §1.10).
    RhoS,
    /// Residual polarization d of the subsurface light.
    D,
    /// Real index of the interface the subsurface light crosses.
    NSub,
    /// Residual circular polarization d_c of the subsurface light (D's m33 is −d_c).
    DC,
    /// How the residual polarization changes with the scattering angle Θ: d(Θ) = d + d1 cos Θ.
    D1,
}

/// A term of the model: F = facet term + ideal depolarizer (docs/design.md §1.3).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Term {
    /// P(θ) G M(β) / (4 cosθ cosθ_i cosθ_r): the slope distribution's parameters and N = n + ik.
    Facet,
    /// (ρ_d/π) diag(1, 0, 0, 0): unpolarized diffuse reflection.
    IdealDepolarizer,
    /// (ρ_s/πZ) T(θ_r) L(−η_r) D(d) L(η_i) T(θ_i): light refracted in, scattered inside with a
    /// residual polarization in the scattering plane, and refracted out
    /// (docs/design.md §1.10, `pbrdf::subsurface`).
    Subsurface,
}

/// The term that scatters light from under the surface, beside the facet term.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Body {
    /// [`Term::IdealDepolarizer`] (ρ_d), today's default.
    #[default]
    Depolarizer,
    /// [`Term::Subsurface`] (ρ_s, d).
    Subsurface,
}

impl Body {
    pub const ALL: [Body; 2] = [Body::Depolarizer, Body::Subsurface];

    /// The terms beside the facet term, in the order the model adds them.
    pub fn terms(self) -> &'static [Term] {
        match self {
            Body::Depolarizer => &[Term::IdealDepolarizer],
            Body::Subsurface => &[Term::Subsurface],
        }
    }

    /// The subsurface lobes among [`Body::terms`] (docs/design.md §1.10): none for the ideal
    /// depolarizer. A body with lobes lets light into the material.
    pub fn lobe_terms(self) -> impl Iterator<Item = Term> {
        self.terms().iter().copied().filter(|t| t.lobe().is_some())
    }

    pub fn name(self) -> &'static str {
        match self {
            Body::Depolarizer => "depolarizer",
            Body::Subsurface => "subsurface",
        }
    }
}

/// Which terms a model is made of (docs/design.md §1.10): the facet term on one side of the
/// facets, and one body term. Written `external+depolarizer` (the default, §1.3's model),
/// `external+subsurface`, `internal+subsurface`, `internal+depolarizer`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct ModelTerms {
    pub facet_side: FacetSide,
    pub body: Body,
}

impl ModelTerms {
    /// The combinations a fit chooses among (`--terms all`), the default first. Internal
    /// facets with the ideal depolarizer are left out: for k = 0 they are external facets with
    /// n → 1/n (the same ε), so they only duplicate the default — which is how a volume
    /// scatterer fitted with today's model ends at n < 1.
    pub const ALL: [ModelTerms; 3] = [
        ModelTerms::new(FacetSide::External, Body::Depolarizer),
        ModelTerms::new(FacetSide::External, Body::Subsurface),
        ModelTerms::new(FacetSide::Internal, Body::Subsurface),
    ];

    pub const fn new(facet_side: FacetSide, body: Body) -> ModelTerms {
        ModelTerms { facet_side, body }
    }

    /// Whether `parameter` belongs to one of these terms (the slope parameters also depend on
    /// the distribution: [`super::DistributionKind::has`]).
    pub fn has(&self, parameter: Parameter) -> bool {
        let term = parameter.info().term;
        term == Term::Facet || self.body.terms().contains(&term)
    }

    /// Whether a fit frees `parameter` unless told otherwise (`--free`, `--fix`): every parameter
    /// of the terms except k behind internal facets, held at 0 (docs/design.md §1.10). Light
    /// reflected inside a grain must have crossed the grain to get there, so the grain is
    /// transparent at that wavelength; its absorption along the way is the body's ρ_s, not an
    /// interface property. Left free, k stands in for what the facet model lacks (PTFE at
    /// 1.064 µm, which does not absorb, fits k ≈ 0.07 and an index of 1.23 instead of 1.39).
    pub fn fitted_by_default(&self, parameter: Parameter) -> bool {
        self.has(parameter)
            && !(parameter == Parameter::K && self.facet_side == FacetSide::Internal)
    }

    /// Parses `external+subsurface` and the like (`internal+depolarizer` too).
    pub fn parse(text: &str) -> Option<ModelTerms> {
        ModelTerms::ALL
            .into_iter()
            .chain([ModelTerms::new(FacetSide::Internal, Body::Depolarizer)])
            .find(|t| t.to_string() == text.trim())
    }
}

impl fmt::Display for ModelTerms {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}+{}", self.facet_side.name(), self.body.name())
    }
}

/// Which parameter of a lobe term ([`Term::lobe`]) is which field of [`super::Subsurface`]; a lobe
/// without an `interface_index`, `circular` or `residual_slope` parameter takes that field's
/// default (n, d, 0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LobeParameters {
    pub reflectance: Parameter,
    pub residual: Parameter,
    pub interface_index: Option<Parameter>,
    pub circular: Option<Parameter>,
    pub residual_slope: Option<Parameter>,
}

impl LobeParameters {
    /// The parameters other than the reflectance, in [`Parameter::ALL`] order.
    pub(super) fn dependents(&self) -> impl Iterator<Item = Parameter> {
        [
            Some(self.residual),
            self.interface_index,
            self.circular,
            self.residual_slope,
        ]
        .into_iter()
        .flatten()
    }
}

/// How a parameter varies over the wavelengths of a spectral fit (docs/design.md §1.9–1.10).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SpectralRole {
    /// The surface's geometry: one value for every wavelength, always.
    Shared,
    /// Shared unless the fit is asked for one value per wavelength (`--per-wavelength`).
    SharedByDefault,
    /// One value per wavelength (a material's index, its reflectances).
    PerWavelength,
}

/// What the crate knows about one [`Parameter`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterInfo {
    /// The name on the command line, in material files and in fit records.
    pub key: &'static str,
    /// Further names the command line accepts (`rho` for ρ_d, docs/design.md §4).
    pub aliases: &'static [&'static str],
    /// The flag of `irpol eval` and `emissivity` that gives its value (`--rho-s`).
    pub flag: &'static str,
    /// The symbol in report tables.
    pub label: &'static str,
    pub unit: &'static str,
    /// The term of the model the parameter belongs to.
    pub term: Term,
    /// The values a model accepts ([`limits`]): (lowest, highest, whether the lowest itself is
    /// excluded).
    pub domain: (f64, f64, bool),
    /// The search interval of a fit unless `--bounds` says otherwise.
    pub default_bounds: (f64, f64),
    /// The `#` line above the key in a material file's `[model]`.
    pub comment: &'static str,
    /// Whether a spectral fit shares it across wavelengths.
    pub spectral: SpectralRole,
    /// The value of a parameter that is neither free nor given one: a moderately rough
    /// dielectric without absorption or diffuse part.
    pub default_value: f64,
    /// Where a local search without a global stage starts: inside the box and away from the
    /// k = 0 boundary, where the linear Mueller elements are stationary in k.
    pub start: f64,
    /// How the fit's optimizers see the parameter ([`SearchMap`]).
    pub search: SearchMap,
    /// Which end of its search interval makes a local fit's end point suspect ([`TrapRule`]).
    pub trap: TrapRule,
    /// Where the local stages restart from a trapped end point (`fit::optimize`): smooth,
    /// medium and rough surfaces with low and high index, each with some absorption so that no
    /// restart sits on the k = 0 stationary boundary (only the free parameters are taken).
    pub restarts: [f64; RESTART_COUNT],
}

/// The number of restart points of a trapped local fit ([`ParameterInfo::restarts`]).
pub const RESTART_COUNT: usize = 4;

/// Scale of the asinh search map of k: below ~0.1 the search coordinate is linear in k (k = 0 is
/// an ordinary point), above it logarithmic (metals reach k ≈ 50 in the LWIR).
const K_SEARCH_SCALE: f64 = 0.1;

/// Every parameter's entry, in [`Parameter::ALL`] order.
const REGISTRY: [ParameterInfo; Parameter::COUNT] = [
    ParameterInfo {
        key: "sigma",
        aliases: &[],
        flag: "sigma",
        label: "σ",
        unit: "dimensionless",
        term: Term::Facet,
        domain: (limits::MIN_SIGMA, limits::MAX_SIGMA, false),
        default_bounds: (0.005, 1.5),
        comment: "slope parameter σ (dimensionless): Gaussian rms slope per axis; Cauchy a = 2σ² (q = 2 is GGX, α = √2σ)",
        spectral: SpectralRole::Shared,
        default_value: 0.2,
        start: 0.2,
        search: SearchMap::Log,
        trap: TrapRule::EitherBound,
        restarts: [0.03, 0.1, 0.3, 0.1],
    },
    ParameterInfo {
        key: "q",
        aliases: &[],
        flag: "q",
        label: "q",
        unit: "dimensionless",
        term: Term::Facet,
        // q > 1 is open: the distribution is not normalizable at 1.
        domain: (1.0, limits::MAX_Q, true),
        default_bounds: (1.05, 50.0),
        comment: "Cauchy tail exponent q (> 1; > 1.5 with Smith): small q puts more facets at steep tilts",
        spectral: SpectralRole::Shared,
        default_value: 2.0,
        start: 3.0,
        search: SearchMap::LogAboveOne,
        trap: TrapRule::LowerBound,
        restarts: [3.0, 2.0, 3.0, 8.0],
    },
    ParameterInfo {
        key: "n",
        aliases: &[],
        flag: "n",
        label: "n",
        unit: "dimensionless",
        term: Term::Facet,
        domain: (limits::MIN_N, limits::MAX_N, false),
        default_bounds: (0.05, 10.0),
        comment: "real part n of the complex refractive index N = n + ik at wavelength_um",
        spectral: SpectralRole::PerWavelength,
        default_value: 1.5,
        start: 1.8,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [2.0, 1.5, 1.5, 3.0],
    },
    ParameterInfo {
        key: "k",
        aliases: &[],
        flag: "k",
        label: "k",
        unit: "dimensionless",
        term: Term::Facet,
        domain: (0.0, limits::MAX_K, false),
        default_bounds: (0.0, 50.0),
        comment: "extinction coefficient k (imaginary part of N, ≥ 0): absorption",
        spectral: SpectralRole::PerWavelength,
        default_value: 0.0,
        start: 0.1,
        search: SearchMap::Asinh { scale: K_SEARCH_SCALE },
        trap: TrapRule::Never,
        restarts: [0.1, 0.3, 0.05, 1.0],
    },
    ParameterInfo {
        key: "rho_d",
        aliases: &["rho"],
        flag: "rho",
        label: "ρd",
        unit: "dimensionless",
        term: Term::IdealDepolarizer,
        domain: (0.0, 1.0, false),
        default_bounds: (0.0, 1.0),
        comment: "unpolarized diffuse reflectance ρ_d (0–1): adds ρ_d/π to m00 only",
        spectral: SpectralRole::PerWavelength,
        default_value: 0.0,
        start: 0.02,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [0.01, 0.01, 0.03, 0.01],
    },
    ParameterInfo {
        key: "rho_s",
        aliases: &[],
        flag: "rho-s",
        label: "ρs",
        unit: "dimensionless",
        term: Term::Subsurface,
        domain: (0.0, 1.0, false),
        default_bounds: (0.0, 1.0),
        comment: "subsurface reflectance ρ_s (0–1): the fraction of the light refracted in that comes back out, p-polarized by the interface",
        spectral: SpectralRole::PerWavelength,
        default_value: 0.5,
        start: 0.5,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [0.5, 0.8, 0.3, 0.9],
    },
    ParameterInfo {
        key: "d",
        aliases: &[],
        flag: "d",
        label: "d",
        unit: "dimensionless",
        term: Term::Subsurface,
        domain: (0.0, 1.0, false),
        default_bounds: (0.0, 1.0),
        comment: "residual polarization d (0–1) of the subsurface light: D = diag(1, d, −d, −d) in scattering-plane frames",
        spectral: SpectralRole::SharedByDefault,
        default_value: 0.0,
        start: 0.1,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [0.1, 0.3, 0.05, 0.5],
    },
    ParameterInfo {
        key: "n_sub",
        aliases: &[],
        flag: "n-sub",
        label: "n_sub",
        unit: "dimensionless",
        term: Term::Subsurface,
        domain: (limits::MIN_N, limits::MAX_N, false),
        default_bounds: (1.0, 4.0),
        comment: "real index of the interface the subsurface light crosses (absent: n)",
        spectral: SpectralRole::SharedByDefault,
        default_value: 1.5,
        start: 1.4,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [2.0, 1.5, 1.3, 2.5],
    },
    ParameterInfo {
        key: "d_c",
        aliases: &[],
        flag: "d-c",
        label: "d_c",
        unit: "dimensionless",
        term: Term::Subsurface,
        domain: (-1.0, 1.0, false),
        default_bounds: (-1.0, 1.0),
        comment: "residual circular polarization d_c (−1–1, at least 2d − 1) of the subsurface light: D's m33 = −d_c (absent: d, a mirror's sign; below 0 helicity is kept)",
        spectral: SpectralRole::SharedByDefault,
        default_value: 0.0,
        start: 0.0,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [0.1, -0.1, 0.0, 0.5],
    },
    ParameterInfo {
        key: "d1",
        aliases: &[],
        flag: "d1",
        label: "d1",
        unit: "dimensionless",
        term: Term::Subsurface,
        domain: (-1.0, 1.0, false),
        default_bounds: (-1.0, 1.0),
        comment: "change of the residual polarization with the scattering angle Θ (between the incident and the scattered beam): d(Θ) = d + d1 cos Θ, |d| + |d1| ≤ 1 (absent: 0)",
        spectral: SpectralRole::SharedByDefault,
        default_value: 0.0,
        start: 0.0,
        search: SearchMap::Linear,
        trap: TrapRule::Never,
        restarts: [0.0, 0.0, 0.0, 0.0],
    },
];

/// A parameter value outside the values a model accepts.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("{parameter} = {} is outside {}, the values a model accepts", number(*.value), range(*.parameter))]
pub struct OutsideDomain {
    pub parameter: Parameter,
    pub value: f64,
}

/// "[0.0001, 10]" or "(1, 100]": a parameter's domain as an interval.
fn range(parameter: Parameter) -> String {
    let (low, high, open) = parameter.domain();
    let bracket = if open { '(' } else { '[' };
    format!("{bracket}{}, {}]", number(low), number(high))
}

impl Parameter {
    /// All parameters in their canonical order (the order of vectors and matrices in a fit).
    /// The number of parameters.
    pub const COUNT: usize = 10;

    pub const ALL: [Parameter; Parameter::COUNT] = [
        Parameter::Sigma,
        Parameter::Q,
        Parameter::N,
        Parameter::K,
        Parameter::RhoD,
        Parameter::RhoS,
        Parameter::D,
        Parameter::NSub,
        Parameter::DC,
        Parameter::D1,
    ];

    /// The parameter's entry in the registry.
    pub fn info(&self) -> &'static ParameterInfo {
        &REGISTRY[self.index()]
    }

    /// The name used on the command line and in material files.
    pub fn name(&self) -> &'static str {
        self.info().key
    }

    /// The symbol of report tables ("σ", "ρd").
    pub fn label(&self) -> &'static str {
        self.info().label
    }

    /// Parses a name of [`Parameter::name`] or one of its aliases (`rho` for ρ_d).
    pub fn parse(text: &str) -> Option<Parameter> {
        let text = text.trim();
        Parameter::ALL.into_iter().find(|p| {
            let info = p.info();
            info.key == text || info.aliases.contains(&text)
        })
    }

    /// Position in [`Parameter::ALL`].
    pub fn index(&self) -> usize {
        *self as usize
    }

    /// Whether the parameter belongs to a subsurface lobe ([`Term::lobe`]), whose keys a
    /// material stores by parameter ([`super::LobeKeys`]).
    pub fn is_lobe(&self) -> bool {
        self.info().term.lobe().is_some()
    }

    /// The values a model accepts ([`limits`]): (lowest, highest, whether the lowest itself is
    /// excluded).
    pub fn domain(&self) -> (f64, f64, bool) {
        self.info().domain
    }

    /// Refuses a value outside [`Parameter::domain`] (or not finite), naming the range.
    pub fn check(&self, value: f64) -> Result<(), OutsideDomain> {
        let (low, high, open) = self.domain();
        let above_low = if open { value > low } else { value >= low };
        if value.is_finite() && above_low && value <= high {
            Ok(())
        } else {
            Err(OutsideDomain {
                parameter: *self,
                value,
            })
        }
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Term {
    pub const ALL: [Term; 3] = [Term::Facet, Term::IdealDepolarizer, Term::Subsurface];

    /// The term's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Term::Facet => "facet",
            Term::IdealDepolarizer => "depolarizer",
            Term::Subsurface => "subsurface",
        }
    }

    /// Which of the term's parameters plays which part of a subsurface lobe
    /// ([`super::Subsurface`]); `None` for a term that is not a lobe.
    pub const fn lobe(self) -> Option<LobeParameters> {
        match self {
            Term::Subsurface => Some(LobeParameters {
                reflectance: Parameter::RhoS,
                residual: Parameter::D,
                interface_index: Some(Parameter::NSub),
                circular: Some(Parameter::DC),
                residual_slope: Some(Parameter::D1),
            }),
            Term::Facet | Term::IdealDepolarizer => None,
        }
    }

    /// The parameters of the term, in canonical order (the facet term's slope parameters are
    /// those of every distribution: [`super::DistributionKind::parameters`] says which one has
    /// which).
    pub fn parameters(self) -> impl Iterator<Item = Parameter> {
        Parameter::ALL
            .into_iter()
            .filter(move |p| p.info().term == self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_parse_back_and_every_parameter_has_one_term() {
        for parameter in Parameter::ALL {
            assert_eq!(Parameter::parse(parameter.name()), Some(parameter));
            let owners = Term::ALL
                .iter()
                .filter(|t| t.parameters().any(|p| p == parameter))
                .count();
            assert_eq!(owners, 1, "{parameter}");
            let (low, high) = parameter.info().default_bounds;
            assert!(parameter.check(low).is_ok() && parameter.check(high).is_ok());
        }
        assert_eq!(Parameter::parse(" rho "), Some(Parameter::RhoD));
        assert_eq!(Parameter::parse("alpha"), None);
        // serde's names are the registry's keys.
        for parameter in Parameter::ALL {
            let json = serde_json::to_string(&parameter).unwrap();
            assert_eq!(json, format!("\"{}\"", parameter.name()));
        }
    }
}
