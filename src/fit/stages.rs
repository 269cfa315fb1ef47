//! The optimizer stages of a fit and the record each leaves behind (its convergence history).

use super::option_error::OptionError;
use serde::{Deserialize, Serialize};
use std::fmt;

/// One optimizer stage.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Stage {
    /// Genetic algorithm over the whole search box (global; [`super::genetic`]).
    Ga,
    /// Nelder–Mead simplex (local, derivative-free; argmin's `NelderMead`).
    Nm,
    /// Levenberg–Marquardt on the residual vector (local, quadratic convergence).
    Lm,
}

impl Stage {
    pub fn name(&self) -> &'static str {
        match self {
            Stage::Ga => "ga",
            Stage::Nm => "nm",
            Stage::Lm => "lm",
        }
    }
}

impl fmt::Display for Stage {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A sequence of stages, each starting from the previous one's best point, written as names
/// joined by `+`: `ga+lm` (default), `ga+nm`, `ga`, `nm`, `lm`, `ga+nm+lm`, …
///
/// Why `ga+lm` by default: on the shipped measurements Nelder–Mead needs 500–1700 model
/// evaluations to polish what Levenberg–Marquardt polishes in 25–150, to the same χ² (within
/// 1e-10 relative), and LM's Jacobian is the one the uncertainties use.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Optimizer(Vec<Stage>);

impl Optimizer {
    pub fn new(stages: Vec<Stage>) -> Result<Optimizer, OptionError> {
        if stages.is_empty() {
            return Err(OptionError::NoStage);
        }
        if stages.iter().skip(1).any(|s| *s == Stage::Ga) {
            return Err(OptionError::GeneticNotFirst);
        }
        Ok(Optimizer(stages))
    }

    pub fn parse(text: &str) -> Result<Optimizer, OptionError> {
        let stages = text
            .split('+')
            .map(|name| match name.trim() {
                "ga" => Ok(Stage::Ga),
                "nm" => Ok(Stage::Nm),
                "lm" => Ok(Stage::Lm),
                other => Err(OptionError::UnknownStage {
                    stage: other.to_owned(),
                    text: text.to_owned(),
                }),
            })
            .collect::<Result<Vec<_>, _>>()?;
        Optimizer::new(stages)
    }

    pub fn stages(&self) -> &[Stage] {
        &self.0
    }

    /// Whether the first stage is a local search, which then starts from a given point.
    pub fn starts_locally(&self) -> bool {
        self.0[0] != Stage::Ga
    }
}

impl Default for Optimizer {
    fn default() -> Self {
        Optimizer(vec![Stage::Ga, Stage::Lm])
    }
}

impl fmt::Display for Optimizer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.0.iter().map(Stage::name).collect();
        f.write_str(&names.join("+"))
    }
}

/// What one stage did: its best cost after its initialization and after each iteration (one
/// generation of the GA, one simplex step of Nelder–Mead, one accepted or rejected LM step),
/// the work it took and why it stopped.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StageHistory {
    pub stage: Stage,
    /// Best cost so far, non-increasing.
    pub best_cost: Vec<f64>,
    pub iterations: u64,
    pub evaluations: u64,
    pub termination: String,
}

/// The history of every stage of one fit (and of every start of a multistart), in run order.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ConvergenceHistory {
    pub stages: Vec<StageHistory>,
}

impl ConvergenceHistory {
    pub fn iterations(&self) -> u64 {
        self.stages.iter().map(|s| s.iterations).sum()
    }
    pub fn evaluations(&self) -> u64 {
        self.stages.iter().map(|s| s.evaluations).sum()
    }
    /// The best cost so far after every recorded step of every stage, in run order (restarts
    /// included, so the curve never rises), and how many leading entries belong to the
    /// global (GA) stage.
    pub fn best_cost_trace(&self) -> (Vec<f64>, usize) {
        let mut best = f64::INFINITY;
        let mut trace = Vec::new();
        for stage in &self.stages {
            for &cost in &stage.best_cost {
                best = best.min(cost);
                trace.push(best);
            }
        }
        let global = self
            .stages
            .iter()
            .take_while(|s| s.stage == Stage::Ga)
            .map(|s| s.best_cost.len())
            .sum();
        (trace, global)
    }

    /// Termination reason of the last stage.
    pub fn termination(&self) -> String {
        self.stages
            .last()
            .map(|s| format!("{}: {}", s.stage, s.termination))
            .unwrap_or_default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn optimizer_names_parse_and_print() {
        assert_eq!(Optimizer::default().to_string(), "ga+lm");
        let o = Optimizer::parse("ga+nm+lm").unwrap();
        assert_eq!(o.stages(), &[Stage::Ga, Stage::Nm, Stage::Lm]);
        assert!(!o.starts_locally());
        assert!(Optimizer::parse("nm").unwrap().starts_locally());
        assert!(Optimizer::parse("nm+ga")
            .unwrap_err()
            .to_string()
            .contains("first"));
        assert!(Optimizer::parse("ga+bfgs")
            .unwrap_err()
            .to_string()
            .contains("bfgs"));
    }
}
