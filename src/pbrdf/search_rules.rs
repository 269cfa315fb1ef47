//! How a fit's optimizers see a parameter ([`super::ParameterInfo::search`],
//! [`super::ParameterInfo::trap`]): the map to the coordinate they search in, and which bound of
//! the search interval marks a local fit as trapped.

/// The smooth, monotone map from a parameter's value to the *search coordinate* a fit's
/// optimizers work in, chosen so that the parameter's plausible range spreads evenly over the
/// search box.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SearchMap {
    /// The value itself: parameters that enter the Mueller elements (nearly) linearly.
    Linear,
    /// ln v: a parameter that spans decades (roughness).
    Log,
    /// ln(v − 1): a tail exponent whose tail weight goes as 1/(v − 1).
    LogAboveOne,
    /// asinh(v / scale): linear below ~scale (0 is an ordinary point), logarithmic above.
    Asinh { scale: f64 },
}

impl SearchMap {
    /// The search coordinate of `value`.
    pub fn to_search(self, value: f64) -> f64 {
        match self {
            SearchMap::Linear => value,
            SearchMap::Log => value.ln(),
            SearchMap::LogAboveOne => (value - 1.0).ln(),
            SearchMap::Asinh { scale } => (value / scale).asinh(),
        }
    }

    /// Inverse of [`SearchMap::to_search`].
    pub fn from_search(self, coordinate: f64) -> f64 {
        match self {
            SearchMap::Linear => coordinate,
            SearchMap::Log => coordinate.exp(),
            SearchMap::LogAboveOne => 1.0 + coordinate.exp(),
            SearchMap::Asinh { scale } => scale * coordinate.sinh(),
        }
    }

    /// d(value)/d(coordinate) of [`SearchMap::from_search`], to carry Jacobians to values.
    pub fn value_per_coordinate(self, coordinate: f64) -> f64 {
        match self {
            SearchMap::Linear => 1.0,
            SearchMap::Log | SearchMap::LogAboveOne => coordinate.exp(),
            SearchMap::Asinh { scale } => scale * coordinate.cosh(),
        }
    }
}

/// Which bound of its search interval, reached by a local fit, marks the fit as trapped in a
/// degenerate shape (a surface of no slope or all slope, a tail that holds every facet) and
/// sends the local stages to restart elsewhere (`fit::optimize`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TrapRule {
    /// Either bound is an ordinary answer (an index, a reflectance).
    Never,
    /// Both bounds are degenerate (σ).
    EitherBound,
    /// The lower bound is degenerate (q → 1: all facets in the tail).
    LowerBound,
}

impl TrapRule {
    /// Whether a point at the lower (`at_lower`) or the upper (`at_upper`) bound is a trap.
    pub fn traps(self, at_lower: bool, at_upper: bool) -> bool {
        match self {
            TrapRule::Never => false,
            TrapRule::EitherBound => at_lower || at_upper,
            TrapRule::LowerBound => at_lower,
        }
    }
}
