//! What the `irpol` subcommands do, as library functions the thin `main.rs` calls: model
//! selection from flags or a material file, angle sweeps, geometry CSVs and CSV output.

pub mod evaluate;
pub mod render;
pub mod sun;

use crate::material::Material;
use crate::optics::RefractiveIndex;
use crate::pbrdf::{Pbrdf, Shadowing, SlopeDistribution};
use std::path::PathBuf;

/// A pBRDF chosen on the command line: a material file, or parameters.
#[derive(Clone, Debug, Default)]
pub struct ModelArgs {
    pub material: Option<PathBuf>,
    pub distribution: Option<String>,
    pub sigma: Option<f64>,
    pub q: Option<f64>,
    pub n: Option<f64>,
    pub k: Option<f64>,
    pub rho: Option<f64>,
    pub shadowing: Option<String>,
}

impl ModelArgs {
    /// The model: the material's, with `--shadowing` overriding it, or one built from the flags.
    pub fn build(&self) -> anyhow::Result<Pbrdf> {
        let shadowing = match &self.shadowing {
            Some(name) => Some(Shadowing::parse(name).ok_or_else(|| {
                anyhow::anyhow!("unknown shadowing '{name}': use none, torrance-sparrow or smith")
            })?),
            None => None,
        };
        if let Some(path) = &self.material {
            if self.sigma.is_some() || self.q.is_some() || self.n.is_some() || self.k.is_some() {
                anyhow::bail!(
                    "give either --material or model parameters (--sigma --q --n --k), not both"
                );
            }
            let mut spec = Material::load(path)?.model;
            if let Some(shadowing) = shadowing {
                spec.shadowing = shadowing;
            }
            return Ok(spec.pbrdf()?);
        }
        let missing = |flag: &str| anyhow::anyhow!("missing --{flag} (or give --material FILE)");
        let sigma = self.sigma.ok_or_else(|| missing("sigma"))?;
        let distribution = match self.distribution.as_deref().unwrap_or("cauchy") {
            "cauchy" => SlopeDistribution::Cauchy {
                sigma,
                q: self.q.ok_or_else(|| missing("q"))?,
            },
            "gaussian" => {
                if self.q.is_some() {
                    anyhow::bail!("--q applies to the cauchy distribution only");
                }
                SlopeDistribution::Gaussian { sigma }
            }
            other => anyhow::bail!("unknown distribution '{other}': use cauchy or gaussian"),
        };
        let index = RefractiveIndex::new(
            self.n.ok_or_else(|| missing("n"))?,
            self.k.ok_or_else(|| missing("k"))?,
        );
        Ok(Pbrdf::new(
            distribution,
            shadowing.unwrap_or_default(),
            index,
            self.rho.unwrap_or(0.0),
        )?)
    }
}

/// Parses `START:STOP:STEP` (inclusive of STOP within rounding) or a single value.
pub fn parse_sweep(text: &str, name: &str) -> anyhow::Result<Vec<f64>> {
    let parts: Vec<&str> = text.split(':').collect();
    let number = |s: &str| -> anyhow::Result<f64> {
        let value: f64 = s
            .trim()
            .parse()
            .map_err(|_| anyhow::anyhow!("--{name}: '{s}' is not a number"))?;
        if value.is_finite() {
            Ok(value)
        } else {
            anyhow::bail!("--{name}: '{s}' is not finite")
        }
    };
    match parts.as_slice() {
        [single] => Ok(vec![number(single)?]),
        [start, stop, step] => {
            let (start, stop, step) = (number(start)?, number(stop)?, number(step)?);
            if step <= 0.0 || stop < start {
                anyhow::bail!(
                    "--{name}: need STEP > 0 and STOP ≥ START in START:STOP:STEP, got '{text}'"
                );
            }
            let count = ((stop - start) / step + 1e-9).floor() as usize + 1;
            if count > 1_000_000 {
                anyhow::bail!("--{name}: '{text}' asks for {count} values; at most 1000000");
            }
            Ok((0..count).map(|i| start + i as f64 * step).collect())
        }
        _ => anyhow::bail!("--{name}: expected a number or START:STOP:STEP, got '{text}'"),
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
        for bad in ["0:10:0", "10:0:1", "a:1:1", "1:2", "nan", "0:1e9:1e-3"] {
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
    }
}
