//! A TOML table must be written as a table. serde's derived `Deserialize` of a struct also
//! accepts a sequence of its fields in order, so `ground = [0.0, 0.0]` was read as a ground at
//! 0 K with emissivity 0, silently. The scene's tables (and those of `[thermal]`) are read through
//! [`table`] and its forms for optional fields, maps and lists, which ask the reader for a map
//! only: a sequence is then "invalid type: sequence, expected a table".

use serde::de::{value::MapAccessDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Deserializer};
use std::collections::BTreeMap;
use std::fmt;
use std::marker::PhantomData;

/// `T` from a table only (`#[serde(deserialize_with = "table")]`).
pub fn table<'de, D, T>(deserializer: D) -> Result<T, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    struct TableVisitor<T>(PhantomData<T>);

    impl<'de, T: Deserialize<'de>> Visitor<'de> for TableVisitor<T> {
        type Value = T;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("a table")
        }

        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<T, A::Error> {
            T::deserialize(MapAccessDeserializer::new(map))
        }
    }

    deserializer.deserialize_map(TableVisitor(PhantomData))
}

/// An item of a map or list that must be a table.
struct Table<T>(T);

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Table<T> {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        table(deserializer).map(Table)
    }
}

/// An optional table (`#[serde(default, deserialize_with = "optional_table")]`).
pub fn optional_table<'de, D, T>(deserializer: D) -> Result<Option<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    table(deserializer).map(Some)
}

/// A sub-table that may also be written as a flag (`dofp = true`, the shorthand for a table of
/// defaults; `dofp = false` for none): `#[serde(default, deserialize_with = "table_or_flag")]`.
pub fn table_or_flag<'de, D, T>(deserializer: D) -> Result<Option<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de> + Default,
{
    struct FlagVisitor<T>(PhantomData<T>);

    impl<'de, T: Deserialize<'de> + Default> Visitor<'de> for FlagVisitor<T> {
        type Value = Option<T>;

        fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
            f.write_str("true, false or a table")
        }

        fn visit_bool<E: serde::de::Error>(self, flag: bool) -> Result<Option<T>, E> {
            Ok(flag.then(T::default))
        }

        fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<Option<T>, A::Error> {
            T::deserialize(MapAccessDeserializer::new(map)).map(Some)
        }
    }

    deserializer.deserialize_any(FlagVisitor(PhantomData))
}

/// Tables by name (`[materials.NAME]`, `[objects.parts.NAME]`, `[thermal.layers.NAME]`).
pub fn table_map<'de, D, T>(deserializer: D) -> Result<BTreeMap<String, T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let map = BTreeMap::<String, Table<T>>::deserialize(deserializer)?;
    Ok(map.into_iter().map(|(k, Table(v))| (k, v)).collect())
}

/// A list of tables (`[[objects]]`).
pub fn table_list<'de, D, T>(deserializer: D) -> Result<Vec<T>, D::Error>
where
    D: Deserializer<'de>,
    T: Deserialize<'de>,
{
    let list = Vec::<Table<T>>::deserialize(deserializer)?;
    Ok(list.into_iter().map(|Table(v)| v).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Debug, Deserialize, PartialEq)]
    #[serde(deny_unknown_fields)]
    struct Ground {
        temperature_k: f64,
        emissivity: f64,
    }

    #[derive(Debug, Deserialize)]
    struct Scene {
        #[serde(deserialize_with = "table")]
        ground: Ground,
        #[serde(default, deserialize_with = "table_map")]
        layers: BTreeMap<String, Ground>,
    }

    #[test]
    fn tables_are_read_and_sequences_refused() {
        let scene: Scene = toml::from_str(
            "ground = { temperature_k = 290.0, emissivity = 0.9 }\n[layers.a]\n\
             temperature_k = 1.0\nemissivity = 0.5\n",
        )
        .unwrap();
        assert_eq!(scene.ground.temperature_k, 290.0);
        assert_eq!(scene.layers["a"].emissivity, 0.5);
        for text in [
            "ground = [0.0, 0.0]",
            "ground = [0.0, 0.0, 0.0]",
            "ground = { temperature_k = 1.0, emissivity = 1.0 }\nlayers = { a = [1.0, 2.0] }",
        ] {
            let error = toml::from_str::<Scene>(text).unwrap_err().to_string();
            assert!(error.contains("expected a table"), "{text}: {error}");
        }
        let error = toml::from_str::<Scene>("ground = { temperature_k = 1.0, e = 1.0 }")
            .unwrap_err()
            .to_string();
        assert!(error.contains("unknown field `e`"), "{error}");
    }
}
