//! How a measurement file writes its numbers: `,` between fields and `.` as decimal point
//! (SPEC v1), or `;` between fields with `,` or `.` as decimal point, as tracker software exports
//! them (SPEC v2). The separator is read off the header, the decimal mark off the first numbers
//! that have one; every later number must agree.

pub use crate::error_kind::DecimalFault;
use serde::{Deserialize, Serialize};
use std::fmt;

/// The character between fields.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Delimiter {
    /// `,` (SPEC v1).
    Comma,
    /// `;` (tracker exports, SPEC v2).
    Semicolon,
}

impl Delimiter {
    /// The byte itself.
    pub fn byte(self) -> u8 {
        match self {
            Delimiter::Comma => b',',
            Delimiter::Semicolon => b';',
        }
    }
}

/// The decimal mark of the file's numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Decimal {
    /// `1.5`.
    Point,
    /// `1,5` (only in `;`-separated files).
    Comma,
}

impl Decimal {
    fn mark(self) -> char {
        match self {
            Decimal::Point => '.',
            Decimal::Comma => ',',
        }
    }
}

/// What the reader detected about how the file is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Dialect {
    /// Between fields.
    pub delimiter: Delimiter,
    /// The decimal mark; `None` while no number with a fraction has been read (integers only).
    pub decimal: Option<Decimal>,
}

impl Default for Dialect {
    fn default() -> Self {
        Self { delimiter: Delimiter::Comma, decimal: Some(Decimal::Point) }
    }
}

impl fmt::Display for Dialect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let delimiter = match self.delimiter {
            Delimiter::Comma => "','",
            Delimiter::Semicolon => "';'",
        };
        match self.decimal {
            Some(Decimal::Point) => write!(f, "{delimiter}-separated, decimal point"),
            Some(Decimal::Comma) => write!(f, "{delimiter}-separated, decimal comma"),
            None => write!(f, "{delimiter}-separated, whole numbers only"),
        }
    }
}

impl Dialect {
    /// The dialect the header line shows: `;` when it separates more fields than `,` does
    /// (outside double quotes), `,` otherwise. A comma-separated file has the decimal point.
    pub(crate) fn from_header_line(bytes: &[u8]) -> Self {
        // The first line that is not blank, ended by `\n`, `\r\n` or a lone `\r` (the CSV layer
        // skips blank lines before the header and ends records at either).
        let line = bytes.split(|&b| b == b'\n' || b == b'\r').find(|l| !l.is_empty()).unwrap_or(&[]);
        let (mut commas, mut semicolons, mut quoted) = (0usize, 0usize, false);
        for &b in line {
            match b {
                b'"' => quoted = !quoted,
                b',' if !quoted => commas += 1,
                b';' if !quoted => semicolons += 1,
                _ => {}
            }
        }
        if semicolons > commas { Self { delimiter: Delimiter::Semicolon, decimal: None } } else { Self::default() }
    }

    /// Parses one cell as a number in this dialect, fixing the decimal mark on the first number
    /// that shows one. `Ok(None)` when the text is not a finite number at all.
    pub(crate) fn number(&mut self, text: &str) -> Result<Option<f64>, DecimalFault> {
        let found = match (text.contains('.'), text.contains(',')) {
            (false, false) => None,
            (true, false) => Some(Decimal::Point),
            (false, true) => Some(Decimal::Comma),
            (true, true) => return Ok(None),
        };
        let value = match found {
            Some(Decimal::Comma) => text.replacen(',', ".", 1).parse::<f64>(),
            _ => text.parse::<f64>(),
        };
        let value = match value {
            Ok(v) if v.is_finite() => v,
            _ => return Ok(None),
        };
        if let Some(found) = found {
            match (self.delimiter, self.decimal) {
                (Delimiter::Comma, _) if found == Decimal::Comma => return Err(DecimalFault::CommaInCommaFile),
                (_, Some(expected)) if expected != found => {
                    return Err(DecimalFault::Other { expected: expected.mark() });
                }
                _ => self.decimal = Some(found),
            }
        }
        Ok(Some(value))
    }
}
