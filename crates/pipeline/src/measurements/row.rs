//! The cells of one row of a measurement file, turned into SI numbers and an orientation, each
//! refusal at its line and column.

use super::dialect::{Delimiter, Dialect};
use super::layout::{Column, OrientationColumns};
use crate::Error;
use lie::{SO3, Vector3};

/// The CSV layer's refusal as ours, at its line and field.
pub(super) fn syntax_error(e: &csv::Error, file: &str, delimiter: Delimiter) -> Error {
    let line = e.position().map_or(1, |p| p.line());
    match e.kind() {
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => Error::FieldCount {
            file: file.to_owned(),
            line,
            column: (*expected_len).min(*len) as usize + 1,
            found: *len,
            expected: *expected_len,
            delimiter: delimiter.byte() as char,
        },
        csv::ErrorKind::Utf8 { err, .. } => Error::InvalidUtf8 { file: file.to_owned(), line, column: err.field() + 1 },
        _ => Error::CsvSyntax { file: file.to_owned(), line, column: 1, message: e.to_string() },
    }
}

/// The cells of one row, read as the header's layout says.
pub(super) struct Row<'a> {
    pub record: &'a csv::StringRecord,
    pub line: u64,
    pub file: &'a str,
    pub names: &'a [String],
    pub dialect: &'a mut Dialect,
}

impl Row<'_> {
    /// The cell of `column` as an SI number.
    pub fn number(&mut self, column: Column) -> Result<f64, Error> {
        let text = self.record.get(column.index).unwrap_or("");
        let at = |text: &str| {
            (self.file.to_owned(), self.line, column.index + 1, self.names[column.index].clone(), text.to_owned())
        };
        match self.dialect.number(text) {
            Ok(Some(value)) => Ok(value * column.scale),
            Ok(None) => {
                let (file, line, column, name, text) = at(text);
                Err(Error::NotANumber { file, line, column, name, text })
            }
            Err(fault) => {
                let (file, line, column, name, text) = at(text);
                Err(Error::DecimalMark { file, line, column, name, text, fault })
            }
        }
    }

    /// The cells of `columns` as SI numbers.
    pub fn numbers(&mut self, columns: &[Column]) -> Result<Vec<f64>, Error> {
        columns.iter().map(|&c| self.number(c)).collect()
    }

    /// The orientation the row's quaternion or Euler angles give.
    pub fn orientation(&mut self, columns: &OrientationColumns) -> Result<SO3, Error> {
        match columns {
            OrientationColumns::Quaternion(c) => {
                let q = self.numbers(c)?;
                SO3::from_quaternion(q[0], q[1], q[2], q[3]).map_err(|_| Error::QuaternionNorm {
                    file: self.file.to_owned(),
                    line: self.line,
                    column: c[0].index + 1,
                    norm: q.iter().map(|v| v * v).sum::<f64>().sqrt(),
                })
            }
            OrientationColumns::Euler(c) => {
                // R = Rx(rx) · Ry(ry) · Rz(rz), the order of Leica/T-Mac exports (SPEC v2); each
                // angle is first brought into one turn, so that no finite angle makes a NaN.
                let a = self.numbers(c)?;
                let turn = |angle: f64| angle.rem_euclid(std::f64::consts::TAU);
                Ok(SO3::exp(&(Vector3::x() * turn(a[0])))
                    * SO3::exp(&(Vector3::y() * turn(a[1])))
                    * SO3::exp(&(Vector3::z() * turn(a[2]))))
            }
        }
    }
}
