//! A linear axis's periodic error per screw (or rack) pitch: the carriage of a ball-screw or
//! rack-and-pinion axis errs periodically in its own position, with the screw's lead (the
//! pinion's circumference) as period `p` (`loadsim::ScrewPeriodicModel`). It is a gear series
//! ([`GearPeriodicTerm`]) in the screw's phase `φ = 2π q / p`: `δq = Σ_h a_h cos(h φ) + b_h sin(h φ)`,
//! metres along the joint's axis (its spatial twist per metre), held and faded outside the phases
//! it was fitted on exactly as a gear series is outside its angles, and centred so that a constant
//! offset stays with the geometry.
//!
//! A kind of its own rather than a `gear_periodic` with a pitch: its item takes a length the gear's
//! does not (`screw_periodic:JOINT:PITCH_MM:HARMONICS`), a verdict that names it points at the
//! drive of a linear axis and not at a gear train, and the SPEC's `gear_periodic` stays "a
//! periodic error in a joint's own angle" for the scripts that read it.

use super::Regressor;
use crate::check::{Cursor, EffectFault};
use crate::term::{EffectTerm, NewEffect};
use crate::{
    Argument, CandidateContext, CandidateModel, Direction, EffectContext, EffectSpec, GearPeriodicTerm, IdentifiedEffect,
};
use errors::Error;
use crate::ErrorKind;
use measurements::{BoundSet, Measurement};
use serde::{Deserialize, Serialize};
use std::f64::consts::TAU;

/// A periodic error of one linear axis in its own position, per screw or rack pitch.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ScrewPeriodicTerm {
    /// The screw's lead (or the pinion's circumference), m.
    pub pitch_m: f64,
    /// The series in the screw's phase `2π q / pitch_m`: its `joint` is the axis; its angles
    /// (`fitted_range`, `turn_gaps`, `taper_rad`) are phases, rad; its `theta` and
    /// `fitted_rms_rad` are metres along the axis.
    pub series: GearPeriodicTerm,
}

impl ScrewPeriodicTerm {
    /// The screw series of 0-based `joint` with pitch `pitch_m` and `orders`, scaled on the
    /// training rows, faded as `options` says.
    pub fn new(
        joint: usize,
        pitch_m: f64,
        orders: Vec<u32>,
        rows: &[Measurement],
        options: &crate::GearOptions,
    ) -> Self {
        let phases: Vec<f64> = rows.iter().filter_map(|r| r.q.get(joint)).map(|&q| TAU * q / pitch_m).collect();
        Self { pitch_m, series: GearPeriodicTerm::from_angles(joint, orders, &phases, options) }
    }

    /// The screw's phase at the axis position `q`, m: `2π q / pitch`.
    pub fn phase(&self, q: f64) -> f64 {
        TAU * q / self.pitch_m
    }

    /// The 0-based joint.
    pub fn joint(&self) -> usize {
        self.series.joint
    }

    /// The position error at the axis position `q`, m.
    pub fn position_error(&self, q: f64) -> f64 {
        self.series.joint_error(self.phase(q))
    }

    /// Records the series' RMS over the training rows, after the fit (see
    /// [`GearPeriodicTerm::record_rms`]).
    pub fn record_rms(&mut self, rows: &[Measurement]) {
        let phases: Vec<f64> = rows.iter().filter_map(|r| r.q.get(self.series.joint)).map(|&q| self.phase(q)).collect();
        self.series.record_rms_at(&phases);
    }

    fn position(&self, row: &Measurement) -> Result<f64, Error> {
        let joint = self.series.joint;
        row.q
            .get(joint)
            .copied()
            .ok_or_else(|| Error::new(ErrorKind::EffectJoint { joint: joint + 1, joint_count: row.q.len() }))
    }
}

impl Regressor for ScrewPeriodicTerm {
    fn directions(&self) -> Vec<Direction> {
        self.series.directions()
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        Ok(self.series.features_at(self.phase(self.position(row)?)))
    }

    fn theta(&self) -> &[f64] {
        &self.series.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.series.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        let (j, pitch_mm) = (self.series.joint + 1, self.pitch_m * 1e3);
        self.series
            .orders
            .iter()
            .flat_map(|h| [format!("cos({h}·2π q{j} / {pitch_mm} mm)"), format!("sin({h}·2π q{j} / {pitch_mm} mm)")])
            .collect()
    }
}

impl EffectTerm for ScrewPeriodicTerm {
    fn after_fit(&mut self, rows: &[Measurement]) {
        self.record_rms(rows);
    }

    fn label(&self) -> String {
        let (j, pitch_mm) = (self.series.joint + 1, self.pitch_m * 1e3);
        let consecutive = self.series.orders.iter().enumerate().all(|(k, &h)| h as usize == k + 1);
        match (consecutive, self.series.orders.last()) {
            (true, Some(last)) => format!("screw_periodic:{j}:{pitch_mm}:{last}"),
            _ => format!("screw_periodic:{j}:{pitch_mm} (harmonics {:?})", self.series.orders),
        }
    }

    fn joints(&self) -> Vec<usize> {
        vec![self.series.joint + 1]
    }

    fn check(&self, cursor: &Cursor<'_>, n: usize, tools: usize) -> Result<(), EffectFault> {
        let (low, high) = robot::PITCH_BOUNDS_MM;
        cursor.finite("pitch_m", &[self.pitch_m], true)?;
        if !(low * 1e-3..=high * 1e-3).contains(&self.pitch_m) {
            let kind = crate::FaultKind::Value { value: self.pitch_m, limit: high * 1e-3 };
            return Err(cursor.fault("pitch_m", 0, "pitch_m".into(), kind));
        }
        EffectTerm::check(&self.series, cursor, n, tools)
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("pitch_m", 1);
        add("series", 1);
        self.series.count_fields(add);
    }

    /// The series' weight at the screw's phase: 1 on the positions it was fitted on, fading to 0
    /// within a quarter of the shortest period (of travel) outside them.
    fn coverage_weight(&self, row: &Measurement) -> f64 {
        self.position(row).map_or(1.0, |q| self.series.held_and_weight(self.phase(q)).1)
    }

    /// The share of a typical error the fade leaves, m along the axis.
    fn uncovered(&self, row: &Measurement) -> Option<(Direction, f64)> {
        let q = self.position(row).ok()?;
        Some((Direction::Joint(self.series.joint), self.series.faded_sigma(self.phase(q))))
    }

    fn has_sigma(&self) -> bool {
        EffectTerm::has_sigma(&self.series)
    }

    fn prior_scale(&self) -> Vec<f64> {
        self.series.prior_scale()
    }
}

impl NewEffect for ScrewPeriodicTerm {
    const ARGUMENTS: &'static [Argument] = &[Argument::Joint, Argument::Pitch, Argument::Harmonics];

    /// Harmonics `1..=harmonics` of a prismatic joint's screw phase, with the item's pitch (or,
    /// for `--effects auto`, the robot file's `pitch_mm` of the joint).
    fn build(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        let joint = spec.joint_index()?;
        let description = &context.robot.joints[joint];
        if description.kind != poe::JointKind::Prismatic {
            return Err(Error::new(ErrorKind::EffectNeedsPrismatic { effect: "screw_periodic", joint: joint + 1 }));
        }
        let pitch_m = spec.required_pitch_m(description.pitch_mm)?;
        let harmonics = spec.required_harmonics()?;
        Ok(ScrewPeriodicTerm::new(joint, pitch_m, (1..=harmonics).collect(), data.rows(), &context.gear))
    }

    /// A series of the screw's phase up to the diagnosis's longest order, on a prismatic joint
    /// that moves and whose robot file states its pitch (without it the period is unknown, and no
    /// candidate is offered); after the joint's gear-like candidates.
    fn joint_candidates(context: &CandidateContext<'_>, joint: usize) -> Result<Vec<CandidateModel>, Error> {
        let description = &context.robot.joints[joint];
        let Some(pitch_mm) = description.pitch_mm else { return Ok(Vec::new()) };
        if !context.moving.contains(&joint) || description.kind != poe::JointKind::Prismatic {
            return Ok(Vec::new());
        }
        let orders = (1..=context.longest_order).collect();
        let screw =
            ScrewPeriodicTerm::new(joint, pitch_mm * 1e-3, orders, context.data.rows(), &crate::GearOptions::default());
        Ok(vec![CandidateModel { series: true, ..CandidateModel::plain(IdentifiedEffect::ScrewPeriodic(screw), 5) }])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(positions: &[f64]) -> Vec<Measurement> {
        positions.iter().map(|&q| Measurement::at(vec![q], lie::Vector3::zeros())).collect()
    }

    #[test]
    fn the_features_repeat_every_pitch_and_fade_outside_the_fitted_travel() {
        // 0.2 … 0.6 m of travel on a 10 mm screw: 40 turns, every phase seen.
        let travel: Vec<f64> = (0..400).map(|i| 0.2 + 0.4 * f64::from(i) / 399.0).collect();
        let screw = ScrewPeriodicTerm::new(0, 0.01, vec![1, 2], &rows(&travel), &crate::GearOptions::default());
        let at = |q: f64| screw.features(&rows(&[q])[0], 0).unwrap();
        let (a, b) = (at(0.3333), at(0.3333 + 0.01));
        for (x, y) in a.iter().zip(&b) {
            assert!((x - y).abs() < 1e-9, "{a:?} against {b:?}");
        }
        assert!(a.iter().any(|v| v.abs() > 0.1), "{a:?}");
        // The phases of a whole number of turns cover the circle: no gap, applied everywhere, as a
        // gear series fitted over more than a turn is.
        assert!(screw.series.turn_gaps.is_empty(), "{:?}", screw.series.turn_gaps);
        // A quarter of a turn of travel seen (2.5 mm): outside it the series fades within a
        // quarter of the shortest period.
        let short: Vec<f64> = (0..50).map(|i| 0.3 + 0.0025 * f64::from(i) / 49.0).collect();
        let screw = ScrewPeriodicTerm::new(0, 0.01, vec![1, 2], &rows(&short), &crate::GearOptions::default());
        let weight = |q: f64| screw.coverage_weight(&rows(&[q])[0]);
        assert_eq!(weight(0.301), 1.0);
        assert_eq!(weight(0.3025 + 0.01 * 0.25 / 2.0 * 1.01), 0.0);
        assert!(weight(0.3025 + 0.0002) < 1.0 && weight(0.3025 + 0.0002) > 0.0);
        assert_eq!(screw.label(), "screw_periodic:1:10:2");
        assert_eq!(screw.parameter_names()[0], "cos(1·2π q1 / 10 mm)");
    }
}
