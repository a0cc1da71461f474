//! The robot's joint limits, kept in the model file by `fit`: `eval`, `predict` and
//! `compensate` count the rows that put a joint beyond them. Such a row is a pose the arm cannot
//! take (degrees under `_rad`, a file of another robot, a typo), and whatever the model answers
//! there was never measured. The fitted span (`training_range.rs`) says where the model was
//! fitted; this says where the robot can be at all, and holds for models fitted on part of it.

use measurements::Measurement;
use serde::{Deserialize, Serialize};

/// The limits as a model file keeps them: per joint `[lower, upper]` in SI units (rad, m), `None`
/// for a joint without limits (a URDF's continuous joint).
pub fn stored_limits(limits: &[(f64, f64)]) -> Vec<Option<[f64; 2]>> {
    limits.iter().map(|&(lo, hi)| (lo.is_finite() && hi.is_finite()).then_some([lo, hi])).collect()
}

/// The first stored limit that is not a finite range, smallest first, or a list of the wrong
/// length: its index and the offending value.
pub(crate) fn limits_fault(limits: &[Option<[f64; 2]>], joints: usize) -> Option<(usize, f64)> {
    if !limits.is_empty() && limits.len() != joints {
        return Some((limits.len(), limits.len() as f64));
    }
    limits.iter().enumerate().find_map(|(j, range)| {
        let [lo, hi] = (*range)?;
        [lo, hi].into_iter().find(|v| !v.is_finite()).or((lo > hi).then_some(lo)).map(|v| (j, v))
    })
}

/// Rows that put a joint beyond the robot's limits: one warning per such joint.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BeyondLimitsWarning {
    /// The 1-based joint.
    pub joint: usize,
    /// Its unit: `rad`, or `m` for a prismatic joint.
    #[serde(deserialize_with = "crate::unit_name::deserialize")]
    pub unit: crate::unit_name::Unit,
    /// The robot description's limits, `[lower, upper]`.
    pub limits: [f64; 2],
    /// How many rows put the joint beyond them.
    pub rows_outside: usize,
    /// How many rows there are.
    pub rows: usize,
    /// The file line of the first of them.
    pub first_line: u64,
    /// The joint's value there.
    pub first_value: f64,
}

impl std::fmt::Display for BeyondLimitsWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [lo, hi] = self.limits;
        write!(
            f,
            "{} of {} rows (the first at line {}, {:.4} {unit}) put joint {} beyond the robot's limits \
             ({lo:.4} … {hi:.4} {unit}): the arm cannot take these poses, and what the model answers there \
             was never measured (degrees under _rad? another robot's file?)",
            self.rows_outside,
            self.rows,
            self.first_line,
            self.first_value,
            self.joint,
            unit = self.unit
        )
    }
}

/// One warning per joint that some of `rows` put beyond `limits` (`prismatic[j]`: whether joint
/// `j` is prismatic, for its unit).
pub fn beyond_limits(
    limits: &[Option<[f64; 2]>],
    prismatic: &[bool],
    rows: &[Measurement],
) -> Vec<BeyondLimitsWarning> {
    limits
        .iter()
        .enumerate()
        .filter_map(|(j, range)| {
            let [lo, hi] = (*range)?;
            let mut beyond =
                rows.iter().filter_map(|r| r.q.get(j).filter(|&&q| q < lo || q > hi).map(|&q| (r.line, q)));
            let (first_line, first_value) = beyond.next()?;
            Some(BeyondLimitsWarning {
                joint: j + 1,
                unit: if prismatic.get(j).copied().unwrap_or(false) { "m" } else { "rad" },
                limits: [lo, hi],
                rows_outside: 1 + beyond.count(),
                rows: rows.len(),
                first_line,
                first_value,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(line: u64, q: [f64; 2]) -> Measurement {
        Measurement { line, ..Measurement::at(q.to_vec(), lie::Vector3::zeros()) }
    }

    #[test]
    fn rows_beyond_a_limit_are_counted_per_joint_from_the_first_line() {
        let limits = stored_limits(&[(-1.0, 1.0), (f64::NEG_INFINITY, f64::INFINITY)]);
        assert_eq!(limits, [Some([-1.0, 1.0]), None]);
        let rows = [row(2, [0.5, 1e3]), row(3, [100.0, 0.0]), row(4, [-1.0, 0.0]), row(5, [-1.5, 0.0])];
        let warnings = beyond_limits(&limits, &[false, true], &rows);
        assert_eq!(warnings.len(), 1, "the joint without limits is never beyond them");
        let w = &warnings[0];
        assert_eq!((w.joint, w.unit, w.rows_outside, w.rows, w.first_line, w.first_value), (1, "rad", 2, 4, 3, 100.0));
        assert!(w.to_string().starts_with("2 of 4 rows (the first at line 3, 100.0000 rad) put joint 1 beyond"));
        assert!(beyond_limits(&limits, &[false, false], &rows[..1]).is_empty(), "on the limit is inside");
    }

    #[test]
    fn a_stored_limit_that_is_not_a_range_is_a_fault() {
        assert_eq!(limits_fault(&[Some([-1.0, 1.0]), None], 2), None);
        assert_eq!(limits_fault(&[], 6), None, "files written before the limits were kept");
        assert_eq!(limits_fault(&[Some([1.0, -1.0])], 1), Some((0, 1.0)));
        assert_eq!(limits_fault(&[None, Some([f64::NAN, 1.0])], 2).map(|(j, _)| j), Some(1));
        assert_eq!(limits_fault(&[None], 2), Some((1, 1.0)));
    }
}
