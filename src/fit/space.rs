//! The model being fitted: a distribution family and shadowing, which parameters are free, the
//! values of the others, and the box of search coordinates the free ones live in.

use super::parameters::{from_search, to_search, Interval, ParameterBounds, ParameterValues};
use super::FitError;
use crate::material::ModelSpec;
use crate::optics::RefractiveIndex;
use crate::pbrdf::{DistributionKind, Parameter};
use crate::pbrdf::{LobeKeys, ModelError, ModelTerms, Pbrdf, Shadowing, Subsurface};

/// Lowest n searched with the volume terms (see [`ModelSpace::new`]).
pub const VOLUME_MIN_N: f64 = 1.0;

/// A family of pBRDF models with some parameters free (docs/design.md §1.3).
#[derive(Clone, Debug)]
pub struct ModelSpace {
    kind: DistributionKind,
    shadowing: Shadowing,
    terms: ModelTerms,
    free: Vec<Parameter>,
    /// Values of the parameters that are not free (free entries are overwritten).
    base: ParameterValues,
    bounds: ParameterBounds,
    lower: Vec<f64>,
    upper: Vec<f64>,
}

impl ModelSpace {
    /// `free` lists the adjustable parameters (those the family does not have, q for the
    /// Gaussian, are dropped); `base` gives the value of every other one. Fails if nothing is
    /// free or the fixed values do not make a valid model.
    pub fn new(
        kind: DistributionKind,
        shadowing: Shadowing,
        terms: ModelTerms,
        free: &[Parameter],
        base: ParameterValues,
        bounds: &ParameterBounds,
    ) -> Result<ModelSpace, FitError> {
        bounds
            .validate()
            .map_err(|e| FitError::Options(e.to_string()))?;
        let mut bounds = bounds.effective(shadowing);
        if terms != ModelTerms::default() {
            // With the volume terms n must mean the material's index: an n below 1 would make
            // internal facets external ones of index 1/n (the same ε) and, with its own n_sub,
            // the subsurface term could not tell them apart (docs/design.md §1.10).
            let n = bounds.get(Parameter::N);
            let lower = n.lower.max(VOLUME_MIN_N);
            bounds.set(Parameter::N, Interval::new(lower, n.upper.max(lower * 1.5)));
        }
        let free: Vec<Parameter> = Parameter::ALL
            .into_iter()
            .filter(|p| free.contains(p) && kind.has(*p) && terms.has(*p))
            .collect();
        if free.is_empty() {
            return Err(FitError::Options(format!(
                "no free parameter is left for the {kind} model"
            )));
        }
        let (lower, upper) = free
            .iter()
            .map(|&p| {
                let interval = bounds.get(p);
                (to_search(p, interval.lower), to_search(p, interval.upper))
            })
            .unzip();
        let space = ModelSpace {
            kind,
            shadowing,
            terms,
            free,
            base,
            bounds,
            lower,
            upper,
        };
        // The fixed values must make a valid model on their own (e.g. q > 3/2 with Smith).
        let mut probe = base;
        for &p in &space.free {
            let interval = bounds.get(p);
            probe.set(p, 0.5 * (interval.lower + interval.upper));
        }
        space
            .pbrdf(&probe)
            .map_err(|e| FitError::Options(format!("the fixed parameters are invalid: {e}")))?;
        Ok(space)
    }

    pub fn kind(&self) -> DistributionKind {
        self.kind
    }
    pub fn shadowing(&self) -> Shadowing {
        self.shadowing
    }
    pub fn terms(&self) -> ModelTerms {
        self.terms
    }
    /// Free parameters in canonical order: the order of search vectors.
    pub fn free(&self) -> &[Parameter] {
        &self.free
    }
    pub fn dimension(&self) -> usize {
        self.free.len()
    }
    /// Effective bounds (q raised for Smith).
    pub fn bounds(&self) -> &ParameterBounds {
        &self.bounds
    }
    /// Lower corner of the search box.
    pub fn lower(&self) -> &[f64] {
        &self.lower
    }
    /// Upper corner of the search box.
    pub fn upper(&self) -> &[f64] {
        &self.upper
    }

    /// Full parameter values for search coordinates, clamped into the box.
    pub fn values(&self, search: &[f64]) -> ParameterValues {
        let mut values = self.base;
        for (i, &p) in self.free.iter().enumerate() {
            let coordinate = search[i].clamp(self.lower[i], self.upper[i]);
            let interval = self.bounds.get(p);
            // Clamp again: exp/sinh of a bound's coordinate may round just outside it.
            values.set(
                p,
                from_search(p, coordinate).clamp(interval.lower, interval.upper),
            );
        }
        values
    }

    /// Search coordinates of the free parameters of `values`, clamped into the box.
    pub fn search(&self, values: &ParameterValues) -> Vec<f64> {
        self.free
            .iter()
            .enumerate()
            .map(|(i, &p)| to_search(p, values.get(p)).clamp(self.lower[i], self.upper[i]))
            .collect()
    }

    /// The free parameters' values, in [`ModelSpace::free`] order.
    pub fn free_values(&self, values: &ParameterValues) -> Vec<f64> {
        self.free.iter().map(|&p| values.get(p)).collect()
    }

    pub fn pbrdf(&self, values: &ParameterValues) -> Result<Pbrdf, ModelError> {
        let model = Pbrdf::new(
            self.kind.with_parameters(|p| values.get(p)),
            self.shadowing,
            RefractiveIndex::new(values.get(Parameter::N), values.get(Parameter::K)),
            self.body_value(values, Parameter::RhoD),
        )?;
        let lobes = self.lobes(values);
        if lobes.is_empty() && self.terms == ModelTerms::default() {
            Ok(model)
        } else {
            model.with_volume(self.terms.facet_side, lobes)
        }
    }

    /// A body term's parameter: its value where the family has the term, else 0.
    fn body_value(&self, values: &ParameterValues, parameter: Parameter) -> f64 {
        if self.terms.has(parameter) {
            values.get(parameter)
        } else {
            0.0
        }
    }

    /// The family's subsurface lobes at `values`, every key of each one given.
    fn lobes(&self, values: &ParameterValues) -> Vec<Subsurface> {
        self.terms
            .body
            .lobe_terms()
            .filter_map(|term| {
                Subsurface::from_keys(term, |p| Some(values.get(p))).expect("ρ_s is given")
            })
            .collect()
    }

    pub fn model_spec(&self, values: &ParameterValues, wavelength_um: f64) -> ModelSpec {
        let mut lobe_keys = LobeKeys::default();
        for (parameter, value) in self.lobes(values).iter().flat_map(Subsurface::keys) {
            lobe_keys.set(parameter, Some(value));
        }
        ModelSpec {
            distribution: self.kind.with_parameters(|p| values.get(p)),
            shadowing: self.shadowing,
            n: values.get(Parameter::N),
            k: values.get(Parameter::K),
            rho_d: self.body_value(values, Parameter::RhoD),
            facet: self.terms.facet_side,
            lobe_keys,
            wavelength_um,
        }
    }
}
