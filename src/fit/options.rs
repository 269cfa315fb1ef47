//! What a fit is asked to do (the options of `irpol fit`, docs/design.md §4).

use super::optimize::OptimizerSettings;
use super::option_error::OptionError;
use super::parameters::{ParameterBounds, ParameterValues};
use super::robust::RobustLoss;
use super::stages::Optimizer;
use super::FitError;
use crate::pbrdf::{DistributionKind, Parameter};
use crate::pbrdf::{ModelTerms, Shadowing, SpectralRole};
use std::collections::BTreeMap;

/// Options of [`super::fit_measurement`].
#[derive(Clone, Debug, PartialEq)]
pub struct FitOptions {
    /// The slope distribution to fit; `None` fits both, keeps the one the data prefer (AIC) and
    /// records the other as the alternative.
    pub distribution: Option<DistributionKind>,
    /// Shadowing of the fitted model (default Smith, which generated the shipped measurements).
    pub shadowing: Shadowing,
    /// The terms of the fitted model (docs/design.md §1.10); default §1.3's facets + ρ_d.
    pub terms: ModelTerms,
    /// Several sets of terms to choose among (`--terms a,b`), by AIC or by cross-validation;
    /// empty: fit `terms` alone.
    pub term_candidates: Vec<ModelTerms>,
    /// K of K-fold cross-validation (`--cv K`), reported beside AIC and deciding the terms.
    pub cv_folds: Option<usize>,
    /// The default choice of terms (`irpol fit` without `--terms`, docs/design.md §1.10):
    /// without `cv_folds`, the candidates are cross-validated with
    /// [`super::cross_validation::DEFAULT_FOLDS`] where the set is large enough, else compared
    /// by AIC.
    pub choose_terms: bool,
    /// Adjustable parameters; `None` = every parameter the terms fit by default
    /// ([`ModelTerms::fitted_by_default`]) that is not in `fixed`. q is ignored for the Gaussian.
    pub free: Option<Vec<Parameter>>,
    /// Values of parameters held fixed. A parameter neither free nor here takes
    /// [`Parameter::default_value`].
    pub fixed: BTreeMap<Parameter, f64>,
    /// Where the first stage starts (the GA's first individual, or the local search's start),
    /// per free parameter; [`Parameter::starting_value`] for the ones not given.
    pub start: BTreeMap<Parameter, f64>,
    pub optimizer: Optimizer,
    /// Seed of the genetic stage (the local stages are deterministic).
    pub seed: u64,
    /// Robust loss on the normalized residuals (off by default).
    pub robust: Option<RobustLoss>,
    pub bounds: ParameterBounds,
    pub settings: OptimizerSettings,
    /// How n, k depend on wavelength when a material was measured at several (docs/design.md §1.9).
    pub dispersion: super::Dispersion,
    /// Parameters a spectral fit frees at each wavelength that it would otherwise share
    /// ([`SpectralRole::SharedByDefault`]: the subsurface term's d, n_sub, d_c).
    pub per_wavelength: Vec<Parameter>,
    /// The longest fit started without a word (`--max-minutes`): a fit estimated longer
    /// (src/fit/cost.rs) is refused before any work, naming its factors.
    pub max_minutes: f64,
}

/// The longest fit started without a word unless [`FitOptions::max_minutes`] says otherwise
/// (src/fit/cost.rs).
pub const DEFAULT_MAX_MINUTES: f64 = 60.0;

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            distribution: None,
            shadowing: Shadowing::Smith,
            terms: ModelTerms::default(),
            term_candidates: Vec::new(),
            cv_folds: None,
            choose_terms: false,
            free: None,
            fixed: BTreeMap::new(),
            start: BTreeMap::new(),
            optimizer: Optimizer::default(),
            seed: 0,
            robust: None,
            bounds: ParameterBounds::default(),
            settings: OptimizerSettings::default(),
            dispersion: super::Dispersion::Table,
            per_wavelength: Vec::new(),
            max_minutes: DEFAULT_MAX_MINUTES,
        }
    }
}

impl FitOptions {
    /// The distributions to fit: the requested one, or every family in
    /// [`DistributionKind::ALL`] order.
    pub fn distributions(&self) -> Vec<DistributionKind> {
        match self.distribution {
            Some(kind) => vec![kind],
            None => DistributionKind::ALL.to_vec(),
        }
    }

    /// The free parameters (before dropping the ones a family lacks), checked against `fixed`.
    pub fn free_parameters(&self) -> Result<Vec<Parameter>, FitError> {
        match &self.free {
            None => Ok(Parameter::ALL
                .into_iter()
                .filter(|p| self.terms.fitted_by_default(*p) && !self.fixed.contains_key(p))
                .collect()),
            Some(free) => {
                if let Some(p) = free.iter().find(|p| self.fixed.contains_key(p)) {
                    return Err(FitError::Options(format!(
                        "{p} is both free and fixed; drop it from --free or from --fix"
                    )));
                }
                Ok(free.clone())
            }
        }
    }

    /// These options with `terms` as the model's terms.
    pub fn with_terms(&self, terms: ModelTerms) -> FitOptions {
        FitOptions {
            terms,
            ..self.clone()
        }
    }

    /// Whether a spectral fit gives `parameter` one value for every wavelength
    /// (docs/design.md §1.10: geometry always; the subsurface's d, n_sub, d_c unless
    /// [`FitOptions::per_wavelength`] names them).
    pub fn shared_across_wavelengths(&self, parameter: Parameter) -> bool {
        match parameter.info().spectral {
            SpectralRole::Shared => true,
            SpectralRole::SharedByDefault => !self.per_wavelength.contains(&parameter),
            SpectralRole::PerWavelength => false,
        }
    }

    /// Values of every parameter that is not free: the fixed values, else the defaults.
    pub fn base_values(&self) -> ParameterValues {
        let mut values = ParameterValues(Parameter::ALL.map(|p| p.default_value()));
        for (&p, &v) in &self.fixed {
            values.set(p, v);
        }
        values
    }
}

/// Parses a comma-separated parameter list such as `sigma,q,n` (`--free`).
pub fn parse_parameter_list(text: &str) -> Result<Vec<Parameter>, OptionError> {
    let mut list = Vec::new();
    for name in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let parameter =
            Parameter::parse(name).ok_or_else(|| OptionError::UnknownParameter(name.to_owned()))?;
        if list.contains(&parameter) {
            return Err(OptionError::ListedTwice(name.to_owned()));
        }
        list.push(parameter);
    }
    if list.is_empty() {
        return Err(OptionError::EmptyList);
    }
    Ok(list)
}

/// Parses comma-separated `name=value` pairs such as `k=0.1,rho=0` (`--fix`).
pub fn parse_parameter_values(text: &str) -> Result<BTreeMap<Parameter, f64>, OptionError> {
    let mut values = BTreeMap::new();
    for pair in text.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let (name, value) = pair
            .split_once('=')
            .ok_or_else(|| OptionError::NotNameValue(pair.to_owned()))?;
        let parameter = Parameter::parse(name)
            .ok_or_else(|| OptionError::UnknownParameter(name.trim().to_owned()))?;
        let value: f64 = value
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| OptionError::NotFinite {
                parameter,
                pair: pair.to_owned(),
            })?;
        parameter.check(value).map_err(OptionError::OutsideDomain)?;
        if values.insert(parameter, value).is_some() {
            return Err(OptionError::GivenTwice(parameter));
        }
    }
    if values.is_empty() {
        return Err(OptionError::NoPairs);
    }
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn free_parameters_default_to_everything_not_fixed() {
        let mut options = FitOptions {
            fixed: parse_parameter_values("k=0.1, rho=0").unwrap(),
            ..FitOptions::default()
        };
        assert_eq!(
            options.free_parameters().unwrap(),
            vec![Parameter::Sigma, Parameter::Q, Parameter::N]
        );
        assert_eq!(options.base_values().get(Parameter::K), 0.1);
        assert_eq!(options.base_values().get(Parameter::N), 1.5);
        options.free = Some(parse_parameter_list("sigma,k").unwrap());
        assert!(options
            .free_parameters()
            .unwrap_err()
            .to_string()
            .contains("both free and fixed"));
    }

    #[test]
    fn lists_and_values_are_checked() {
        assert!(parse_parameter_list("sigma,sigma").is_err());
        assert_eq!(
            parse_parameter_list("sigma,alpha").unwrap_err().to_string(),
            "unknown parameter 'alpha' (use sigma, q, n, k, rho_d)"
        );
        assert!(parse_parameter_list("").is_err());
        assert!(parse_parameter_values("k:0.1").is_err());
        assert!(parse_parameter_values("k=abc").is_err());
        assert!(parse_parameter_values("k=inf").is_err());
        assert!(parse_parameter_values("k=1,k=2").is_err());
        assert!(parse_parameter_values("sigma=1e308")
            .unwrap_err()
            .to_string()
            .contains("sigma = 1e308 is outside"));
        assert!(parse_parameter_values("q=0.5").is_err());
        assert_eq!(parse_parameter_values("n=2.2").unwrap()[&Parameter::N], 2.2);
    }
}
