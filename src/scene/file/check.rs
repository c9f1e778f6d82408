//! Positions and value checks: a byte offset in the scene file becomes a [`SceneFileError`]
//! with a line and column, and serde's messages become ones a TOML user can act on.

use glam::Vec3;
use toml::Spanned;

use super::error::{SceneFileError, did_you_mean};
use super::spec::Three;
use crate::scene::MAX_COORDINATE;

/// How each required key is written, for "missing key" messages.
pub const KEY_FORMS: [(&str, &str); 9] = [
    ("position", "position = [x, y, z]"),
    ("power", "power = 14 (or [r, g, b])"),
    (
        "direction",
        "direction = [x, y, z] (the way the light travels)",
    ),
    ("irradiance", "irradiance = 1 (or [r, g, b])"),
    ("emission", "emission = 0.5 (or [r, g, b])"),
    ("colour", "colour = [r, g, b] (each from 0 to 1)"),
    (
        "kind",
        "kind = \"triangles\", \"box\", \"obj\" or \"icosphere\"",
    ),
    ("material", "material = \"NAME\" (a [material.NAME] table)"),
    ("bounces", "bounces = n (0 to 16)"),
];

/// The file being read: its text and its name, for positioned errors.
pub struct Ctx<'a> {
    /// The scene file's text.
    pub source: &'a str,
    /// Its name as shown.
    pub file: &'a str,
}

impl Ctx<'_> {
    /// An error at byte `offset`.
    pub fn err(&self, offset: usize, message: impl Into<String>) -> SceneFileError {
        SceneFileError::at(self.file, self.source, offset, message)
    }

    /// An error at `v`.
    pub fn err_at<T>(&self, v: &Spanned<T>, message: impl Into<String>) -> SceneFileError {
        self.err(v.span().start, message)
    }

    /// `v` as an `f32` triple, each component finite and within ±[`MAX_COORDINATE`].
    pub fn point(&self, v: &Spanned<Three<f64>>, what: &str) -> Result<Vec3, SceneFileError> {
        for c in &v.get_ref().0 {
            if !c.is_finite() || c.abs() > f64::from(MAX_COORDINATE) {
                return Err(self.err_at(
                    v,
                    format!(
                        "{what} has the coordinate {c}: expected finite numbers within ±{MAX_COORDINATE:e}"
                    ),
                ));
            }
        }
        Ok(Vec3::from(v.get_ref().0.map(|c| c as f32)))
    }

    /// A number in `lo..=hi`.
    pub fn ranged(
        &self,
        v: &Spanned<f64>,
        lo: f64,
        hi: f64,
        what: &str,
    ) -> Result<f64, SceneFileError> {
        let x = *v.get_ref();
        if !(x >= lo && x <= hi) {
            return Err(self.err_at(
                v,
                format!("{what} is {x}: expected a number from {lo} to {hi}"),
            ));
        }
        Ok(x)
    }

    /// A whole number in `lo..=hi`.
    pub fn whole(
        &self,
        v: &Spanned<i64>,
        lo: i64,
        hi: i64,
        what: &str,
    ) -> Result<i64, SceneFileError> {
        let x = *v.get_ref();
        if !(lo..=hi).contains(&x) {
            return Err(self.err_at(
                v,
                format!("{what} is {x}: expected a whole number from {lo} to {hi}"),
            ));
        }
        Ok(x)
    }

    /// "NAME:LINE:COL" of byte `offset`, to name a place in the scene file from another file's
    /// error.
    pub fn place(&self, offset: usize) -> String {
        let (l, c) = super::line_column(self.source, offset);
        format!("{}:{l}:{c}", self.file)
    }
}

/// A TOML or serde error as a positioned message; unknown keys get a suggestion.
///
/// This reads serde's English messages: `toml::de::Error` keeps only a message and a span,
/// and serde's derived code reports an unknown or missing field through
/// `de::Error::unknown_field` / `missing_field`, whose default forms are text. The tests below
/// build errors with those very constructors, so a change of wording in serde or toml fails
/// them by name rather than degrading the messages in silence.
pub fn toml_error(cx: &Ctx, e: &toml::de::Error) -> SceneFileError {
    let offset = e.span().map_or(0, |s| s.start);
    let message = e.message().trim().replace('\n', "; ");
    let message = if let Some(rest) = message.strip_prefix("unknown field `") {
        // serde: "unknown field `KEY`, expected `a`" / "… one of `a`, `b`" / "… `a` or `b`",
        // or "unknown field `KEY`, there are no fields". KEY may itself hold backticks.
        let (key, expected) = rest
            .rsplit_once("`, expected ")
            .or_else(|| {
                rest.rsplit_once("`, there are no fields")
                    .map(|(k, _)| (k, ""))
            })
            .unwrap_or((rest.trim_end_matches('`'), ""));
        let known: Vec<&str> = expected.split('`').skip(1).step_by(2).collect();
        format!(
            "unknown key `{key}`{} (keys here: {})",
            did_you_mean(key, &known),
            if known.is_empty() {
                "none".to_string()
            } else {
                known.join(", ")
            }
        )
    } else if let Some(rest) = message.strip_prefix("missing field `") {
        let key = rest.strip_suffix('`').unwrap_or(rest);
        let form = KEY_FORMS
            .iter()
            .find(|k| k.0 == key)
            .map_or(String::new(), |k| format!(": add {}", k.1));
        format!("missing key `{key}` in this table{form}")
    } else {
        message
            .replace("duplicate field", "duplicate key")
            .replace(" as i128", "")
            .replace(
                "expected an array of length 3",
                "expected three numbers [a, b, c]",
            )
            .replace("expected i64", "expected a whole number")
            .replace("expected f64", "expected a number")
            .replace("expected a boolean", "expected true or false")
            .replace("invalid type: map", "invalid type: table")
            .replace("invalid type: sequence", "invalid type: array")
            .replace(
                "expected a sequence",
                "expected an array: [a, b, ...], or [[NAME]] tables (double brackets) for a list of tables",
            )
            .replace(
                "expected a map",
                "expected a table: [NAME] or [NAME.KEY] headers, or { key = value }",
            )
    };
    cx.err(offset, message)
}

#[cfg(test)]
mod tests {
    use serde::de::{Error as _, Unexpected};

    use super::*;

    /// The message [`toml_error`] makes of an error built by serde's own constructor.
    fn shown(e: toml::de::Error) -> String {
        let cx = Ctx {
            source: "",
            file: "f.toml",
        };
        toml_error(&cx, &e).message
    }

    #[test]
    fn serde_field_errors_become_toml_messages() {
        let e = toml::de::Error::unknown_field("mirorr", &["colour", "mirror"]);
        assert_eq!(
            shown(e),
            "unknown key `mirorr`; did you mean `mirror`? (keys here: colour, mirror)"
        );
        let e = toml::de::Error::unknown_field("zoom", &["position", "yaw", "pitch"]);
        assert_eq!(
            shown(e),
            "unknown key `zoom` (keys here: position, yaw, pitch)"
        );
        let e = toml::de::Error::unknown_field("a`, expected `b", &["kind"]);
        assert_eq!(shown(e), "unknown key `a`, expected `b` (keys here: kind)");
        let e = toml::de::Error::unknown_field("x", &[]);
        assert_eq!(shown(e), "unknown key `x` (keys here: none)");
        let e = toml::de::Error::missing_field("power");
        assert_eq!(
            shown(e),
            "missing key `power` in this table: add power = 14 (or [r, g, b])"
        );
        let e = toml::de::Error::duplicate_field("yaw");
        assert_eq!(shown(e), "duplicate key `yaw`");
    }

    #[test]
    fn serde_type_errors_use_toml_words() {
        let e = toml::de::Error::invalid_type(Unexpected::Str("x"), &"f64");
        assert_eq!(shown(e), "invalid type: string \"x\", expected a number");
        let e = toml::de::Error::invalid_type(Unexpected::Map, &"i64");
        assert_eq!(shown(e), "invalid type: table, expected a whole number");
        let e = toml::de::Error::invalid_type(Unexpected::Seq, &"a boolean");
        assert_eq!(shown(e), "invalid type: array, expected true or false");
    }
}
