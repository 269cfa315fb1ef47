//! Why the text of a fit option is refused: [`OptionError`], shared by the option parsers
//! (`options`, `robust`, `stages`, the spectral `Dispersion`), which sit below `options`.

use crate::pbrdf::{OutsideDomain, Parameter};
use crate::text::shown;

/// Why the text of a fit option (`--free`, `--fix`, `--robust`, `--optimizer`, `--dispersion`)
/// is refused. Quoted user text goes through [`shown`] when displayed, so a message stays one
/// line of printable characters whatever was typed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OptionError {
    #[error("unknown parameter '{}' (use sigma, q, n, k, rho_d)", shown(.0))]
    UnknownParameter(String),
    #[error("parameter '{}' is listed twice", shown(.0))]
    ListedTwice(String),
    #[error("the parameter list is empty")]
    EmptyList,
    #[error("'{}' is not name=value (e.g. k=0.1)", shown(.0))]
    NotNameValue(String),
    #[error("the value of {parameter} in '{}' is not a finite number", shown(.pair))]
    NotFinite { parameter: Parameter, pair: String },
    /// A value outside the parameter's domain ([`Parameter::check`]).
    #[error(transparent)]
    OutsideDomain(#[from] OutsideDomain),
    #[error("{0} is given twice")]
    GivenTwice(Parameter),
    #[error("no name=value pair given")]
    NoPairs,
    #[error("robust loss scale '{}' is not a number", shown(.0))]
    RobustScaleNotNumber(String),
    #[error("robust loss scale {} must be finite and > 0", crate::text::number(*.0))]
    RobustScale(f64),
    #[error("unknown robust loss '{}' (huber or cauchy)", shown(.0))]
    UnknownRobustLoss(String),
    #[error("the optimizer needs at least one stage")]
    NoStage,
    #[error("the genetic stage (ga) can only come first")]
    GeneticNotFirst,
    #[error(
        "unknown optimizer stage '{}' in '{}' (use ga, nm, lm joined by +, e.g. ga+nm)",
        shown(.stage),
        shown(.text)
    )]
    UnknownStage { stage: String, text: String },
    #[error(
        "unknown dispersion '{}': use auto, table, cauchy or lorentz:N with N = 1…6 oscillators",
        shown(.0)
    )]
    UnknownDispersion(String),
}
