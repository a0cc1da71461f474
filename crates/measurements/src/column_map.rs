//! `--columns NAME=HEADER,…`: any other header mapped onto the SPEC's column names (SPEC v2), so
//! that a tracker export is read as it comes. Units stay explicit: the target names carry them.

use super::quantity::quantity;
use crate::ErrorKind;
pub use crate::error_kind::ColumnMapFault;
use errors::Error;
use std::fmt;
use std::str::FromStr;

/// Header names mapped onto SPEC column names, as given to `--columns`.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ColumnMap {
    /// `(SPEC name, header)` pairs in the order given.
    entries: Vec<(String, String)>,
}

impl ColumnMap {
    /// The `(SPEC name, header)` pairs, in the order given.
    pub fn entries(&self) -> &[(String, String)] {
        &self.entries
    }

    /// Whether nothing is mapped.
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }

    /// The SPEC name a header is mapped to, if any.
    pub(super) fn target_of(&self, header: &str) -> Option<&str> {
        self.entries.iter().find(|(_, h)| h == header).map(|(t, _)| t.as_str())
    }
}

/// Splits `text` at the commas outside double quotes, with each piece's 0-based character offset.
fn items(text: &str) -> Result<Vec<(usize, &str)>, Error> {
    let mut pieces = Vec::new();
    let (mut start, mut quoted) = (0, false);
    let mut quote_at = 0;
    for (i, c) in text.char_indices() {
        match c {
            '"' => {
                quoted = !quoted;
                quote_at = i;
            }
            ',' if !quoted => {
                pieces.push((start, &text[start..i]));
                start = i + 1;
            }
            _ => {}
        }
    }
    if quoted {
        return Err(fault(text, quote_at, ColumnMapFault::UnclosedQuote));
    }
    pieces.push((start, &text[start..]));
    Ok(pieces)
}

/// The error for a fault found at byte `offset` of the argument.
fn fault(argument: &str, offset: usize, fault: ColumnMapFault) -> Error {
    let column = argument[..offset.min(argument.len())].chars().count() + 1;
    let end = argument[offset.min(argument.len())..].find(',').map_or(argument.len(), |e| offset + e);
    Error::at_line(
        "--columns",
        1,
        column,
        ErrorKind::ColumnMap { text: argument[offset.min(argument.len())..end].to_owned(), fault },
    )
}

impl FromStr for ColumnMap {
    type Err = Error;

    /// Parses `NAME=HEADER,…`; a header holding `,` or `=` is written in double quotes
    /// (`x_mm="X, mm"`). A refusal names the character of the argument where it is.
    fn from_str(text: &str) -> Result<Self, Error> {
        if text.trim().is_empty() {
            return Err(fault(text, 0, ColumnMapFault::Empty));
        }
        let mut entries: Vec<(String, String)> = Vec::new();
        for (offset, item) in items(text)? {
            let at = |fault_kind| fault(text, offset + (item.len() - item.trim_start().len()), fault_kind);
            let (target, header) = item.split_once('=').ok_or_else(|| at(ColumnMapFault::MissingEquals))?;
            let target = target.trim();
            if quantity(target).is_none() {
                return Err(at(ColumnMapFault::UnknownTarget));
            }
            let header = header.trim();
            let header = match header.strip_prefix('"') {
                Some(rest) => match rest.split_once('"') {
                    Some((inside, after)) if after.trim().is_empty() => inside,
                    _ => return Err(at(ColumnMapFault::TextAfterQuote)),
                },
                None => header,
            };
            if header.trim().is_empty() {
                return Err(at(ColumnMapFault::EmptyHeader));
            }
            if entries.iter().any(|(t, _)| t == target) {
                return Err(at(ColumnMapFault::DuplicateTarget));
            }
            if entries.iter().any(|(_, h)| h == header.trim()) {
                return Err(at(ColumnMapFault::DuplicateHeader));
            }
            entries.push((target.to_owned(), header.trim().to_owned()));
        }
        Ok(Self { entries })
    }
}

impl fmt::Display for ColumnMap {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, (target, header)) in self.entries.iter().enumerate() {
            let separator = if i == 0 { "" } else { "," };
            write!(f, "{separator}{target}=\"{header}\"")?;
        }
        Ok(())
    }
}
