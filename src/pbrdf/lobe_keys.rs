//! The keys of a model's subsurface lobes (docs/design.md §1.10) as a material file, a scene's
//! inline material or the command line writes them: values stored by [`Parameter`], present
//! where written, so that the readers, writers and flags name no lobe parameter themselves and a
//! new lobe term is an entry of the registry (`super::terms`).

use super::subsurface::{LobeKeysWithoutReflectance, Subsurface};
use super::terms::{Body, Parameter, Term};
use serde::de::{Error as _, MapAccess};
use serde::ser::{Serialize, SerializeMap, Serializer};

/// The values of the lobe terms' parameters that are written, `V` a number (a grey model) or a
/// spectral table.
#[derive(Clone, Debug, PartialEq)]
pub struct LobeKeys<V> {
    values: [Option<V>; Parameter::COUNT],
}

impl<V> Default for LobeKeys<V> {
    fn default() -> LobeKeys<V> {
        LobeKeys {
            values: std::array::from_fn(|_| None),
        }
    }
}

/// The lobe parameters, in [`Parameter::ALL`] order.
pub fn lobe_parameters() -> impl Iterator<Item = Parameter> {
    Parameter::ALL.into_iter().filter(Parameter::is_lobe)
}

impl<V> LobeKeys<V> {
    /// The value of `parameter` where written (`None` also for a parameter of no lobe).
    pub fn get(&self, parameter: Parameter) -> Option<&V> {
        self.values[parameter.index()].as_ref()
    }

    /// Writes (`Some`) or removes (`None`) the value of a lobe parameter.
    pub fn set(&mut self, parameter: Parameter, value: Option<V>) {
        debug_assert!(parameter.is_lobe(), "{parameter} is no lobe's");
        self.values[parameter.index()] = value;
    }

    /// The written keys, in [`Parameter::ALL`] order.
    pub fn iter(&self) -> impl Iterator<Item = (Parameter, &V)> {
        Parameter::ALL
            .into_iter()
            .filter_map(|p| self.get(p).map(|v| (p, v)))
    }

    /// Each written value taken through `f`.
    pub fn map<W>(&self, mut f: impl FnMut(Parameter, &V) -> W) -> LobeKeys<W> {
        let mut mapped = LobeKeys::default();
        for (p, v) in self.iter() {
            mapped.values[p.index()] = Some(f(p, v));
        }
        mapped
    }

    /// The lobe terms whose reflectance is written, in [`Term::ALL`] order.
    fn present_terms(&self) -> impl Iterator<Item = Term> + '_ {
        Term::ALL.into_iter().filter(|t| {
            t.lobe()
                .is_some_and(|lobe| self.get(lobe.reflectance).is_some())
        })
    }

    /// The body term the keys describe: the one whose lobes are those written (the ideal
    /// depolarizer when none is).
    pub fn body(&self) -> Body {
        Body::ALL
            .into_iter()
            .find(|b| b.lobe_terms().eq(self.present_terms()))
            .unwrap_or_default()
    }
}

impl LobeKeys<f64> {
    /// The lobes the keys describe, in [`Term::ALL`] order; refuses a lobe's keys without its
    /// reflectance.
    pub fn lobes(&self) -> Result<Vec<Subsurface>, LobeKeysWithoutReflectance> {
        let mut lobes = Vec::new();
        for term in Term::ALL {
            if let Some(lobe) = Subsurface::from_keys(term, |p| self.get(p).copied())? {
                lobes.push(lobe);
            }
        }
        Ok(lobes)
    }

    /// The keys with each lobe's d written (0 where absent), as a grey model stores them.
    pub fn with_residuals(mut self) -> Result<LobeKeys<f64>, LobeKeysWithoutReflectance> {
        for lobe in self.lobes()? {
            let residual = lobe.term.lobe().expect("a lobe term").residual;
            self.set(residual, Some(lobe.d));
        }
        Ok(self)
    }
}

/// The keys as entries of the table they are flattened into, in [`Parameter::ALL`] order.
impl<V: Serialize> Serialize for LobeKeys<V> {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        let mut map = serializer.serialize_map(None)?;
        for (parameter, value) in self.iter() {
            map.serialize_entry(parameter.name(), value)?;
        }
        map.end()
    }
}

/// The field names a table reader lists when it refuses an unknown key: its own `fixed` ones,
/// then the lobe parameters' (kept by the reader in a `static`, as serde wants a `'static`
/// list).
pub fn table_fields(fixed: &[&'static str]) -> Vec<&'static str> {
    fixed
        .iter()
        .copied()
        .chain(lobe_parameters().map(|p| p.name()))
        .collect()
}

/// Reads every entry of a table being deserialized that holds lobe keys beside its own (a
/// material's `[model]`, a scene's inline material): `own` takes a key of the table's own and
/// says whether it was one, the lobes' keys are returned, and any other key is refused by name
/// with `fields`, the whole list ([`table_fields`]).
pub fn read_table<'de, A, V>(
    mut map: A,
    fields: &'static [&'static str],
    mut own: impl FnMut(&str, &mut A) -> Result<bool, A::Error>,
) -> Result<LobeKeys<V>, A::Error>
where
    A: MapAccess<'de>,
    V: serde::Deserialize<'de>,
{
    let mut keys = LobeKeys::default();
    while let Some(key) = map.next_key::<String>()? {
        if own(&key, &mut map)? {
            continue;
        }
        match lobe_parameters().find(|p| p.name() == key) {
            Some(parameter) => keys.set(parameter, Some(map.next_value()?)),
            None => return Err(A::Error::unknown_field(&key, fields)),
        }
    }
    Ok(keys)
}
