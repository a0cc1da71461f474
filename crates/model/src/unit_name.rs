//! A unit named in a report (`rad`, `m`, `kg`, `°C`, `s`), read back from its JSON as the
//! `&'static str` the report holds; a unit no report writes is refused, not kept as some other.

use serde::{Deserialize, Deserializer};

/// A unit as a warning holds it. Named, not written `&'static str` at the field, because serde
/// takes a `&str` field as borrowed from the input and would read only from `'static` text.
pub(crate) type Unit = &'static str;

/// Every unit a warning of an evaluation names.
const UNITS: [&str; 5] = ["rad", "m", "kg", "°C", "s"];

/// Reads one of [`UNITS`].
pub(crate) fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Unit, D::Error> {
    let text = String::deserialize(deserializer)?;
    UNITS.iter().copied().find(|unit| *unit == text).ok_or_else(|| {
        serde::de::Error::invalid_value(serde::de::Unexpected::Str(&text), &"a unit: rad, m, kg, °C or s")
    })
}
