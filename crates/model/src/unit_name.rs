//! A unit named in a report (`rad`, `m`, `kg`, `°C`, `s`, and a measured signal's, one of
//! `measurements::INPUT_UNITS`), read back from its JSON as the `&'static str` the report holds;
//! a unit no report writes is refused, not kept as some other.

use serde::{Deserialize, Deserializer};

/// A unit as a warning holds it. Named, not written `&'static str` at the field, because serde
/// takes a `&str` field as borrowed from the input and would read only from `'static` text.
pub(crate) type Unit = &'static str;

/// Every unit a warning of an evaluation names.
const UNITS: [&str; 5] = ["rad", "m", "kg", "°C", "s"];

/// Reads the unit of a measured signal (one of [`measurements::INPUT_UNITS`]), or the empty
/// unit of a signal whose name states none.
fn signal_unit(text: &str) -> Option<Unit> {
    if text.is_empty() {
        return Some("");
    }
    measurements::INPUT_UNITS.iter().map(|(_, unit)| *unit).find(|unit| *unit == text)
}

/// Reads the unit of an input span: one of [`measurements::INPUT_UNITS`].
pub(crate) fn input<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<Unit>, D::Error> {
    let Some(text) = Option::<String>::deserialize(deserializer)? else { return Ok(None) };
    signal_unit(&text).filter(|u| !u.is_empty()).map(Some).ok_or_else(|| {
        serde::de::Error::invalid_value(serde::de::Unexpected::Str(&text), &"a unit of a measured signal (SPEC)")
    })
}

/// Reads one of [`UNITS`] or a measured signal's unit (empty where its name states none).
pub(crate) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Unit, D::Error> {
    let text = String::deserialize(deserializer)?;
    UNITS.iter().copied().find(|unit| *unit == text).or_else(|| signal_unit(&text)).ok_or_else(|| {
        serde::de::Error::invalid_value(
            serde::de::Unexpected::Str(&text),
            &"a unit: rad, m, kg, °C, s, or a measured signal's (SPEC)",
        )
    })
}
