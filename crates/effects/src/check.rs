//! The effects of a model file checked once, on reading: every index within the robot, every
//! count consistent, every value finite. A fault names the field and its occurrence within the
//! `effects` list, so that the caller can place it in the file. Each effect checks its own fields
//! (`EffectTerm::check`, in its file) through a [`Cursor`]; this module places the faults.

use super::{IdentifiedEffect, LoadFrame};
use errors::{CommonKind, Error};

/// What is wrong, where.
#[derive(Debug)]
pub struct EffectFault {
    /// The field path, e.g. `effects[1].theta`.
    pub path: String,
    /// The line and column of the field in the file.
    pub position: (usize, usize),
    /// What is wrong.
    pub kind: FaultKind,
}

/// The kinds of [`EffectFault`]; each becomes the [`Error`] variant of the same name.
#[derive(Debug)]
#[allow(missing_docs)] // the fields are those of the `Error` variants they become
pub enum FaultKind {
    /// A list of the wrong length.
    Count { what: &'static str, found: usize, expected: usize },
    /// An index beyond the robot's joints or tools.
    Index { index: usize, limit: usize },
    /// A value that is not finite.
    NotFinite { value: f64 },
    /// A value beyond a sanity bound.
    Value { value: f64, limit: f64 },
    /// Two ends of a range in the wrong order.
    Order { low: f64, high: f64 },
}

impl EffectFault {
    /// The error of this fault in file `file`.
    pub fn into_error(self, file: &str) -> Error {
        let (line, column) = self.position;
        let file = file.to_owned();
        let field = self.path;
        match self.kind {
            FaultKind::Count { what, found, expected } => {
                Error::at_line(file, line as u64, column, CommonKind::ModelCount { field, what, found, expected })
            }
            FaultKind::Index { index, limit } => {
                Error::at_line(file, line as u64, column, CommonKind::ModelIndex { field, index, limit })
            }
            FaultKind::NotFinite { value } => {
                Error::at_line(file, line as u64, column, CommonKind::NotFinite { field, value })
            }
            FaultKind::Value { value, limit } => {
                Error::at_line(file, line as u64, column, CommonKind::ModelValue { field, value, limit })
            }
            FaultKind::Order { low, high } => Error::at_line(
                file,
                line as u64,
                column,
                CommonKind::RonFormat {
                    message: format!("{field} is [{low}, {high}]: its first value must not exceed its second"),
                },
            ),
        }
    }
}

/// Counts occurrences of field names within the effects list, effect by effect, so that a fault
/// is placed at its own occurrence.
pub(crate) struct Cursor<'a> {
    effect: usize,
    seen: std::collections::HashMap<&'static str, usize>,
    locate: &'a dyn Fn(&str, usize) -> (usize, usize),
}

impl Cursor<'_> {
    pub(crate) fn fault(&self, field: &'static str, within: usize, path: String, kind: FaultKind) -> EffectFault {
        let occurrence = self.seen.get(field).copied().unwrap_or(0) + within;
        EffectFault {
            path: format!("effects[{}].{path}", self.effect),
            position: (self.locate)(field, occurrence),
            kind,
        }
    }

    pub(crate) fn finite(&self, field: &'static str, values: &[f64], positive: bool) -> Result<(), EffectFault> {
        match values.iter().position(|v| !v.is_finite() || (positive && *v <= 0.0)) {
            Some(k) => Err(self.fault(field, 0, format!("{field}[{k}]"), FaultKind::NotFinite { value: values[k] })),
            None => Ok(()),
        }
    }

    pub(crate) fn count(&self, field: &'static str, found: usize, expected: usize) -> Result<(), EffectFault> {
        if found == expected {
            Ok(())
        } else {
            Err(self.fault(field, 0, field.to_owned(), FaultKind::Count { what: "values", found, expected }))
        }
    }

    pub(crate) fn joint(
        &self,
        field: &'static str,
        within: usize,
        path: String,
        joint: usize,
        n: usize,
    ) -> Result<(), EffectFault> {
        if joint < n {
            Ok(())
        } else {
            Err(self.fault(field, within, path, FaultKind::Index { index: joint, limit: n }))
        }
    }

    pub(crate) fn load(&self, load: &LoadFrame, n: usize, tools: usize) -> Result<(), EffectFault> {
        let base = &load.base_model;
        if base.joint_count() != n {
            let kind = FaultKind::Count { what: "joints", found: base.joint_count(), expected: n };
            return Err(self.fault("base_model", 0, "base_model".into(), kind));
        }
        if base.tool_count() != tools {
            let kind = FaultKind::Count { what: "tools", found: base.tool_count(), expected: tools };
            return Err(self.fault("base_model", 0, "base_model".into(), kind));
        }
        let moved = base.joints().iter().map(|j| j.previous_from_joint_zero).chain(base.tools().iter().copied());
        if let Some((_, value)) = robot::bad_translation(moved) {
            let kind = if value.is_finite() {
                FaultKind::Value { value, limit: robot::MAX_TRANSLATION_M }
            } else {
                FaultKind::NotFinite { value }
            };
            return Err(self.fault("base_model", 0, "base_model".into(), kind));
        }
        self.finite("gravity_m_per_s2", &load.gravity_m_per_s2, false)
    }

    /// The payload span of a load-driven effect: every end finite, the lower not above the upper.
    pub(crate) fn payload_span(&self, span: Option<&crate::PayloadSpan>) -> Result<(), EffectFault> {
        let Some(span) = span else { return Ok(()) };
        let ranges = std::iter::once(("kg", 0, "payload_span.kg".to_owned(), span.kg));
        let torques = span
            .torque_nm
            .iter()
            .enumerate()
            .map(|(k, r)| ("torque_nm", 0, format!("payload_span.torque_nm[{k}]"), *r));
        for (field, within, path, [low, high]) in ranges.chain(torques) {
            if let Some(&value) = [low, high].iter().find(|v| !v.is_finite()) {
                return Err(self.fault(field, within, path, FaultKind::NotFinite { value }));
            }
            if low > high {
                return Err(self.fault(field, within, path, FaultKind::Order { low, high }));
            }
        }
        Ok(())
    }

    /// Counts the fields of a payload span ([`Cursor::payload_span`]).
    pub(crate) fn count_payload_span(span: Option<&crate::PayloadSpan>, add: &mut dyn FnMut(&'static str, usize)) {
        if let Some(span) = span {
            add("payload_span", 1);
            add("kg", 1);
            add("torque_nm", usize::from(!span.torque_nm.is_empty()));
        }
    }

    /// Counts the fields of one effect, so that the next effect's occurrences start after them.
    fn advance(&mut self, effect: &IdentifiedEffect) {
        let mut add = |field: &'static str, count: usize| *self.seen.entry(field).or_insert(0) += count;
        add("theta", 1);
        effect.term().count_fields(&mut add);
        self.effect += 1;
    }
}

/// Checks every effect of a model with `n` joints and `tools` tools; `locate` gives the line and
/// column of the `occurrence`-th (0-based, counted from the start of the effects list) `field:`.
pub fn check_effects(
    effects: &[IdentifiedEffect],
    n: usize,
    tools: usize,
    locate: &dyn Fn(&str, usize) -> (usize, usize),
) -> Result<(), EffectFault> {
    let mut cursor = Cursor { effect: 0, seen: std::collections::HashMap::new(), locate };
    for effect in effects {
        effect.term().check(&cursor, n, tools)?;
        cursor.finite("theta", effect.theta(), false)?;
        // The features are scaled to RMS 1 on the training poses, so a coefficient is the effect's
        // RMS size in rad or m: beyond a kilometre it is a corrupt file, not a robot.
        let limit = robot::MAX_TRANSLATION_M;
        if let Some(k) = effect.theta().iter().position(|v| v.abs() > limit) {
            let kind = FaultKind::Value { value: effect.theta()[k], limit };
            return Err(cursor.fault("theta", 0, format!("theta[{k}]"), kind));
        }
        cursor.advance(effect);
    }
    Ok(())
}
