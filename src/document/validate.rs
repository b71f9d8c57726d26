//! Validation shared by the CLI, the GUI and the project loader: every setting is checked in
//! the library, and a rejected value is named in the words the GUI uses for it.

use thiserror::Error;

/// A value out of range: what it is (in the GUI's words), the file key, the value and the rule
/// it breaks. Displays in words only (`Field width (mm) must be a positive number, not -5`);
/// file-level errors add the key.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{what} must be {rule}, not {value}")]
pub struct InvalidValue {
    /// The setting in words, as the GUI labels it (e.g. `Field width (mm)`).
    pub what: String,
    /// The key in a profile, settings or pens file (e.g. `field_mm[0]`).
    pub key: String,
    /// The rejected value as text.
    pub value: String,
    /// What the value must be (e.g. `a positive number`).
    pub rule: String,
}

impl InvalidValue {
    /// A rejected value.
    pub fn new(
        what: impl Into<String>,
        key: impl Into<String>,
        value: impl ToString,
        rule: impl Into<String>,
    ) -> Self {
        Self {
            what: what.into(),
            key: key.into(),
            value: value.to_string(),
            rule: rule.into(),
        }
    }
    /// The same error with `prefix` before the setting's words and key (e.g. a layer's name).
    pub fn within(mut self, words: &str, key: &str) -> Self {
        self.what = format!("{words}: {}", self.what);
        self.key = format!("{key}.{}", self.key);
        self
    }
    /// The message with the file key, for errors about a file: `… (key field_mm[0])`.
    pub fn with_key(&self) -> String {
        format!("{self} (key {})", self.key)
    }
}

/// Rule text for [`positive`].
pub const POSITIVE: &str = "a positive number";
/// Rule text for [`non_negative`].
pub const NON_NEGATIVE: &str = "zero or a positive number";

/// `v > 0` and finite.
pub fn positive(what: &str, key: &str, v: f64) -> Result<(), InvalidValue> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(InvalidValue::new(what, key, v, POSITIVE))
    }
}

/// `v >= 0` and finite.
pub fn non_negative(what: &str, key: &str, v: f64) -> Result<(), InvalidValue> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(InvalidValue::new(what, key, v, NON_NEGATIVE))
    }
}

/// `lo <= v <= hi`.
pub fn within(what: &str, key: &str, v: f64, lo: f64, hi: f64) -> Result<(), InvalidValue> {
    if (lo..=hi).contains(&v) {
        Ok(())
    } else {
        Err(InvalidValue::new(
            what,
            key,
            v,
            format!("between {lo} and {hi}"),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_first_key_on_request() {
        let e = positive("Field width (mm)", "field_mm[0]", -5.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "Field width (mm) must be a positive number, not -5"
        );
        assert!(e.with_key().ends_with("(key field_mm[0])"));
        let e = e.within("Layer 'fill'", "layer.fill");
        assert!(
            e.to_string().starts_with("Layer 'fill': Field width"),
            "{e}"
        );
        assert_eq!(e.key, "layer.fill.field_mm[0]");
        assert!(non_negative("x", "x", 0.0).is_ok());
        assert!(non_negative("x", "x", f64::NAN).is_err());
        assert!(within("x", "x", 1.5, 0.0, 1.0).is_err());
    }
}
