//! Revolute angles taken modulo 2π for the model's coverage: a joint whose limits span
//! more than a turn reaches the same link positions at `q` and `q ± 2π`, so poses measured one
//! turn away from the training poses (UR10 series D's joint 1 against C's) are where the model
//! was fitted once the turn is taken off. Only where the limits allow the other turn, only for a
//! joint that turns its frame by its angle (scale 1), and only where the wrapped angle lies inside
//! the fitted range and the given one does not. `calib register`, `eval` and `predict` all wrap
//! through [`wrapped`] and say which joints they wrapped.

use crate::CalibratedModel;
use measurements::Measurement;
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A joint whose angles some rows had wrapped into the fitted range.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WrappedJoint {
    /// The joint, from 1.
    pub joint: usize,
    /// Rows wrapped.
    pub rows_wrapped: usize,
    /// Rows.
    pub rows: usize,
    /// The turns added to them (e.g. `[-1]`), each once, ascending.
    pub turns: Vec<i64>,
    /// The file line of the first of them.
    pub first_line: u64,
}

impl std::fmt::Display for WrappedJoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let turns: Vec<String> = self.turns.iter().map(|t| format!("{t:+}·2π")).collect();
        write!(
            f,
            "joint {}: {} of {} rows (the first at line {}) lie in the range the model was fitted on only modulo 2π \
             (shifted by {}; the joint's limits span more than a turn): the model was applied at the wrapped angles, \
             the same link positions",
            self.joint,
            self.rows_wrapped,
            self.rows,
            self.first_line,
            turns.join(", ")
        )
    }
}

/// The rows with every revolute angle outside the fitted range moved by whole turns into it where
/// that is possible within the joint's limits (those spanning more than 2π), and what was moved.
/// Without a training range or stored limits nothing is moved.
pub fn wrapped(model: &CalibratedModel, rows: &[Measurement]) -> (Vec<Measurement>, Vec<WrappedJoint>) {
    let mut out = rows.to_vec();
    let mut report = Vec::new();
    let Some(range) = &model.training_range else { return (out, report) };
    for (j, joint) in model.kinematics.joints().iter().enumerate() {
        let (Some(Some([lo, hi])), Some(&[low, high])) = (model.joint_limits.get(j), range.q.get(j)) else { continue };
        // A joint that turns its frame by `scale · q` with `scale ≠ 1` (stages of one motor) is
        // not the same a turn away.
        if joint.kind != poe::JointKind::Revolute || joint.scale != 1.0 || hi - lo <= TAU {
            continue;
        }
        let mut turns = Vec::new();
        let mut first_line = None;
        let mut count = 0;
        for row in &mut out {
            let Some(q) = row.q.get(j).copied() else { continue };
            if (low..=high).contains(&q) {
                continue;
            }
            // The fewest turns that bring q inside [low, high] and keep it within the limits.
            let k_min = ((low - q) / TAU).ceil() as i64;
            let k_max = ((high - q) / TAU).floor() as i64;
            let best = (k_min..=k_max)
                .filter(|&k| k != 0)
                .map(|k| (k, q + k as f64 * TAU))
                .filter(|(_, w)| (*lo..=*hi).contains(w))
                .min_by_key(|(k, _)| k.abs());
            if let Some((k, w)) = best {
                row.q[j] = w;
                count += 1;
                first_line.get_or_insert(row.line);
                if !turns.contains(&k) {
                    turns.push(k);
                }
            }
        }
        if count > 0 {
            turns.sort_unstable();
            report.push(WrappedJoint {
                joint: j + 1,
                rows_wrapped: count,
                rows: rows.len(),
                turns,
                first_line: first_line.unwrap_or(0),
            });
        }
    }
    (out, report)
}
