//! Measured signals that may explain the error, beside the joints: any numeric column
//! named by `--inputs` (an inclinometer, a motor temperature, the room temperature), kept per row
//! by name and in the unit the column's name states, as written (no conversion: a model learns
//! from them in whatever unit they were measured in, and records that unit).

use errors::{Error, ErrorKind};
use std::fmt;
use std::str::FromStr;
use std::sync::Arc;

/// The values of a row's input columns, by name. Every row of a file shares one list of names,
/// so a row knows its inputs wherever it goes (a subset, a row made from it for the inverse
/// kinematics) and costs one pointer more than its values.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Inputs {
    names: Arc<[String]>,
    values: Vec<f64>,
}

impl Inputs {
    /// Values of the inputs `names`, in their order. Panics when the lengths differ: a caller
    /// makes both from one list.
    pub fn new(names: Arc<[String]>, values: Vec<f64>) -> Self {
        assert_eq!(names.len(), values.len(), "one value per input name");
        Self { names, values }
    }

    /// The value of input `name`, if the row has it.
    pub fn get(&self, name: &str) -> Option<f64> {
        self.names.iter().position(|n| n == name).map(|k| self.values[k])
    }

    /// The value of input `name`, expected at place `k` (where a file read for a model puts
    /// the model's `k`-th input): found there without a search, else looked up by name.
    pub fn value(&self, k: usize, name: &str) -> Option<f64> {
        match self.names.get(k) {
            Some(n) if n == name => Some(self.values[k]),
            _ => self.get(name),
        }
    }

    /// The names, in the order of [`Inputs::values`].
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The names as shared by the rows of one file.
    pub fn shared_names(&self) -> &Arc<[String]> {
        &self.names
    }

    /// The values, in the order of [`Inputs::names`].
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Whether the row has no input.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }
}

/// An input column as the file names it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InputColumn {
    /// Its name (the SPEC name a `--columns` map gave it, else the header).
    pub name: String,
    /// The unit its name's suffix states ([`input_unit`]), if any.
    pub unit: Option<&'static str>,
    /// 1-based column in the file.
    pub column: usize,
}

/// The suffixes an input's name may end in (`tilt_x_mrad`, `motor2_temp_c`), with the unit each
/// states as reports print it. A name with another ending has no unit of ours; its values are
/// used all the same.
pub const INPUT_UNITS: [(&str, &str); 24] = [
    ("rad", "rad"),
    ("mrad", "mrad"),
    ("urad", "µrad"),
    ("deg", "°"),
    ("m", "m"),
    ("mm", "mm"),
    ("um", "µm"),
    ("c", "°C"),
    ("k", "K"),
    ("s", "s"),
    ("ms", "ms"),
    ("min", "min"),
    ("h", "h"),
    ("kg", "kg"),
    ("n", "N"),
    ("nm", "N·m"),
    ("a", "A"),
    ("v", "V"),
    ("w", "W"),
    ("mps2", "m/s²"),
    ("pa", "Pa"),
    ("hz", "Hz"),
    ("rpm", "rpm"),
    ("pct", "%"),
];

/// The unit the suffix after the last `_` of `name` states (`tilt_x_mps2` → `m/s²`), if it is
/// one of [`INPUT_UNITS`] (case-insensitive).
pub fn input_unit(name: &str) -> Option<&'static str> {
    let (_, suffix) = name.rsplit_once('_')?;
    INPUT_UNITS.iter().find(|(s, _)| s.eq_ignore_ascii_case(suffix)).map(|(_, unit)| *unit)
}

/// The names of `--inputs NAME[,NAME…]`: none empty, none twice.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct InputNames(Vec<String>);

impl InputNames {
    /// The names in the order given.
    pub fn names(&self) -> &[String] {
        &self.0
    }

    /// The names, checked as the argument's are; `source` names the list in a refusal.
    pub fn new(names: Vec<String>, source: &str) -> Result<Self, Error> {
        for (k, name) in names.iter().enumerate() {
            if name.trim().is_empty() || names[..k].contains(name) {
                return Err(Error::at_line(source.to_owned(), 1, k + 1, ErrorKind::InputList { name: name.clone() }));
            }
        }
        Ok(Self(names))
    }
}

impl FromStr for InputNames {
    type Err = Error;

    /// Parses `NAME[,NAME…]`, each name trimmed; a refusal names the character where the name at
    /// fault starts.
    fn from_str(text: &str) -> Result<Self, Error> {
        let mut names: Vec<String> = Vec::new();
        let mut offset = 0;
        for piece in text.split(',') {
            let name = piece.trim();
            if name.is_empty() || names.iter().any(|n| n == name) {
                let column = text[..offset].chars().count() + 1;
                return Err(Error::at_line("--inputs", 1, column, ErrorKind::InputList { name: name.to_owned() }));
            }
            names.push(name.to_owned());
            offset += piece.len() + 1;
        }
        Ok(Self(names))
    }
}

impl fmt::Display for InputNames {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0.join(","))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_inputs_unit_is_its_names_suffix_where_that_is_a_unit() {
        assert_eq!(input_unit("tilt_x_mps2"), Some("m/s²"));
        assert_eq!(input_unit("motor2_temp_C"), Some("°C"));
        assert_eq!(input_unit("tilt_x"), None);
        assert_eq!(input_unit("current"), None);
    }

    #[test]
    fn an_inputs_list_with_an_empty_or_a_repeated_name_is_refused_where_it_starts() {
        let names: InputNames = " tilt_x, temp_c ".parse().unwrap();
        assert_eq!(names.names(), ["tilt_x", "temp_c"]);
        let error = "tilt_x,temp_c,tilt_x".parse::<InputNames>().unwrap_err();
        assert!(error.to_string().starts_with("--inputs:1:15: the input 'tilt_x' is named twice"), "{error}");
        let error = "tilt_x,,temp_c".parse::<InputNames>().unwrap_err();
        assert!(error.to_string().starts_with("--inputs:1:8: an empty name"), "{error}");
    }
}
