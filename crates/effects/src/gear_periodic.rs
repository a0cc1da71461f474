//! Gear (or encoder) periodic error: a smooth periodic function of one joint's own angle, as a
//! Fourier series `δq_j = Σ_h a_h cos(h q_j) + b_h sin(h q_j)` (`loadsim::periodic_joint_regressor`)
//! of any order.
//!
//! A series is known only near the angles it was fitted on: a series of order 48 fitted on a 130°
//! arc says nothing of the rest of the circle, and past the last training angle it can reach tens
//! of millimetres within a few degrees (UR10 series B, 20 mm). So the series is fitted
//! and applied *held and faded*: at an angle outside the fitted angles (past either end, or in a
//! gap wider than half the shortest period) it is evaluated at the nearest fitted angle and
//! multiplied by a raised-cosine taper that reaches zero [`GearPeriodicTerm::taper_rad`] away, where
//! the model is the geometry alone. Each feature has its mean over the training angles removed, so
//! that a constant joint offset stays with the geometry, which holds it everywhere, rather than
//! with the series, which fades.

use super::{Regressor, rms_scales};
use crate::Direction;
use crate::check::{Cursor, EffectFault, FaultKind};
use crate::term::{EffectTerm, NewEffect};
use crate::{Argument, CandidateContext, CandidateModel, EffectContext, EffectSpec, IdentifiedEffect, MAX_HARMONICS};
use errors::{Error, OptionOutOfRange};
use crate::ErrorKind;
use measurements::{BoundSet, Measurement};
use serde::{Deserialize, Serialize};

/// A periodic error of one joint in its own angle.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GearPeriodicTerm {
    /// 0-based joint.
    pub joint: usize,
    /// The harmonic orders, each with a cosine then a sine parameter.
    pub orders: Vec<u32>,
    /// Each feature is divided by this (its RMS on the training poses; 1 where it vanishes).
    pub scale: Vec<f64>,
    /// The coefficients, rad per unit of the scaled feature: `cos(h₁q), sin(h₁q), cos(h₂q), …`.
    pub theta: Vec<f64>,
    /// The joint's smallest and largest angle on the training poses, rad: the series is known
    /// only there (a series of order 48 fitted on a 130° arc says nothing of the rest of the
    /// circle), and `eval`, `predict` and `compensate` warn about rows outside it. Absent in model
    /// files written before it was recorded.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted_range: Option<[f64; 2]>,
    /// Open intervals inside `fitted_range` with no training angle that are wider than half the
    /// series' shortest period (`π / h_max`, the sampling theorem's spacing): the series is not
    /// determined there either, and rows inside them are warned about like rows outside.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub fitted_gaps: Vec<[f64; 2]>,
    /// The arcs of the joint's turn (angles modulo 2π, in `[0, 2π)`; the arc across 2π ends
    /// beyond it) that hold no training angle and are wider than half the series' shortest
    /// period. The series has whole harmonics, so it repeats every turn: a wrist that turned
    /// one and a half times was fitted on `q` and on `q ± 2π` alike. Written in place of
    /// `fitted_gaps` since the taper was introduced; the series is held and faded in these arcs.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub turn_gaps: Vec<[f64; 2]>,
    /// How far outside the fitted angles (past an end, or into a gap) the series fades to zero,
    /// rad; `None` in model files written before the taper (the series is then applied as it is
    /// everywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub taper_rad: Option<f64>,
    /// The mean of each unscaled feature over the training angles, subtracted before scaling;
    /// empty in model files written before it was (nothing subtracted).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub mean: Vec<f64>,
    /// The RMS of the fitted joint error over the training angles, rad: how large the error the
    /// series corrects typically is, and so the uncertainty left where it fades out (recorded
    /// by `fit`; absent in older files).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fitted_rms_rad: Option<f64>,
    /// The prior's smoothness ([`GearOptions::roughness_order`]) the series was fitted with.
    #[serde(default)]
    pub roughness_order: f64,
}

/// How a gear series is held and faded outside the angles it was fitted on.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GearOptions {
    /// The taper's width as a fraction of the series' shortest period `2π / h_max`. 0.25: a
    /// quarter period is the distance over which the highest harmonic goes from a crest to a
    /// zero, so no harmonic the data resolved is extrapolated further than its own correlation
    /// length; half the gap threshold (half a period, the sampling theorem's spacing), so that
    /// the taper reaches zero in the middle of every gap and the held value is continuous.
    pub taper_fraction_of_period: f64,
    /// The smoothness of the prior on the coefficients: harmonic `h`'s prior standard deviation
    /// is the effects' `prior_sigma` divided by `h^roughness_order` (a spectral smoothness prior:
    /// order 1 penalises the energy of the series' derivative, `∫ f'² = π Σ h² (a_h² + b_h²)`,
    /// Wahba, *Spline Models for Observational Data*, 1990, §2.2). Coefficients the data determine
    /// are barely moved (a UR10 harmonic is determined to a few µrad); combinations of high
    /// harmonics that cancel on the training angles, and so only matter where there are none,
    /// are held near zero instead of trading against each other.
    pub roughness_order: f64,
}

impl Default for GearOptions {
    fn default() -> Self {
        Self { taper_fraction_of_period: 0.25, roughness_order: 1.0 }
    }
}

impl GearOptions {
    /// Refuses a taper fraction outside (0, 0.25]: a wider taper would not reach zero inside a
    /// gap.
    pub fn validate(&self) -> Result<(), OptionOutOfRange> {
        let f = self.taper_fraction_of_period;
        let taper = f.is_finite() && f > 0.0 && f <= 0.25;
        OptionOutOfRange::check("taper_fraction_of_period", f, taper, "a number in (0, 0.25]")?;
        let r = self.roughness_order;
        OptionOutOfRange::check("roughness_order", r, r.is_finite() && (0.0..=4.0).contains(&r), "a number in [0, 4]")
    }
}

impl GearPeriodicTerm {
    /// The gear series of `joint` (1-based) with `orders`, scaled on the training rows, with the
    /// default [`GearOptions`].
    pub fn new(joint: usize, orders: Vec<u32>, rows: &[Measurement]) -> Result<Self, Error> {
        Self::with_options(joint, orders, rows, &GearOptions::default())
    }

    /// [`GearPeriodicTerm::new`] with the taper of `options`.
    pub fn with_options(
        joint: usize,
        orders: Vec<u32>,
        rows: &[Measurement],
        options: &GearOptions,
    ) -> Result<Self, Error> {
        let angles: Vec<f64> = rows.iter().filter_map(|row| row.q.get(joint).copied()).collect();
        Ok(Self::from_angles(joint, orders, &angles, options))
    }

    /// The series of `joint` fitted on the angles `angles` (rad; for a screw, its phases,
    /// `crate::ScrewPeriodicTerm`), with the taper of `options`.
    pub(crate) fn from_angles(joint: usize, orders: Vec<u32>, angles: &[f64], options: &GearOptions) -> Self {
        let fitted_range = angles.iter().fold(None, |range: Option<[f64; 2]>, &q| {
            Some(range.map_or([q, q], |[low, high]| [low.min(q), high.max(q)]))
        });
        let AngleCoverage { turn_gaps, taper_rad, .. } = AngleCoverage::of(joint, &orders, angles, options);
        let mut model = Self {
            joint,
            orders,
            scale: Vec::new(),
            theta: Vec::new(),
            fitted_range,
            fitted_gaps: Vec::new(),
            turn_gaps,
            taper_rad,
            mean: Vec::new(),
            fitted_rms_rad: None,
            roughness_order: options.roughness_order,
        };
        let width = 2 * model.orders.len();
        model.scale = vec![1.0; width];
        let raw: Vec<Vec<f64>> = angles.iter().map(|&q| model.features_at(q)).collect();
        let count = raw.len().max(1) as f64;
        // Order 0 is the joint's bare twist (the diagnosis's backlash side uses it): a constant
        // by definition, kept as it is.
        model.mean = (0..width)
            .map(|l| if model.orders[l / 2] == 0 { 0.0 } else { raw.iter().map(|r| r[l]).sum::<f64>() / count })
            .collect();
        let centred: Vec<Vec<f64>> =
            raw.iter().map(|r| r.iter().zip(&model.mean).map(|(v, m)| v - m).collect()).collect();
        model.scale = rms_scales(&centred);
        model.theta = vec![0.0; width];
        model
    }
}

impl GearPeriodicTerm {
    /// Whether the series was fitted on poses near the angle `q` (inside the fitted range and
    /// outside its gaps); true for model files that do not record the range.
    pub fn covers(&self, q: f64) -> bool {
        if self.taper_rad.is_some() {
            return self.turn_gap(q).is_none();
        }
        let Some([low, high]) = self.fitted_range else { return true };
        (low..=high).contains(&q) && !self.fitted_gaps.iter().any(|&[a, b]| a < q && q < b)
    }

    /// The joint error at angle `q`, rad: `Σ θ_l f_l(q)`.
    pub fn joint_error(&self, q: f64) -> f64 {
        self.features_at(q).iter().zip(&self.theta).map(|(f, t)| f * t).sum()
    }

    /// The scaled features at the joint angle `q`: held, faded, centred and scaled.
    pub(crate) fn features_at(&self, q: f64) -> Vec<f64> {
        let (held, weight) = self.held_and_weight(q);
        if weight == 0.0 {
            return vec![0.0; 2 * self.orders.len()];
        }
        let mean = |l: usize| self.mean.get(l).copied().unwrap_or(0.0);
        self.orders
            .iter()
            .flat_map(|&h| loadsim::periodic_joint_regressor(held, f64::from(h)))
            .zip(&self.scale)
            .enumerate()
            .map(|(l, (v, s))| (v - mean(l)) * weight / s)
            .collect()
    }

    /// Records [`GearPeriodicTerm::fitted_rms_rad`] over the training rows, after the fit.
    pub fn record_rms(&mut self, rows: &[Measurement]) {
        let angles: Vec<f64> = rows.iter().filter_map(|r| r.q.get(self.joint).copied()).collect();
        self.record_rms_at(&angles);
    }

    /// Records [`GearPeriodicTerm::fitted_rms_rad`] over the training angles `angles`.
    pub(crate) fn record_rms_at(&mut self, angles: &[f64]) {
        let values: Vec<f64> = angles.iter().map(|&q| self.joint_error(q)).collect();
        let rms = (values.iter().map(|v| v * v).sum::<f64>() / values.len().max(1) as f64).sqrt();
        self.fitted_rms_rad = rms.is_finite().then_some(rms);
    }

    /// The standard deviation of the joint error the model leaves uncorrected at `q`, rad: where
    /// the series fades out by `1 − w`, that share of a typical error (its RMS on the training
    /// angles) is unknown; 0 on the fitted angles (there the series' own uncertainty, a few µrad
    /// on real data, is far below it) and for files that do not record the RMS.
    pub fn faded_sigma(&self, q: f64) -> f64 {
        self.fitted_rms_rad.map_or(0.0, |rms| (1.0 - self.held_and_weight(q).1) * rms)
    }

    /// The turn gap `q` lies in, with `q`'s angle in that gap's coordinates.
    fn turn_gap(&self, q: f64) -> Option<(f64, [f64; 2])> {
        turn_gap(&self.turn_gaps, q)
    }

    /// The prior standard deviation of each parameter relative to the effects' `prior_sigma`:
    /// `h^-roughness_order` for both of harmonic `h`'s coefficients.
    pub fn prior_scale(&self) -> Vec<f64> {
        self.orders.iter().flat_map(|&h| [f64::from(h.max(1)).powf(-self.roughness_order); 2]).collect()
    }

    /// The angle the series is evaluated at for `q` (the nearest fitted angle where `q` lies
    /// outside them) and the weight it is applied with there (1 on the fitted angles, fading to
    /// 0 over [`GearPeriodicTerm::taper_rad`]). Older files without a taper: `(q, 1)` everywhere.
    pub fn held_and_weight(&self, q: f64) -> (f64, f64) {
        held_and_weight(&self.turn_gaps, self.taper_rad, q)
    }
}

/// Where a joint's series of the orders up to the highest fitted was fitted on the turn of its
/// angles, and how it fades beyond: what [`GearPeriodicTerm::held_and_weight`] reads, without the
/// series' features (their means and scales over the angles cost a sine and cosine per order
/// and angle). For a caller that needs only the coverage of a fit on some angles (the
/// diagnosis's arcs, once per fold).
#[derive(Debug, Clone, PartialEq)]
pub struct AngleCoverage {
    /// The 0-based joint.
    pub joint: usize,
    turn_gaps: Vec<[f64; 2]>,
    taper_rad: Option<f64>,
}

impl AngleCoverage {
    /// The coverage of a series of `joint` with `orders` fitted on `angles` (rad), as
    /// [`GearPeriodicTerm`] records it with `options`.
    pub fn of(joint: usize, orders: &[u32], angles: &[f64], options: &GearOptions) -> Self {
        let mut turn: Vec<f64> = angles.iter().map(|q| q.rem_euclid(std::f64::consts::TAU)).collect();
        turn.sort_by(f64::total_cmp);
        let h_max = f64::from(orders.iter().copied().max().unwrap_or(1).max(1));
        let spacing = std::f64::consts::PI / h_max;
        let mut turn_gaps: Vec<[f64; 2]> =
            turn.windows(2).filter(|w| w[1] - w[0] > spacing).map(|w| [w[0], w[1]]).collect();
        if let (Some(&first), Some(&last)) = (turn.first(), turn.last())
            && first + std::f64::consts::TAU - last > spacing
        {
            turn_gaps.push([last, first + std::f64::consts::TAU]);
        }
        let taper_rad = Some(options.taper_fraction_of_period * std::f64::consts::TAU / h_max);
        Self { joint, turn_gaps, taper_rad }
    }

    /// [`GearPeriodicTerm::held_and_weight`] of the series this coverage describes.
    pub fn held_and_weight(&self, q: f64) -> (f64, f64) {
        held_and_weight(&self.turn_gaps, self.taper_rad, q)
    }
}

/// The held angle and the weight at `q` of a series whose turn has the gaps `turn_gaps` and fades
/// over `taper_rad` ([`GearPeriodicTerm::held_and_weight`]).
fn held_and_weight(turn_gaps: &[[f64; 2]], taper_rad: Option<f64>, q: f64) -> (f64, f64) {
    let Some(width) = taper_rad else { return (q, 1.0) };
    let Some((t, [a, b])) = turn_gap(turn_gaps, q) else { return (q, 1.0) };
    let held_t = if t - a <= b - t { a } else { b };
    let held = q + (held_t - t);
    let distance = (held_t - t).abs();
    let weight = if distance >= width { 0.0 } else { 0.5 * (1.0 + (std::f64::consts::PI * distance / width).cos()) };
    (held, weight)
}

/// The gap of `turn_gaps` the angle `q` falls in, with `q` on that gap's turn.
fn turn_gap(turn_gaps: &[[f64; 2]], q: f64) -> Option<(f64, [f64; 2])> {
    let t = q.rem_euclid(std::f64::consts::TAU);
    turn_gaps
        .iter()
        .find_map(|&[a, b]| [t, t + std::f64::consts::TAU].into_iter().find(|&x| a < x && x < b).map(|x| (x, [a, b])))
}

impl Regressor for GearPeriodicTerm {
    fn directions(&self) -> Vec<Direction> {
        vec![Direction::Joint(self.joint); 2 * self.orders.len()]
    }

    fn features(&self, row: &Measurement, _tool: usize) -> Result<Vec<f64>, Error> {
        let q = *row
            .q
            .get(self.joint)
            .ok_or_else(|| Error::new(ErrorKind::EffectJoint { joint: self.joint + 1, joint_count: row.q.len() }))?;
        Ok(self.features_at(q))
    }

    fn theta(&self) -> &[f64] {
        &self.theta
    }

    fn theta_mut(&mut self) -> &mut Vec<f64> {
        &mut self.theta
    }

    fn parameter_names(&self) -> Vec<String> {
        let j = self.joint + 1;
        self.orders.iter().flat_map(|h| [format!("cos({h} q{j})"), format!("sin({h} q{j})")]).collect()
    }
}

impl EffectTerm for GearPeriodicTerm {
    fn after_fit(&mut self, rows: &[Measurement]) {
        self.record_rms(rows);
    }

    fn label(&self) -> String {
        let consecutive = self.orders.iter().enumerate().all(|(k, &h)| h as usize == k + 1);
        match (consecutive, self.orders.last()) {
            (true, Some(last)) => format!("gear_periodic:{}:{last}", self.joint + 1),
            _ => format!("gear_periodic:{} (harmonics {:?})", self.joint + 1, self.orders),
        }
    }

    fn joints(&self) -> Vec<usize> {
        vec![self.joint + 1]
    }

    fn check(&self, cursor: &Cursor<'_>, n: usize, _tools: usize) -> Result<(), EffectFault> {
        cursor.joint("joint", 0, "joint".into(), self.joint, n)?;
        if let Some(k) = self.orders.iter().position(|&h| h > MAX_HARMONICS) {
            let kind = FaultKind::Index { index: self.orders[k] as usize, limit: MAX_HARMONICS as usize + 1 };
            return Err(cursor.fault("orders", 0, format!("orders[{k}]"), kind));
        }
        cursor.count("scale", self.scale.len(), 2 * self.orders.len())?;
        cursor.count("theta", self.theta.len(), 2 * self.orders.len())?;
        cursor.finite("scale", &self.scale, true)?;
        if let Some([low, high]) = self.fitted_range {
            cursor.finite("fitted_range", &[low, high], false)?;
            if low > high {
                let kind = FaultKind::Order { low, high };
                return Err(cursor.fault("fitted_range", 0, "fitted_range".into(), kind));
            }
        }
        for (k, &[a, b]) in self.fitted_gaps.iter().enumerate() {
            cursor.finite("fitted_gaps", &[a, b], false)?;
            if a > b {
                let kind = FaultKind::Order { low: a, high: b };
                return Err(cursor.fault("fitted_gaps", 0, format!("fitted_gaps[{k}]"), kind));
            }
        }
        // The turn's gaps lie within [0, 4π): a gap starts inside the turn and the one across 2π
        // ends within the next.
        for (k, &[a, b]) in self.turn_gaps.iter().enumerate() {
            cursor.finite("turn_gaps", &[a, b], false)?;
            if a > b || a < 0.0 || b > 2.0 * std::f64::consts::TAU {
                let kind = FaultKind::Order { low: a, high: b };
                return Err(cursor.fault("turn_gaps", 0, format!("turn_gaps[{k}]"), kind));
            }
        }
        if let Some(taper) = self.taper_rad {
            cursor.finite("taper_rad", &[taper], true)?;
        }
        if !self.mean.is_empty() {
            cursor.count("mean", self.mean.len(), 2 * self.orders.len())?;
            cursor.finite("mean", &self.mean, false)?;
        }
        if let Some(rms) = self.fitted_rms_rad {
            cursor.finite("fitted_rms_rad", &[rms], false)?;
            if rms < 0.0 {
                let kind = FaultKind::Order { low: 0.0, high: rms };
                return Err(cursor.fault("fitted_rms_rad", 0, "fitted_rms_rad".into(), kind));
            }
        }
        if !(0.0..=4.0).contains(&self.roughness_order) {
            let kind = FaultKind::Value { value: self.roughness_order, limit: 4.0 };
            return Err(cursor.fault("roughness_order", 0, "roughness_order".into(), kind));
        }
        Ok(())
    }

    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize)) {
        add("joint", 1);
        add("orders", 1);
        add("scale", 1);
        add("fitted_range", usize::from(self.fitted_range.is_some()));
        add("fitted_gaps", usize::from(!self.fitted_gaps.is_empty()));
        add("turn_gaps", usize::from(!self.turn_gaps.is_empty()));
        add("taper_rad", usize::from(self.taper_rad.is_some()));
        add("mean", usize::from(!self.mean.is_empty()));
        add("fitted_rms_rad", usize::from(self.fitted_rms_rad.is_some()));
        add("roughness_order", 1);
    }

    /// 1 on the joint angles it was fitted on, fading to 0 outside them
    /// ([`GearPeriodicTerm::held_and_weight`]).
    fn coverage_weight(&self, row: &Measurement) -> f64 {
        row.q.get(self.joint).map_or(1.0, |&q| self.held_and_weight(q).1)
    }

    /// [`GearPeriodicTerm::faded_sigma`] along the joint's twist.
    fn uncovered(&self, row: &Measurement) -> Option<(Direction, f64)> {
        row.q.get(self.joint).map(|&q| (Direction::Joint(self.joint), self.faded_sigma(q)))
    }

    fn has_sigma(&self) -> bool {
        self.fitted_rms_rad.is_some() && self.taper_rad.is_some()
    }

    fn prior_scale(&self) -> Vec<f64> {
        GearPeriodicTerm::prior_scale(self)
    }
}

impl NewEffect for GearPeriodicTerm {
    const ARGUMENTS: &'static [Argument] = &[Argument::Joint, Argument::Harmonics];

    /// Harmonics `1..=harmonics` of a revolute joint (on a linear axis the period of a screw or
    /// rack is a length, which this series has no parameter for), faded as `context.gear` says.
    fn build(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        let joint = spec.joint_index()?;
        if context.robot.joints[joint].kind == poe::JointKind::Prismatic {
            return Err(Error::new(ErrorKind::EffectJointKind { effect: "gear_periodic", joint: joint + 1 }));
        }
        let harmonics = spec.required_harmonics()?;
        GearPeriodicTerm::with_options(joint, (1..=harmonics).collect(), data.rows(), &context.gear)
    }

    /// A series of the joint's own angle up to the diagnosis's longest order, for a revolute
    /// joint that moves; last among the joint's candidates.
    fn joint_candidates(context: &CandidateContext<'_>, joint: usize) -> Result<Vec<CandidateModel>, Error> {
        if !context.moving.contains(&joint) || context.robot.joints[joint].kind != poe::JointKind::Revolute {
            return Ok(Vec::new());
        }
        let gear = GearPeriodicTerm::new(joint, (1..=context.longest_order).collect(), context.data.rows())?;
        Ok(vec![CandidateModel { series: true, ..CandidateModel::plain(IdentifiedEffect::GearPeriodic(gear), 4) }])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    fn rows(angles: &[f64]) -> Vec<Measurement> {
        angles.iter().map(|&q| Measurement::at(vec![q], lie::Vector3::zeros())).collect()
    }

    /// `n` angles evenly from `low` to `high`.
    fn spread(low: f64, high: f64, n: usize) -> Vec<f64> {
        (0..n).map(|i| low + (high - low) * i as f64 / (n - 1) as f64).collect()
    }

    #[test]
    fn inside_the_fitted_angles_the_series_is_applied_whole_and_past_the_end_it_fades_to_zero() {
        let gear = GearPeriodicTerm::new(0, (1..=12).collect(), &rows(&spread(-1.0, 0.5, 200))).unwrap();
        let width = gear.taper_rad.unwrap();
        assert!((width - 0.25 * TAU / 12.0).abs() < 1e-15, "{width}");
        for q in [-1.0, -0.3, 0.0, 0.5] {
            assert_eq!(gear.held_and_weight(q), (q, 1.0), "{q}");
            assert!(gear.covers(q));
        }
        // Past the end the series is held at the last fitted angle, its weight falling smoothly.
        let mut previous = 1.0;
        for k in 1..=20 {
            let q = 0.5 + width * f64::from(k) / 20.0;
            let (held, weight) = gear.held_and_weight(q);
            assert!((held - 0.5).abs() < 1e-12, "{q}: held at {held}");
            assert!(weight < previous && weight >= 0.0, "{q}: {weight} after {previous}");
            assert!(!gear.covers(q));
            previous = weight;
        }
        assert_eq!(gear.held_and_weight(0.5 + 1.01 * width).1, 0.0);
        assert_eq!(gear.held_and_weight(-1.0 - 1.01 * width).1, 0.0);
        // Fading at zero weight, the features vanish: the effect is the geometry's.
        let features = gear.features(&rows(&[2.0])[0], 0).unwrap();
        assert!(features.iter().all(|&f| f == 0.0), "{features:?}");
    }

    #[test]
    fn a_gap_wider_than_half_the_shortest_period_is_faded_in_its_middle_and_a_narrower_one_is_not() {
        let order = 12;
        let spacing = PI / f64::from(order);
        let mut angles = spread(-1.0, -0.2, 100);
        angles.extend(spread(0.2, 1.0, 100)); // a 0.4 rad gap, wider than π/12 = 0.26
        angles.extend(spread(1.0 + 0.9 * spacing, 1.5, 50)); // a gap just under the spacing
        let gear = GearPeriodicTerm::new(0, (1..=order).collect(), &rows(&angles)).unwrap();
        assert_eq!(gear.held_and_weight(0.0).1, 0.0);
        let (held, weight) = gear.held_and_weight(-0.19);
        assert!((held + 0.2).abs() < 1e-12 && weight > 0.9, "{held} {weight}");
        assert_eq!(gear.held_and_weight(1.0 + 0.45 * spacing), (1.0 + 0.45 * spacing, 1.0));
    }

    #[test]
    fn the_fitted_angles_wrap_with_the_turn_so_a_wrist_fitted_over_more_than_a_turn_has_no_gap() {
        // -4 … 2.5 rad is more than a turn: every angle of the circle was seen, once or twice.
        let gear = GearPeriodicTerm::new(0, (1..=24).collect(), &rows(&spread(-4.0, 2.5, 2000))).unwrap();
        assert!(gear.turn_gaps.is_empty(), "{:?}", gear.turn_gaps);
        for q in [-10.0, -4.5, 3.0, 7.0] {
            assert_eq!(gear.held_and_weight(q), (q, 1.0), "{q}");
        }
        // The same angles one turn away count as fitted: 0.3 + 2π lies where 0.3 was seen.
        let gear = GearPeriodicTerm::new(0, (1..=24).collect(), &rows(&spread(0.0, 1.0, 300))).unwrap();
        assert_eq!(gear.held_and_weight(0.3 + TAU).1, 1.0);
        assert_eq!(gear.held_and_weight(3.0).1, 0.0);
    }

    #[test]
    fn the_features_have_no_mean_over_the_training_angles_so_a_constant_offset_stays_with_the_geometry() {
        let training = rows(&spread(-0.4, 0.9, 300));
        let gear = GearPeriodicTerm::new(0, (1..=6).collect(), &training).unwrap();
        let features: Vec<Vec<f64>> = training.iter().map(|r| gear.features(r, 0).unwrap()).collect();
        for l in 0..12 {
            let mean = features.iter().map(|f| f[l]).sum::<f64>() / features.len() as f64;
            let rms = (features.iter().map(|f| f[l] * f[l]).sum::<f64>() / features.len() as f64).sqrt();
            assert!(mean.abs() < 1e-12, "feature {l}: mean {mean}");
            assert!((rms - 1.0).abs() < 1e-12, "feature {l}: rms {rms}");
        }
    }

    #[test]
    fn order_zero_is_the_bare_twist_and_keeps_its_constant_feature() {
        let gear = GearPeriodicTerm::new(0, vec![0], &rows(&spread(-0.4, 0.9, 30))).unwrap();
        assert_eq!(gear.features(&rows(&[0.3])[0], 0).unwrap(), vec![1.0, 0.0]);
    }

    #[test]
    fn a_model_file_without_the_taper_applies_its_series_everywhere_as_it_did() {
        let mut gear = GearPeriodicTerm::new(0, vec![1, 2], &rows(&spread(0.0, 0.5, 50))).unwrap();
        gear.taper_rad = None;
        gear.mean.clear();
        assert_eq!(gear.held_and_weight(3.0), (3.0, 1.0));
        assert!(gear.features(&rows(&[3.0])[0], 0).unwrap().iter().any(|&f| f != 0.0));
    }

    #[test]
    fn the_taper_and_the_roughness_are_validated() {
        assert!(GearOptions::default().validate().is_ok());
        for taper in [0.0, -0.1, 0.3, f64::NAN] {
            let options = GearOptions { taper_fraction_of_period: taper, ..GearOptions::default() };
            assert_eq!(options.validate().unwrap_err().field, "taper_fraction_of_period", "{taper}");
        }
        for roughness in [-1.0, 5.0, f64::INFINITY] {
            let options = GearOptions { roughness_order: roughness, ..GearOptions::default() };
            assert_eq!(options.validate().unwrap_err().field, "roughness_order", "{roughness}");
        }
    }
}
