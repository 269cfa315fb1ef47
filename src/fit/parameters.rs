//! The fitted pBRDF parameters (σ, q, n, k, ρ_d of docs/design.md §1.2–1.3), their bounds, and the search
//! coordinates the optimizers work in. The parameters themselves (names, domains, default
//! bounds) are declared in [`crate::pbrdf::terms`]; the table below repeats the bounds to
//! explain the search coordinates.
//!
//! Every optimizer sees a parameter through a smooth, monotone map from the physical value to a
//! *search coordinate* that spreads the parameter's plausible range evenly over a finite box:
//!
//! | parameter | default bounds                      | search coordinate  | why                               |
//! |-----------|-------------------------------------|--------------------|-----------------------------------|
//! | σ         | [0.005, 1.5]                        | ln σ               | roughness spans decades           |
//! | q         | [1.05, 50] ([1.51, 50] with Smith)  | ln(q − 1)          | tail weight goes as 1/(q − 1)     |
//! | n         | [0.05, 10]                          | n                  | below 1 near absorption bands     |
//! | k         | [0, 50]                             | asinh(k / 0.1)     | linear near 0, logarithmic above  |
//! | ρ_d       | [0, 1]                              | ρ_d                | enters m00 linearly               |
//! | ρ_s, d    | [0, 1]                              | ρ_s, d             | enter the subsurface term linearly |
//! | n_sub     | [1, 4]                              | n_sub              | as n                              |
//! | d_c       | [−1, 1]                             | d_c                | enters m33 linearly               |
//! | d1        | [−1, 1]                             | d1                 | as d                              |
//!
//! The genetic stage samples the search box; the local stages add a sine map on top of it
//! (MINUIT's bounded transform) so that Nelder–Mead runs unconstrained and can settle exactly on
//! a bound. The Smith Λ of the Cauchy distribution diverges for q ≤ 3/2 (docs/design.md §1.3), hence the
//! raised lower bound of q with Smith shadowing.

use crate::pbrdf::Shadowing;
pub use crate::pbrdf::{DistributionKind, OutsideDomain, Parameter};
use serde::{Deserialize, Serialize};

/// The fit's own values of each parameter (its name, domain and bounds are in
/// [`crate::pbrdf::terms`]).
impl Parameter {
    /// Value used when the parameter is neither free nor given a value: a moderately rough
    /// dielectric without absorption or diffuse part.
    pub fn default_value(&self) -> f64 {
        match self {
            Parameter::Sigma => 0.2,
            Parameter::Q => 2.0,
            Parameter::N => 1.5,
            Parameter::K => 0.0,
            Parameter::RhoD => 0.0,
            Parameter::RhoS => 0.5,
            Parameter::D => 0.0,
            Parameter::NSub => 1.5,
            Parameter::DC => 0.0,
            Parameter::D1 => 0.0,
        }
    }

    /// Where a local search without a global stage starts: inside the box and away from the
    /// k = 0 boundary, where the linear Mueller elements are stationary in k.
    pub fn starting_value(&self) -> f64 {
        match self {
            Parameter::Sigma => 0.2,
            Parameter::Q => 3.0,
            Parameter::N => 1.8,
            Parameter::K => 0.1,
            Parameter::RhoD => 0.02,
            Parameter::RhoS => 0.5,
            Parameter::D => 0.1,
            Parameter::NSub => 1.4,
            Parameter::DC => 0.0,
            Parameter::D1 => 0.0,
        }
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

/// Bounds of the physical parameters (docs/design.md §1.3). The q interval's lower end is raised to
/// [`SMITH_MIN_Q`] when Smith shadowing is used (see [`ParameterBounds::effective`]).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterBounds {
    pub sigma: Interval,
    pub q: Interval,
    pub n: Interval,
    pub k: Interval,
    pub rho_d: Interval,
    pub rho_s: Interval,
    pub d: Interval,
    pub n_sub: Interval,
    pub d_c: Interval,
    pub d1: Interval,
}

/// Lowest q searched with Smith shadowing: Λ of the Cauchy distribution exists only for q > 3/2
/// and grows without bound as q → 3/2⁺.
pub const SMITH_MIN_Q: f64 = 1.51;

impl Default for ParameterBounds {
    /// The registry's default bounds ([`crate::pbrdf::ParameterInfo::default_bounds`]).
    fn default() -> Self {
        let interval = |p: Parameter| {
            let (lower, upper) = p.info().default_bounds;
            Interval::new(lower, upper)
        };
        ParameterBounds {
            sigma: interval(Parameter::Sigma),
            q: interval(Parameter::Q),
            n: interval(Parameter::N),
            k: interval(Parameter::K),
            rho_d: interval(Parameter::RhoD),
            rho_s: interval(Parameter::RhoS),
            d: interval(Parameter::D),
            n_sub: interval(Parameter::NSub),
            d_c: interval(Parameter::DC),
            d1: interval(Parameter::D1),
        }
    }
}

impl ParameterBounds {
    pub fn get(&self, parameter: Parameter) -> Interval {
        match parameter {
            Parameter::Sigma => self.sigma,
            Parameter::Q => self.q,
            Parameter::N => self.n,
            Parameter::K => self.k,
            Parameter::RhoD => self.rho_d,
            Parameter::RhoS => self.rho_s,
            Parameter::D => self.d,
            Parameter::NSub => self.n_sub,
            Parameter::DC => self.d_c,
            Parameter::D1 => self.d1,
        }
    }

    /// The bounds a fit with `shadowing` searches: q ≥ [`SMITH_MIN_Q`] with Smith.
    pub fn effective(&self, shadowing: Shadowing) -> ParameterBounds {
        let mut bounds = *self;
        if shadowing == Shadowing::Smith {
            bounds.q.lower = bounds.q.lower.max(SMITH_MIN_Q);
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

/// Scale of the asinh map of k: below ~0.1 the search coordinate is linear in k (k = 0 is an
/// ordinary point), above it logarithmic (metals reach k ≈ 50 in the LWIR).
const K_SCALE: f64 = 0.1;

/// The physical value → search coordinate map of a parameter (table in the module docs).
pub fn to_search(parameter: Parameter, value: f64) -> f64 {
    match parameter {
        Parameter::Sigma => value.ln(),
        Parameter::Q => (value - 1.0).ln(),
        Parameter::N
        | Parameter::RhoD
        | Parameter::RhoS
        | Parameter::D
        | Parameter::NSub
        | Parameter::DC
        | Parameter::D1 => value,
        Parameter::K => (value / K_SCALE).asinh(),
    }
}

/// Inverse of [`to_search`].
pub fn from_search(parameter: Parameter, coordinate: f64) -> f64 {
    match parameter {
        Parameter::Sigma => coordinate.exp(),
        Parameter::Q => 1.0 + coordinate.exp(),
        Parameter::N
        | Parameter::RhoD
        | Parameter::RhoS
        | Parameter::D
        | Parameter::NSub
        | Parameter::DC
        | Parameter::D1 => coordinate,
        Parameter::K => K_SCALE * coordinate.sinh(),
    }
}

/// d(value)/d(coordinate) of [`from_search`], to carry Jacobians to physical parameters.
pub fn value_per_coordinate(parameter: Parameter, coordinate: f64) -> f64 {
    match parameter {
        Parameter::Sigma => coordinate.exp(),
        Parameter::Q => coordinate.exp(),
        Parameter::N
        | Parameter::RhoD
        | Parameter::RhoS
        | Parameter::D
        | Parameter::NSub
        | Parameter::DC
        | Parameter::D1 => 1.0,
        Parameter::K => K_SCALE * coordinate.cosh(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!(bounds.effective(Shadowing::Smith).q.lower, SMITH_MIN_Q);
        assert_eq!(bounds.effective(Shadowing::TorranceSparrow).q.lower, 1.05);
        assert!(bounds.validate().is_ok());
        let mut bad = bounds;
        bad.q = Interval::new(0.9, 10.0);
        assert!(bad.validate().unwrap_err().to_string().contains("q"));
        bad = bounds;
        bad.rho_d = Interval::new(0.0, 1.5);
        assert!(bad.validate().is_err());
        bad = bounds;
        bad.sigma = Interval::new(0.01, 1e308);
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
