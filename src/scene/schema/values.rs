//! Value types and deserialisers the scene format's parts share: scale factors, field defaults,
//! maps without repeated keys, fixed-length number lists.

use std::collections::BTreeMap;

use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

use super::Vec3Spec;

/// A uniform or per-axis scale factor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(
    untagged,
    expecting = "a scale factor `s` or a per-axis triple `(x, y, z)`"
)]
pub enum ScaleSpec {
    /// The same factor on every axis.
    Uniform(f32),
    /// One factor per axis.
    PerAxis(Vec3Spec),
}

impl ScaleSpec {
    /// The factor per axis.
    #[must_use]
    pub fn factors(&self) -> Vec3Spec {
        match *self {
            ScaleSpec::Uniform(s) => [s; 3],
            ScaleSpec::PerAxis(v) => v,
        }
    }
}

pub(super) fn one() -> f32 {
    1.0
}
pub(super) fn unit_size() -> [f32; 2] {
    [1.0, 1.0]
}
pub(super) fn yes() -> bool {
    true
}

/// Deserialises a map, rejecting a key given twice (RON maps would otherwise keep the last one).
pub(super) fn unique_keys<'de, D: serde::Deserializer<'de>, V: Deserialize<'de>>(
    d: D,
) -> Result<BTreeMap<String, V>, D::Error> {
    struct Unique<V>(std::marker::PhantomData<V>);
    impl<'de, V: Deserialize<'de>> serde::de::Visitor<'de> for Unique<V> {
        type Value = BTreeMap<String, V>;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("a map of names to definitions")
        }
        fn visit_map<A: serde::de::MapAccess<'de>>(
            self,
            mut map: A,
        ) -> Result<Self::Value, A::Error> {
            let mut out = BTreeMap::new();
            while let Some(key) = map.next_key::<String>()? {
                if out.contains_key(&key) {
                    return Err(serde::de::Error::custom(format!(
                        "`{key}` is defined twice"
                    )));
                }
                let value = map.next_value()?;
                out.insert(key, value);
            }
            Ok(out)
        }
    }
    d.deserialize_map(Unique(std::marker::PhantomData))
}

/// Deserialises exactly `N` numbers, rejecting longer lists (TOML arrays would otherwise be
/// silently truncated to their first `N` items).
pub(super) fn exact_floats<'de, D: serde::Deserializer<'de>, const N: usize>(
    d: D,
) -> Result<[f32; N], D::Error> {
    d.deserialize_tuple(N, ExactFloats::<N>)
}

/// Visitor for exactly `N` numbers.
pub(super) struct ExactFloats<const N: usize>;

impl<'de, const N: usize> serde::de::Visitor<'de> for ExactFloats<N> {
    type Value = [f32; N];
    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{N} numbers")
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
        let mut out = [0.0f32; N];
        for (i, slot) in out.iter_mut().enumerate() {
            *slot = seq
                .next_element()?
                .ok_or_else(|| serde::de::Error::invalid_length(i, &self))?;
        }
        let mut extra = 0;
        while seq.next_element::<serde::de::IgnoredAny>()?.is_some() {
            extra += 1;
        }
        if extra > 0 {
            return Err(serde::de::Error::invalid_length(N + extra, &self));
        }
        Ok(out)
    }
}

/// An optional colour of exactly three numbers (`None` for `null`, as `--set` writes an unset
/// one back: settings' `background`, a medium's coefficients).
pub(super) fn optional_rgb<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> Result<Option<super::Rgb>, D::Error> {
    struct Visit;
    impl<'de> serde::de::Visitor<'de> for Visit {
        type Value = Option<super::Rgb>;
        fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
            f.write_str("3 numbers")
        }
        fn visit_none<E: serde::de::Error>(self) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_unit<E: serde::de::Error>(self) -> Result<Self::Value, E> {
            Ok(None)
        }
        fn visit_some<D2: serde::Deserializer<'de>>(self, d: D2) -> Result<Self::Value, D2::Error> {
            exact_floats::<_, 3>(d).map(Some)
        }
    }
    d.deserialize_option(Visit)
}
