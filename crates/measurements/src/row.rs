//! The cells of one row of a measurement file, turned into SI numbers and an orientation, each
//! refusal at its line and column.

use super::dialect::{Delimiter, Dialect};
use super::layout::{Column, OrientationColumns};
use crate::ErrorKind;
use errors::Error;
use lie::{SO3, Vector3};

/// The largest magnitude a column's value can have, in SI units: beyond it the cell is a unit or
/// export error, not a measurement.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct PhysicalRange {
    pub limit: f64,
    pub unit: &'static str,
    pub quantity: &'static str,
}

/// A position coordinate, m: a laser tracker measures to under 100 m, so a coordinate beyond 1 km
/// (1e6 mm) is a wrong unit or a broken export, never a measurement.
pub(super) const MAX_POSITION_M: f64 = 1e3;

/// A revolute joint's angle, rad: 1e3 rad is 160 turns, beyond the travel of any joint (even an
/// endless one's controller wraps its counter long before).
pub(super) const MAX_JOINT_ANGLE_RAD: f64 = 1e3;

/// The range of a tool position coordinate.
pub(super) const POSITION_RANGE: PhysicalRange =
    PhysicalRange { limit: MAX_POSITION_M, unit: "m", quantity: "position" };

/// The range of a prismatic joint's travel: no axis is longer than the tracker's reach.
pub(super) const JOINT_TRAVEL_RANGE: PhysicalRange =
    PhysicalRange { limit: MAX_POSITION_M, unit: "m", quantity: "joint travel" };

/// The range of a revolute joint's angle.
pub(super) const JOINT_ANGLE_RANGE: PhysicalRange =
    PhysicalRange { limit: MAX_JOINT_ANGLE_RAD, unit: "rad", quantity: "joint angle" };

/// The CSV layer's refusal as ours, at its line (as an editor counts it in `body`) and field.
pub(super) fn syntax_error(e: &csv::Error, file: &str, delimiter: Delimiter, body: &[u8]) -> Error {
    let line = super::file_lines::line_of(body, e.position());
    match e.kind() {
        csv::ErrorKind::UnequalLengths { expected_len, len, .. } => Error::at_line(
            file.to_owned(),
            line,
            (*expected_len).min(*len) as usize + 1,
            ErrorKind::FieldCount { found: *len, expected: *expected_len, delimiter: delimiter.byte() as char },
        ),
        csv::ErrorKind::Utf8 { err, .. } => {
            Error::at_line(file.to_owned(), line, err.field() + 1, errors::CommonKind::InvalidUtf8)
        }
        _ => Error::at_line(file.to_owned(), line, 1, ErrorKind::CsvSyntax { message: e.to_string() }),
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
                Err(Error::at_line(file, line, column, ErrorKind::NotANumber { name, text }))
            }
            Err(fault) => {
                let (file, line, column, name, text) = at(text);
                Err(Error::at_line(file, line, column, ErrorKind::DecimalMark { name, text, fault }))
            }
        }
    }

    /// The cells of `columns` as SI numbers.
    pub fn numbers(&mut self, columns: &[Column]) -> Result<Vec<f64>, Error> {
        columns.iter().map(|&c| self.number(c)).collect()
    }

    /// The cells of three stated standard deviations as SI numbers, each positive: a zero or a
    /// negative one would weight its row infinitely or not at all.
    pub fn standard_deviations(&mut self, columns: &[Column; 3]) -> Result<[f64; 3], Error> {
        let mut out = [0.0; 3];
        for (slot, &c) in out.iter_mut().zip(columns) {
            let value = self.number(c)?;
            if value <= 0.0 {
                let name = self.names[c.index].clone();
                let value = value / c.scale;
                return Err(Error::at_line(
                    self.file.to_owned(),
                    self.line,
                    c.index + 1,
                    ErrorKind::NotAStandardDeviation { name, value },
                ));
            }
            *slot = value;
        }
        Ok(out)
    }

    /// The cells of `columns` as SI numbers, each within `range` in magnitude.
    pub fn bounded_numbers(&mut self, columns: &[Column], range: PhysicalRange) -> Result<Vec<f64>, Error> {
        columns
            .iter()
            .map(|&c| {
                let value = self.number(c)?;
                if value.abs() <= range.limit {
                    return Ok(value);
                }
                Err(Error::at_line(
                    self.file.to_owned(),
                    self.line,
                    c.index + 1,
                    ErrorKind::BeyondPhysicalRange {
                        name: self.names[c.index].clone(),
                        value,
                        limit: range.limit,
                        unit: range.unit,
                        quantity: range.quantity,
                    },
                ))
            })
            .collect()
    }

    /// The orientation the row's quaternion or Euler angles give.
    pub fn orientation(&mut self, columns: &OrientationColumns) -> Result<SO3, Error> {
        match columns {
            OrientationColumns::Quaternion(c) => {
                let q = self.numbers(c)?;
                SO3::from_quaternion(q[0], q[1], q[2], q[3]).map_err(|_| {
                    Error::at_line(
                        self.file.to_owned(),
                        self.line,
                        c[0].index + 1,
                        ErrorKind::QuaternionNorm { norm: q.iter().map(|v| v * v).sum::<f64>().sqrt() },
                    )
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
