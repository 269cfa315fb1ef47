//! The fitted pBRDF parameters' values, their bounds, and the search coordinates the optimizers
//! work in. What each parameter *is* — its name, domain, default search interval, default and
//! starting value, search map and trap rule — is declared once in the registry
//! ([`crate::pbrdf::terms`]); this module stores values and intervals keyed by parameter and reads
//! the registry for everything else.
//!
//! Every optimizer sees a parameter through a smooth, monotone map from the physical value to a
//! *search coordinate* ([`crate::pbrdf::SearchMap`]) that spreads the parameter's plausible range
//! evenly over a finite box: ln σ (roughness spans decades), ln(q − 1) (the tail weight goes as
//! 1/(q − 1)), asinh(k / 0.1) (linear near 0, logarithmic above), the value itself for the
//! indices, reflectances and residual polarizations, which enter the Mueller elements (nearly)
//! linearly. The genetic stage samples the search box; the local stages add a sine map on top of
//! it (MINUIT's bounded transform) so that Nelder–Mead runs unconstrained and can settle exactly
//! on a bound. The Smith Λ of the Cauchy distribution diverges for q ≤ 3/2 (docs/design.md
//! §1.3), hence the raised lower bound of q with Smith shadowing.

use crate::pbrdf::Parameter;
use crate::pbrdf::Shadowing;
use serde::{Deserialize, Serialize};

impl Parameter {
    /// The value of a parameter that is neither free nor given one
    /// ([`crate::pbrdf::ParameterInfo::default_value`]).
    pub fn default_value(&self) -> f64 {
        self.info().default_value
    }

    /// Where a local search without a global stage starts
    /// ([`crate::pbrdf::ParameterInfo::start`]).
    pub fn starting_value(&self) -> f64 {
        self.info().start
    }
}

/// One value per [`Parameter`], in canonical order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterValues(pub [f64; Parameter::COUNT]);

impl ParameterValues {
    pub fn get(&self, parameter: Parameter) -> f64 {
        self.0[parameter.index()]
    }
    pub fn set(&mut self, parameter: Parameter, value: f64) {
        self.0[parameter.index()] = value;
    }
}

/// Closed interval [lower, upper] of physical values of one parameter.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    pub lower: f64,
    pub upper: f64,
}

impl Interval {
    pub const fn new(lower: f64, upper: f64) -> Interval {
        Interval { lower, upper }
    }
    pub fn contains(&self, value: f64) -> bool {
        (self.lower..=self.upper).contains(&value)
    }
}

/// Bounds of the physical parameters (docs/design.md §1.3), one [`Interval`] per [`Parameter`]
/// in canonical order. The q interval's lower end is raised to [`SMITH_MIN_Q`] when Smith
/// shadowing is used (see [`ParameterBounds::effective`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParameterBounds([Interval; Parameter::COUNT]);

/// Lowest q searched with Smith shadowing: Λ of the Cauchy distribution exists only for q > 3/2
/// and grows without bound as q → 3/2⁺.
pub const SMITH_MIN_Q: f64 = 1.51;

impl Default for ParameterBounds {
    /// The registry's default bounds ([`crate::pbrdf::ParameterInfo::default_bounds`]).
    fn default() -> Self {
        ParameterBounds(Parameter::ALL.map(|p| {
            let (lower, upper) = p.info().default_bounds;
            Interval::new(lower, upper)
        }))
    }
}

impl ParameterBounds {
    pub fn get(&self, parameter: Parameter) -> Interval {
        self.0[parameter.index()]
    }

    pub fn set(&mut self, parameter: Parameter, interval: Interval) {
        self.0[parameter.index()] = interval;
    }

    /// The bounds a fit with `shadowing` searches: q ≥ [`SMITH_MIN_Q`] with Smith.
    pub fn effective(&self, shadowing: Shadowing) -> ParameterBounds {
        let mut bounds = *self;
        if shadowing == Shadowing::Smith {
            let q = bounds.get(Parameter::Q);
            bounds.set(
                Parameter::Q,
                Interval::new(q.lower.max(SMITH_MIN_Q), q.upper),
            );
        }
        bounds
    }

    /// Checks that every interval is finite, ordered and inside the parameter's
    /// [`Parameter::domain`].
    pub fn validate(&self) -> Result<(), InvalidBounds> {
        for parameter in Parameter::ALL {
            let Interval { lower, upper } = self.get(parameter);
            let domain_ok = parameter.check(lower).is_ok() && parameter.check(upper).is_ok();
            if !(lower < upper && domain_ok) {
                return Err(InvalidBounds {
                    parameter,
                    lower,
                    upper,
                });
            }
        }
        Ok(())
    }
}

/// A search interval that is not finite, not ordered or outside the parameter's domain.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
#[error("the bounds [{lower}, {upper}] of {parameter} are invalid (finite, lower < upper, inside the parameter's domain)")]
pub struct InvalidBounds {
    pub parameter: Parameter,
    pub lower: f64,
    pub upper: f64,
}

/// The physical value → search coordinate map of a parameter (its registry entry's
/// [`crate::pbrdf::SearchMap`]).
pub fn to_search(parameter: Parameter, value: f64) -> f64 {
    parameter.info().search.to_search(value)
}

/// Inverse of [`to_search`].
pub fn from_search(parameter: Parameter, coordinate: f64) -> f64 {
    parameter.info().search.from_search(coordinate)
}

/// d(value)/d(coordinate) of [`from_search`], to carry Jacobians to physical parameters.
pub fn value_per_coordinate(parameter: Parameter, coordinate: f64) -> f64 {
    parameter.info().search.value_per_coordinate(coordinate)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pbrdf::DistributionKind;

    #[test]
    fn search_coordinates_round_trip_and_have_the_right_slope() {
        for (parameter, value) in [
            (Parameter::Sigma, 0.137),
            (Parameter::Q, 1.8),
            (Parameter::N, 2.4),
            (Parameter::K, 0.0),
            (Parameter::K, 37.0),
            (Parameter::RhoD, 0.03),
        ] {
            let s = to_search(parameter, value);
            assert!((from_search(parameter, s) - value).abs() < 1e-13 * value.max(1.0));
            let h = 1e-6;
            let numeric =
                (from_search(parameter, s + h) - from_search(parameter, s - h)) / (2.0 * h);
            let analytic = value_per_coordinate(parameter, s);
            assert!((numeric / analytic - 1.0).abs() < 1e-8, "{parameter}");
        }
        // k's map is linear near 0: k = 0.01 sits at coordinate ≈ 0.1.
        assert!((to_search(Parameter::K, 0.01) - 0.0998).abs() < 1e-3);
    }

    #[test]
    fn smith_raises_the_lower_bound_of_q_and_bad_bounds_are_refused() {
        let bounds = ParameterBounds::default();
        let q_lower = |b: ParameterBounds| b.get(Parameter::Q).lower;
        assert_eq!(q_lower(bounds.effective(Shadowing::Smith)), SMITH_MIN_Q);
        assert_eq!(q_lower(bounds.effective(Shadowing::TorranceSparrow)), 1.05);
        assert!(bounds.validate().is_ok());
        let mut bad = bounds;
        bad.set(Parameter::Q, Interval::new(0.9, 10.0));
        assert!(bad.validate().unwrap_err().to_string().contains("q"));
        bad = bounds;
        bad.set(Parameter::RhoD, Interval::new(0.0, 1.5));
        assert!(bad.validate().is_err());
        bad = bounds;
        bad.set(Parameter::Sigma, Interval::new(0.01, 1e308));
        assert!(bad.validate().is_err());
        assert!(Parameter::Sigma
            .check(1e308)
            .unwrap_err()
            .to_string()
            .contains("[0.0001, 10]"));
        assert!(Parameter::Q
            .check(1.0)
            .unwrap_err()
            .to_string()
            .contains("(1, 100]"));
        assert!(Parameter::Q.check(100.0).is_ok() && Parameter::K.check(0.0).is_ok());
    }

    #[test]
    fn names_parse_back() {
        for parameter in Parameter::ALL {
            assert_eq!(Parameter::parse(parameter.name()), Some(parameter));
        }
        assert_eq!(Parameter::parse("rho"), Some(Parameter::RhoD));
        assert_eq!(Parameter::parse("alpha"), None);
        assert!(!DistributionKind::Gaussian.has(Parameter::Q));
        assert_eq!(
            DistributionKind::parse("cauchy").unwrap().other(),
            DistributionKind::Gaussian
        );
    }
}
