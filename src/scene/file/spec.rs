//! The scene file as written: serde structs that keep each value's position (`Spanned`), so
//! that checks made after parsing can still name a line and column. Values are `f64` here and
//! checked against the limits before they become the scene's `f32`.

use std::collections::BTreeMap;
use std::fmt;

use serde::Deserialize;
use serde::de::{self, MapAccess, SeqAccess, Visitor};
use toml::Spanned;

/// The whole file.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct SceneSpec {
    pub name: Option<Spanned<String>>,
    pub camera: Option<CameraSpec>,
    #[serde(default)]
    pub light: Vec<Spanned<LightSpec>>,
    #[serde(default)]
    pub material: BTreeMap<String, Spanned<MaterialSpec>>,
    #[serde(default)]
    pub object: Vec<Spanned<ObjectSpec>>,
    pub effects: Option<EffectsSpec>,
}

/// `[camera]`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct CameraSpec {
    pub position: Option<Spanned<Three<f64>>>,
    pub yaw: Option<Spanned<f64>>,
    pub pitch: Option<Spanned<f64>>,
}

/// One `[[light]]`: every kind's keys, checked against its `kind` (default "point") after
/// parsing.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    pub kind: Option<Spanned<String>>,
    pub position: Option<Spanned<Three<f64>>>,
    pub power: Option<Spanned<NumberOrTriple>>,
    pub direction: Option<Spanned<Three<f64>>>,
    pub irradiance: Option<Spanned<NumberOrTriple>>,
    pub inner_angle: Option<Spanned<f64>>,
    pub outer_angle: Option<Spanned<f64>>,
    pub emission: Option<Spanned<NumberOrTriple>>,
}

/// One `[material.NAME]`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct MaterialSpec {
    pub colour: Spanned<Three<f64>>,
    pub mirror: Option<Spanned<f64>>,
    pub metal: Option<Spanned<f64>>,
    pub roughness: Option<Spanned<f64>>,
    pub ior: Option<Spanned<f64>>,
    pub transmission: Option<Spanned<f64>>,
    pub emission: Option<Spanned<NumberOrTriple>>,
}

/// One `[[object]]`: every kind's keys, checked against its `kind` after parsing.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct ObjectSpec {
    pub kind: Spanned<String>,
    pub material: Spanned<String>,
    pub triangles: Option<Spanned<Vec<Spanned<TriangleSpec>>>>,
    pub min: Option<Spanned<Three<f64>>>,
    pub max: Option<Spanned<Three<f64>>>,
    pub centre: Option<Spanned<Three<f64>>>,
    pub size: Option<Spanned<Three<f64>>>,
    pub path: Option<Spanned<String>>,
    pub subdivisions: Option<Spanned<i64>>,
    pub amplitude: Option<Spanned<f64>>,
    pub translate: Option<Spanned<Three<f64>>>,
    pub rotate_y: Option<Spanned<f64>>,
    pub scale: Option<Spanned<NumberOrTriple>>,
}

/// A triangle's three vertices.
pub type TriangleSpec = Three<Three<f64>>;

/// `[effects]`.
#[derive(Deserialize, Debug)]
#[serde(deny_unknown_fields)]
pub struct EffectsSpec {
    pub shadows: Option<bool>,
    pub indirect: Option<Spanned<IndirectSpec>>,
    pub samples: Option<Spanned<i64>>,
    pub sampler: Option<Spanned<String>>,
}

/// Exactly three values: `[a, b, c]` (serde's arrays would take a fourth in silence).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Three<T>(pub [T; 3]);

impl<'de, T: Deserialize<'de> + Copy + Default> Deserialize<'de> for Three<T> {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de> + Copy + Default> Visitor<'de> for V<T> {
            type Value = Three<T>;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("three values [a, b, c]")
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = [T::default(); 3];
                for (i, o) in out.iter_mut().enumerate() {
                    *o = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(
                        4,
                        &"exactly three values [a, b, c]",
                    ));
                }
                Ok(Three(out))
            }
        }
        d.deserialize_seq(V(std::marker::PhantomData))
    }
}

/// A number (the same for x, y, z or r, g, b) or a triple.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NumberOrTriple(pub [f64; 3]);

impl<'de> Deserialize<'de> for NumberOrTriple {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = NumberOrTriple;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number or a triple of numbers [a, b, c]")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(NumberOrTriple([v as f64; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(NumberOrTriple([v as f64; 3]))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(NumberOrTriple([v; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Self::Value, A::Error> {
                let mut out = [0.0; 3];
                for (i, o) in out.iter_mut().enumerate() {
                    *o = seq
                        .next_element()?
                        .ok_or_else(|| de::Error::invalid_length(i, &self))?;
                }
                if seq.next_element::<de::IgnoredAny>()?.is_some() {
                    return Err(de::Error::invalid_length(
                        4,
                        &"exactly three numbers [a, b, c]",
                    ));
                }
                Ok(NumberOrTriple(out))
            }
        }
        d.deserialize_any(V)
    }
}

/// `indirect = "none" | N | { bounces = n }`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IndirectSpec {
    /// `"none"`.
    None,
    /// A number: the constant term N.
    Constant(f64),
    /// `{ bounces = n }`.
    Bounces(i64),
}

/// What `indirect` accepts, for messages.
pub const INDIRECT_EXPECTED: &str =
    "\"none\", a number (the constant term, e.g. 0.5) or { bounces = n } (path traced)";

impl<'de> Deserialize<'de> for IndirectSpec {
    fn deserialize<D: de::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = IndirectSpec;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str(INDIRECT_EXPECTED)
            }
            fn visit_str<E: de::Error>(self, v: &str) -> Result<Self::Value, E> {
                if v == "none" {
                    Ok(IndirectSpec::None)
                } else {
                    Err(de::Error::invalid_value(de::Unexpected::Str(v), &self))
                }
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
                Ok(IndirectSpec::Constant(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
                Ok(IndirectSpec::Constant(v as f64))
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Self::Value, E> {
                Ok(IndirectSpec::Constant(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Self::Value, A::Error> {
                let mut bounces = None;
                while let Some(key) = map.next_key::<String>()? {
                    if key != "bounces" {
                        return Err(de::Error::unknown_field(&key, &["bounces"]));
                    }
                    if bounces.is_some() {
                        return Err(de::Error::duplicate_field("bounces"));
                    }
                    bounces = Some(map.next_value::<i64>()?);
                }
                bounces
                    .map(IndirectSpec::Bounces)
                    .ok_or_else(|| de::Error::missing_field("bounces"))
            }
        }
        d.deserialize_any(V)
    }
}
