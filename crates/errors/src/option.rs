//! The one way an options struct refuses a value: [`OptionOutOfRange`], made by
//! [`OptionOutOfRange::check`] and its ranges ([`positive`] …), whatever crate the options are of.
//! A range whose bound is a number ([`above`], [`at_least`], [`count_at_least`]) writes it into
//! `expected` when it refuses.

use std::borrow::Cow;
use std::fmt;

/// An option whose value is outside its range: `option FIELD = VALUE: expected EXPECTED`.
///
/// An options file's reader places it at the field in the file ([`OptionOutOfRange::in_file`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OptionOutOfRange {
    /// The option's field, as its options struct names it (`ridge`, `prior.placement`).
    pub field: &'static str,
    /// Its value.
    pub value: OptionValue,
    /// What it must be (`a positive finite number`; `a finite number above 1`, where the bound is
    /// a number of the range).
    pub expected: Cow<'static, str>,
}

/// An option's value as its refusal shows it.
#[derive(Debug, Clone, PartialEq)]
pub enum OptionValue {
    /// A number (an integer option's too), shown as `{}` shows an `f64`: `-1`, `inf`, `NaN`.
    Number(f64),
    /// A value that is no one number (a pair, a list), as the refusal writes it: `(1.1, 1.3)`.
    Shown(String),
}

impl From<f64> for OptionValue {
    fn from(value: f64) -> Self {
        OptionValue::Number(value)
    }
}

impl fmt::Display for OptionValue {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            OptionValue::Number(value) => write!(f, "{value}"),
            OptionValue::Shown(text) => f.write_str(text),
        }
    }
}

impl OptionOutOfRange {
    /// The refusal of `field`'s `value`, which is not `expected` (a lower crate's refusal of the
    /// same shape, carried over).
    pub fn new(field: &'static str, value: impl Into<OptionValue>, expected: impl Into<Cow<'static, str>>) -> Self {
        OptionOutOfRange { field, value: value.into(), expected: expected.into() }
    }

    /// `Ok` where `accepted`, otherwise the refusal of `field`'s `value`.
    pub fn check(
        field: &'static str,
        value: impl Into<OptionValue>,
        accepted: bool,
        expected: impl Into<Cow<'static, str>>,
    ) -> Result<(), Self> {
        if accepted { Ok(()) } else { Err(OptionOutOfRange::new(field, value, expected)) }
    }

    /// The refusal as an options file's reader gives it: the field to point at in the file (the
    /// last part of a dotted field: `growth` for `jitter.growth`, as the file writes it) and
    /// `SECTION.FIELD is VALUE, expected EXPECTED` (`section` is the options struct's place in the
    /// file, e.g. `effects.gear`; empty at the top level).
    pub fn in_file(&self, section: &str) -> (&'static str, String) {
        let OptionOutOfRange { field, value, expected } = self;
        let dot = if section.is_empty() { "" } else { "." };
        let last = field.rsplit('.').next().unwrap_or(field);
        (last, format!("{section}{dot}{field} is {value}, expected {expected}"))
    }
}

/// A finite number above 0.
pub fn positive(field: &'static str, value: f64) -> Result<(), OptionOutOfRange> {
    OptionOutOfRange::check(field, value, value.is_finite() && value > 0.0, "a positive finite number")
}

/// A finite number of at least 0.
pub fn non_negative(field: &'static str, value: f64) -> Result<(), OptionOutOfRange> {
    OptionOutOfRange::check(field, value, value.is_finite() && value >= 0.0, "a finite number ≥ 0")
}

/// A count of at least 1.
pub fn at_least_one(field: &'static str, value: usize) -> Result<(), OptionOutOfRange> {
    count_at_least(field, value, 1)
}

/// A count of at least `least`.
pub fn count_at_least(field: &'static str, value: usize, least: usize) -> Result<(), OptionOutOfRange> {
    OptionOutOfRange::check(field, value as f64, value >= least, format!("at least {least}"))
}

/// A finite number above `lowest`.
pub fn above(field: &'static str, value: f64, lowest: f64) -> Result<(), OptionOutOfRange> {
    let accepted = value.is_finite() && value > lowest;
    OptionOutOfRange::check(field, value, accepted, format!("a finite number above {lowest}"))
}

/// A finite number of at least `lowest`.
pub fn at_least(field: &'static str, value: f64, lowest: f64) -> Result<(), OptionOutOfRange> {
    let accepted = value.is_finite() && value >= lowest;
    OptionOutOfRange::check(field, value, accepted, format!("a finite number of at least {lowest}"))
}

impl fmt::Display for OptionOutOfRange {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let OptionOutOfRange { field, value, expected } = self;
        write!(f, "option {field} = {value}: expected {expected}")
    }
}

impl std::error::Error for OptionOutOfRange {}

impl crate::Kind for OptionOutOfRange {}

#[cfg(test)]
mod tests {
    use super::{OptionOutOfRange, above, at_least, at_least_one, count_at_least, non_negative, positive};

    #[test]
    fn an_option_out_of_range_names_its_field_value_and_range() {
        let refused = positive("ridge", -1.0).unwrap_err();
        assert_eq!(refused.to_string(), "option ridge = -1: expected a positive finite number");
        assert_eq!(
            refused.in_file("registration"),
            ("ridge", "registration.ridge is -1, expected a positive finite number".to_owned())
        );
        assert_eq!(refused.in_file("").1, "ridge is -1, expected a positive finite number");
        assert!(positive("ridge", f64::INFINITY).is_err());
        assert!(positive("ridge", 0.0).is_err());
        assert!(positive("ridge", 1e-300).is_ok());
        assert!(non_negative("tolerance", 0.0).is_ok());
        assert!(non_negative("tolerance", f64::NAN).is_err());
        assert_eq!(at_least_one("restarts", 0).unwrap_err().to_string(), "option restarts = 0: expected at least 1");
        assert!(at_least_one("restarts", 1).is_ok());
    }

    #[test]
    fn a_range_with_a_number_for_bound_writes_it_and_a_dotted_field_is_found_by_its_last_part() {
        let refused = above("growth", 0.5, 1.0).unwrap_err();
        assert_eq!(refused.to_string(), "option growth = 0.5: expected a finite number above 1");
        assert!(above("growth", 1.0, 1.0).is_err() && above("growth", f64::INFINITY, 1.0).is_err());
        assert!(above("growth", 1.5, 1.0).is_ok());
        let refused = at_least("ratio", 0.5, 1.0).unwrap_err();
        assert_eq!(
            refused.in_file("plausibility").1,
            "plausibility.ratio is 0.5, expected a finite number of at least 1"
        );
        assert!(at_least("ratio", 1.0, 1.0).is_ok() && at_least("ratio", f64::NAN, 1.0).is_err());
        assert_eq!(count_at_least("steps", 7, 8).unwrap_err().to_string(), "option steps = 7: expected at least 8");
        assert!(count_at_least("steps", 8, 8).is_ok());
        let pair = OptionOutOfRange::new("scale_band", super::OptionValue::Shown("(1.1, 1.3)".into()), "0 < low ≤ 1");
        assert_eq!(pair.in_file("plausibility").1, "plausibility.scale_band is (1.1, 1.3), expected 0 < low ≤ 1");
        let nested = OptionOutOfRange::new("jitter.growth", 0.5, "a finite number above 1");
        assert_eq!(
            nested.in_file("gp"),
            ("growth", "gp.jitter.growth is 0.5, expected a finite number above 1".into())
        );
    }
}
