//! Non-geometric effects, each defined once as its regressor: per row, one scalar feature per
//! parameter, times the twist that parameter moves the pose along ([`Direction`]: a joint's
//! spatial twist, a fixed left twist, or the arm's thermal growth). The pose error is, to first
//! order, `y ≈ Σ_l θ_l f_l(row) c_l(q)`, and the effect moves a pose by `exp((Σ_l θ_l f_l c_l)^) T`.
//!
//! The same definition gives the diagnosis's candidate columns (`diagnose/candidates.rs`), the
//! fit's [`poe::identify::PoseCorrection`] (module `correction`), and the calibrated model's
//! prediction ([`IdentifiedEffect::twist`], applied by `model::Part`): what the diagnosis predicts is what the fit does.
//!
//! An effect is one file: its type implements [`Regressor`] and the crate's `EffectTerm` (label,
//! joints, its checks in a model file, coverage) and `NewEffect` (the [`Argument`]s of its
//! `--effects` item, how the fit builds it, its [`CandidateModel`]s for the diagnosis), module
//! `term`. [`IdentifiedEffect`] is generated from the one list of kinds, `loadsim::effect_kinds!`
//! ([`EffectKind`]), a variant per identified kind holding the type of the same name; the
//! `--effects` parser ([`EffectSpec`]) reads the kinds' names and arguments from it; the same
//! line declares the effect's module here, named as its SPEC name (`gear_periodic.rs`), and
//! re-exports its type. Adding an effect: one line in that list and one file here; simulating it
//! too, one file of `loadsim` (`loadsim::SimulatedEffect`) with its `mod` line, and the line's
//! `=> field: Type` (docs/ARCHITECTURE.md, "Adding an effect").
//!
//! ```
//! use effects::EffectSelection;
//! let selection: EffectSelection = "gear_periodic:2:8,thermal".parse().unwrap();
//! assert_eq!(selection.to_string(), "gear_periodic:2:8,thermal");
//! assert!("gear_periodic:2".parse::<EffectSelection>().is_err()); // the harmonics are missing
//! ```
#![deny(missing_docs)]

/// The default of the fit's `EffectOptions::hold_beyond_span`, also what the diagnosis uses: thermal
/// growth and drift are applied as fitted up to this fraction of their fitted span beyond either
/// end; further out each follows its [`BeyondSpan`] rule (held, zero, or dropped to the geometry
/// fitted alone), chosen from the sessions where they can decide it. 1: a linear term is trusted as far
/// beyond its data as the data reaches (see `EffectOptions::hold_beyond_span`).
pub const HOLD_BEYOND_SPAN: f64 = 1.0;

mod beyond_span;
mod check;
mod correction;
mod direction;
mod error_kind;
mod load_frame;
mod payload_span;
mod report;
mod spec;
mod term;

pub use backlash::TorqueSign;
pub use beyond_span::BeyondSpan;
pub use direction::Direction;
pub use error_kind::ErrorKind;
pub use gear_periodic::{AngleCoverage, GearOptions};
pub use joint_compliance::{ComplianceParameter, ComplianceTorque, TorqueFit};
pub use load_frame::LoadFrame;
pub use loadsim::EffectKind;
pub use payload_span::PayloadSpan;
pub use report::{EffectReport, ParameterReport};
pub use report::{effect_reports, reported_label, reported_parameters};
pub use spec::{Argument, EffectListFault, EffectSelection, EffectSpec, MAX_HARMONICS, PITCH_BOUNDS_MM, effect_items};
pub use term::{CandidateContext, CandidateModel, CandidateOptions};

pub use check::{EffectFault, FaultKind, check_effects};
pub use correction::EffectCorrection;
pub use direction::RowTwists;

use errors::Error;
use lie::Vector6;
use measurements::{BoundSet, Measurement};
use poe::LocalPoe;
use robot::RobotDescription;
use serde::{Deserialize, Serialize};
use term::{EffectTerm, NewEffect};

/// An effect as linear in its parameters.
pub trait Regressor {
    /// The twist of each parameter.
    fn directions(&self) -> Vec<Direction>;
    /// The scaled feature of each parameter at one row (`tool`: the model's tool index).
    fn features(&self, row: &Measurement, tool: usize) -> Result<Vec<f64>, Error>;
    /// The parameters' values.
    fn theta(&self) -> &[f64];
    /// The parameters' values, to set after a fit.
    fn theta_mut(&mut self) -> &mut Vec<f64>;
    /// A name for each parameter, for reports (1-based joints).
    fn parameter_names(&self) -> Vec<String>;
}

/// The RMS of each feature over `rows` (one `Vec` per row), 1 where a feature is zero throughout,
/// so that a scaled parameter is the effect's size at a typical row.
pub fn rms_scales(rows: &[Vec<f64>]) -> Vec<f64> {
    let width = rows.first().map_or(0, Vec::len);
    (0..width)
        .map(|l| {
            let mean_sq = rows.iter().map(|r| r[l] * r[l]).sum::<f64>() / rows.len().max(1) as f64;
            if mean_sq > 0.0 && mean_sq.is_finite() { mean_sq.sqrt() } else { 1.0 }
        })
        .collect()
}

/// Refuses a column with one value on every row: an effect linear in its deviation from the mean
/// would see zero everywhere and its parameters would be unobservable.
pub fn check_column_varies(
    values: &[f64],
    rows: &[Measurement],
    effect: &'static str,
    column: &'static str,
) -> Result<(), Error> {
    match values.first() {
        Some(&value) if values.iter().all(|&v| v == value) => Err(Error::new(ErrorKind::EffectColumnConstant {
            effect,
            column,
            value,
            rows: values.len(),
            lines: [rows.first().map_or(0, |r| r.line), rows.last().map_or(0, |r| r.line)],
        })),
        _ => Ok(()),
    }
}

/// Whether every row has measured joint torques.
pub fn has_torques(rows: &[Measurement]) -> bool {
    !rows.is_empty() && rows.iter().all(|r| r.torques_nm.is_some())
}

/// Features that differ between rows by less than this, relative to their size (plus one), are
/// the same ([`IdentifiedEffect::features_constant`]): rounding of the same force computed
/// through each row's rotations (1e-16 per operation, a few hundred operations), far below any
/// change a row could identify.
pub const CONSTANT_FEATURES: f64 = 1e-9;

/// Declares each identified kind's module, named as its SPEC name (`joint_compliance.rs`, …), and
/// re-exports the kind's term type (`JointComplianceTerm`, …) from it: an effect's file is declared
/// by its line in `loadsim::effect_kinds!`, nowhere else.
macro_rules! effect_modules {
    (identified { $( $(#[$doc:meta])* $kind:ident $name:ident: $term:ident $(=> $field:ident $(| $former:literal)?: $sim:ty)?, )* }
     simulated { $( $(#[$sdoc:meta])* $skind:ident $sname:ident => $sfield:ident: $ssim:ty, )* }) => {
        $( mod $name; pub use $name::$term; )*
    };
}

loadsim::effect_kinds!(effect_modules);

/// Generates [`IdentifiedEffect`] from the identified kinds of `loadsim::effect_kinds!`: a variant
/// per kind holding the kind's term type (`GearPeriodic(GearPeriodicTerm)`), every method
/// delegated to its `EffectTerm` / `NewEffect` (module `term`).
macro_rules! identified_effect {
    (identified { $( $(#[$doc:meta])* $kind:ident $name:ident: $term:ident $(=> $field:ident $(| $former:literal)?: $sim:ty)?, )* }
     simulated { $( $(#[$sdoc:meta])* $skind:ident $sname:ident => $sfield:ident: $ssim:ty, )* }) => {
        /// An effect of a calibrated model, with its identified parameters: one variant per
        /// identified kind of `loadsim::effect_kinds!`, holding the kind's term type, written in
        /// model files under the kind's SPEC name.
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(rename_all = "snake_case")]
        pub enum IdentifiedEffect {
            $( $(#[$doc])* $kind($term), )*
        }

        impl IdentifiedEffect {
            /// The kind of the effect.
            pub fn effect_kind(&self) -> EffectKind {
                match self {
                    $( IdentifiedEffect::$kind(_) => EffectKind::$kind, )*
                }
            }

            fn term(&self) -> &dyn EffectTerm {
                match self {
                    $( IdentifiedEffect::$kind(e) => e, )*
                }
            }

            fn term_mut(&mut self) -> &mut dyn EffectTerm {
                match self {
                    $( IdentifiedEffect::$kind(e) => e, )*
                }
            }

            /// What the `--effects` item of `kind` takes after its name (none for a kind the fit
            /// does not identify).
            pub fn arguments(kind: EffectKind) -> &'static [Argument] {
                match kind {
                    $( EffectKind::$kind => <$term as NewEffect>::ARGUMENTS, )*
                    _ => &[],
                }
            }

            fn build(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
                match spec.kind {
                    $( EffectKind::$kind => {
                        <$term as NewEffect>::build(spec, context, data).map(IdentifiedEffect::$kind)
                    } )*
                    _ => Err(Error::at_line("--effects", 1, 1, ErrorKind::EffectList { text: spec.to_string(), fault: EffectListFault::UnknownEffect { items: spec::effect_items() } })),
                }
            }

            /// The diagnosis's candidates on 0-based joint `joint`, every kind's, in their
            /// [`CandidateModel::order`] (the list's order among equals).
            pub fn joint_candidates(
                context: &CandidateContext<'_>,
                joint: usize,
            ) -> Result<Vec<CandidateModel>, Error> {
                let mut all = Vec::new();
                $( all.extend(<$term as NewEffect>::joint_candidates(context, joint)?); )*
                all.sort_by_key(|c| c.order);
                Ok(all)
            }

            /// The diagnosis's candidates that concern no one joint, every kind's, in their
            /// [`CandidateModel::order`] (the list's order among equals).
            pub fn global_candidates(context: &CandidateContext<'_>) -> Result<Vec<CandidateModel>, Error> {
                let mut all = Vec::new();
                $( all.extend(<$term as NewEffect>::global_candidates(context)?); )*
                all.sort_by_key(|c| c.order);
                Ok(all)
            }
        }
    };
}

loadsim::effect_kinds!(identified_effect);

/// What the effects of a fit are built from: the robot (for gravity and masses) and the
/// calibrated kinematics (where the arm and its tools are; the payload hangs from the tools).
#[derive(Debug, Clone, Copy)]
pub struct EffectContext<'a> {
    /// The robot description.
    pub robot: &'a RobotDescription,
    /// The calibrated kinematics (reference frame: the tracker).
    pub kinematics: &'a LocalPoe,
    /// How gear series fade outside their fitted angles.
    pub gear: GearOptions,
    /// `EffectOptions::hold_beyond_span` (the fit's options).
    pub hold_beyond_span: f64,
}

impl EffectContext<'_> {
    /// The load frame, its tools placed from the rows of `data`.
    pub fn load_frame(&self, data: &BoundSet<'_>) -> Result<LoadFrame, Error> {
        LoadFrame::new(self.robot, self.kinematics, data)
    }
}

impl IdentifiedEffect {
    /// The effect `spec` names, its features scaled on the rows of `data`, its parameters at
    /// zero. Backlash takes the sign of the measured torque where every row has
    /// one, of the robot's static torque otherwise (its mass model, or a stand-in).
    pub fn new(spec: &EffectSpec, context: &EffectContext<'_>, data: &BoundSet<'_>) -> Result<Self, Error> {
        let joint_count = context.robot.joint_count();
        if let Some(joint) = spec.joint.filter(|&j| j == 0 || j > joint_count) {
            return Err(Error::new(ErrorKind::EffectJoint { joint, joint_count }));
        }
        Self::build(spec, context, data)
    }

    fn regressor(&self) -> &dyn EffectTerm {
        self.term()
    }

    /// The SPEC name of the effect (`joint_compliance`, `gear_periodic`, …).
    pub fn kind(&self) -> &'static str {
        self.effect_kind().name()
    }

    /// The gear series of an effect known only near the angles it was fitted on (see
    /// [`GearPeriodicTerm::covers`]); `None` for other effects.
    pub fn angle_coverage(&self) -> Option<&GearPeriodicTerm> {
        match self {
            IdentifiedEffect::GearPeriodic(e) if e.fitted_range.is_some() => Some(e),
            _ => None,
        }
    }

    /// How fully the effect applies at `row`: 1 on the joint angles it was fitted on, fading to 0
    /// outside them (a gear series, [`GearPeriodicTerm::held_and_weight`]); 1 for every other effect.
    pub fn coverage_weight(&self, row: &Measurement) -> f64 {
        self.term().coverage_weight(row)
    }

    /// The standard deviation of what the effect leaves uncorrected at `row`, per component of
    /// the pose error `(v, ω)` at the tool point `point` (m, rad): a gear series faded out of its
    /// fitted angles leaves a joint error of [`GearPeriodicTerm::faded_sigma`] along the joint's
    /// twist; zero elsewhere and for every other effect.
    pub fn sigma(
        &self,
        kinematics: &LocalPoe,
        row: &Measurement,
        tool: usize,
        point: &lie::Vector3,
    ) -> Result<Vector6, Error> {
        let Some((direction, sigma)) = self.term().uncovered(row) else { return Ok(Vector6::zeros()) };
        if sigma == 0.0 {
            return Ok(Vector6::zeros());
        }
        let twist = RowTwists::new(kinematics, &row.q, tool).twist(direction)?;
        let w = lie::Vector3::new(twist[3], twist[4], twist[5]);
        let v = lie::Vector3::new(twist[0], twist[1], twist[2]) + w.cross(point);
        Ok(Vector6::new(v.x.abs(), v.y.abs(), v.z.abs(), w.x.abs(), w.y.abs(), w.z.abs()) * sigma)
    }

    /// Whether the effect can report a [`IdentifiedEffect::sigma`] (a gear series that recorded
    /// its RMS).
    pub fn has_sigma(&self) -> bool {
        self.term().has_sigma()
    }

    /// What the effect is beyond the span of the input it was fitted on (`t_s`, `temp_c`); `None`
    /// for an effect of no such input.
    pub fn beyond_span(&self) -> Option<BeyondSpan> {
        self.term().beyond_span()
    }

    /// Sets [`IdentifiedEffect::beyond_span`] (nothing for an effect of no such input).
    pub fn set_beyond_span(&mut self, rule: BeyondSpan) {
        self.term_mut().set_beyond_span(rule);
    }

    /// The payloads an effect driven by the payload's load (joint compliance, link deflection) was
    /// fitted on, and its rule beyond them ([`PayloadSpan`]); `None` for other effects and for
    /// model files written before the span was recorded (extended as fitted, as they were).
    pub fn payload_span(&self) -> Option<&PayloadSpan> {
        self.term().payload_span()
    }

    /// The rule of [`IdentifiedEffect::payload_span`] beyond the span; `None` where there is none.
    pub fn beyond_payload(&self) -> Option<BeyondSpan> {
        self.payload_span().map(|s| s.beyond)
    }

    /// Sets the rule of [`IdentifiedEffect::payload_span`] (nothing where there is none).
    pub fn set_beyond_payload(&mut self, rule: BeyondSpan) {
        self.term_mut().set_beyond_payload(rule);
    }

    /// Records what the effect keeps of its training rows `rows` once its parameters are fitted
    /// (a series' RMS on them, for [`IdentifiedEffect::sigma`]); called by the fit after
    /// [`IdentifiedEffect::set_theta`].
    pub fn after_fit(&mut self, rows: &[Measurement]) {
        self.term_mut().after_fit(rows);
    }

    /// The 1-based joints the effect acts on (empty for thermal growth and drift).
    pub fn joints(&self) -> Vec<usize> {
        self.term().joints()
    }

    /// A name for reports: the SPEC item where there is one (`gear_periodic:1:24`), with what
    /// drives it.
    pub fn label(&self) -> String {
        self.term().label()
    }

    /// Number of parameters.
    pub fn parameter_count(&self) -> usize {
        self.regressor().theta().len()
    }

    /// The identified parameters (scaled: the effect's size at a typical training row).
    pub fn theta(&self) -> &[f64] {
        self.regressor().theta()
    }

    /// Sets the identified parameters after a fit (scaled, as [`IdentifiedEffect::theta`]).
    pub fn set_theta(&mut self, theta: &[f64]) {
        let own = self.term_mut().theta_mut();
        own.clear();
        own.extend_from_slice(theta);
    }

    /// A name for each parameter (1-based joints), for reports.
    pub fn parameter_names(&self) -> Vec<String> {
        self.regressor().parameter_names()
    }

    /// Each parameter's prior standard deviation relative to the effects' common one (1 but for
    /// a gear series' higher harmonics, [`GearPeriodicTerm::prior_scale`]).
    pub fn prior_scale(&self) -> Vec<f64> {
        self.term().prior_scale()
    }

    /// The twist of each parameter.
    pub fn directions(&self) -> Vec<Direction> {
        self.regressor().directions()
    }

    /// The scaled features of one row.
    pub fn features(&self, row: &Measurement, tool: usize) -> Result<Vec<f64>, Error> {
        self.regressor().features(row, tool)
    }

    /// Whether the features are the same on every row of `data` (two rows at least), to rounding
    /// ([`CONSTANT_FEATURES`]). Such an effect adds a constant twist along its directions: a joint
    /// offset or a fixed frame change, which the geometry already holds, so its parameters mean
    /// nothing (a backlash whose torque never changes sign, a compliance under the constant weight
    /// on a vertical column with one payload). The diagnosis does not offer it; the fit warns.
    pub fn features_constant(&self, data: &BoundSet<'_>) -> Result<bool, Error> {
        let mut first: Option<Vec<f64>> = None;
        for (row, tool) in data.iter() {
            let features = self.features(row, tool)?;
            match &first {
                None => first = Some(features),
                Some(f) => {
                    let scale = 1.0 + f.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
                    if f.len() != features.len()
                        || f.iter().zip(&features).any(|(a, b)| (a - b).abs() > CONSTANT_FEATURES * scale)
                    {
                        return Ok(false);
                    }
                }
            }
        }
        Ok(data.rows().len() > 1)
    }

    /// The twist the effect adds at one row under `kinematics`: `Σ_l θ_l f_l c_l`.
    pub fn twist(&self, kinematics: &LocalPoe, row: &Measurement, tool: usize) -> Result<Vector6, Error> {
        let mut twists = RowTwists::new(kinematics, &row.q, tool);
        self.twist_with(&mut twists, row, tool)
    }

    fn twist_with(&self, twists: &mut RowTwists<'_>, row: &Measurement, tool: usize) -> Result<Vector6, Error> {
        let features = self.features(row, tool)?;
        let mut total = Vector6::zeros();
        for ((direction, f), t) in self.directions().into_iter().zip(features).zip(self.theta()) {
            if *t != 0.0 && f != 0.0 {
                total += twists.twist(direction)? * (f * t);
            }
        }
        Ok(total)
    }

    /// The twist per unit of each parameter at every row of `data`: `[parameter][row]`, for the
    /// diagnosis.
    pub fn parameter_twists(&self, kinematics: &LocalPoe, data: &BoundSet<'_>) -> Result<Vec<Vec<Vector6>>, Error> {
        let directions = self.directions();
        let mut out = vec![Vec::with_capacity(data.len()); directions.len()];
        for (row, tool) in data.iter() {
            let features = self.features(row, tool)?;
            let mut twists = RowTwists::new(kinematics, &row.q, tool);
            for (l, (direction, f)) in directions.iter().zip(features).enumerate() {
                out[l].push(twists.twist(*direction)? * f);
            }
        }
        Ok(out)
    }
}

/// A stand-in mass model where the robot file gives none, used only for the *sign* of the static
/// torque (backlash): each link a slender bar from its joint's axis point to the next one's, 50 kg
/// per metre, so that the torque's sign follows where the arm's weight lies, which depends on the
/// geometry far more than on the masses.
pub fn stand_in_dynamics(robot: &RobotDescription) -> loadsim::RobotDynamics {
    let mut points: Vec<lie::Vector3> = robot.joints.iter().map(|j| lie::Vector3::from(j.point)).collect();
    points.push(lie::Vector3::from(robot.flange.position));
    let links = points
        .windows(2)
        .map(|w| loadsim::LinkInertia {
            mass_kg: 50.0 * (w[1] - w[0]).norm().max(0.05),
            com_m: ((w[0] + w[1]) * 0.5).into(),
        })
        .collect();
    loadsim::RobotDynamics {
        links,
        stiffness_nm_per_rad: vec![1.0; robot.joint_count()],
        counterbalance: None,
        gravity_m_per_s2: loadsim::FLOOR_GRAVITY_M_PER_S2,
    }
}

/// `[min, max]` of `values` widened by `beyond` times its width at either end; `None` when empty.
pub fn span_of(values: &[f64], beyond: f64) -> Option<[f64; 2]> {
    let span = values.iter().fold(None, |span, &v| Some(span.map_or([v, v], |[a, b]: [f64; 2]| [a.min(v), b.max(v)])));
    span.map(|[low, high]| [low - beyond * (high - low), high + beyond * (high - low)])
}

/// `value` held inside `span` (unchanged without one).
pub fn held_in(value: f64, span: Option<[f64; 2]>) -> f64 {
    span.map_or(value, |[low, high]| value.clamp(low, high))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_files_name_each_effect_by_its_kind() {
        let thermal = IdentifiedEffect::Thermal(ThermalTerm {
            reference_c: 20.0,
            scale: vec![1.0],
            theta: vec![0.0],
            fitted_span: None,
            beyond_span: BeyondSpan::Hold,
        });
        let text = ron::to_string(&thermal).unwrap();
        assert!(text.starts_with("thermal("), "{text}");
        assert_eq!(thermal.effect_kind(), EffectKind::Thermal);
        assert_eq!(thermal.kind(), "thermal");
        assert!(EffectKind::IDENTIFIED.iter().all(|&k| IdentifiedEffect::arguments(k).len() <= 3));
    }
}
