//! The one way an options struct refuses a value: [`OptionOutOfRange`], made by
//! [`OptionOutOfRange::check`] and its ranges ([`positive`] …), whatever crate the options are of.

use std::fmt;

/// An option whose value is outside its range: `option FIELD = VALUE: expected EXPECTED`.
///
/// An options file's reader places it at the field in the file ([`OptionOutOfRange::in_file`]).
#[derive(Debug, Clone, PartialEq)]
pub struct OptionOutOfRange {
    /// The option's field, as its options struct names it (`ridge`, `prior.placement`).
    pub field: &'static str,
    /// Its value (an integer option's, as a number).
    pub value: f64,
    /// What it must be (`a positive finite number`).
    pub expected: &'static str,
}

impl OptionOutOfRange {
    /// `Ok` where `accepted`, otherwise the refusal of `field`'s `value`.
    pub fn check(field: &'static str, value: f64, accepted: bool, expected: &'static str) -> Result<(), Self> {
        if accepted { Ok(()) } else { Err(OptionOutOfRange { field, value, expected }) }
    }

    /// The refusal as an options file's reader gives it: the field to point at in the file and
    /// `SECTION.FIELD is VALUE, expected EXPECTED` (`section` is the options struct's place in the
    /// file, e.g. `effects.gear`; empty at the top level).
    pub fn in_file(&self, section: &str) -> (&'static str, String) {
        let OptionOutOfRange { field, value, expected } = self;
        let dot = if section.is_empty() { "" } else { "." };
        (field, format!("{section}{dot}{field} is {value}, expected {expected}"))
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
    OptionOutOfRange::check(field, value as f64, value >= 1, "at least 1")
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
    use super::{at_least_one, non_negative, positive};

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
}
