//! What every simulated effect implements ([`SimulatedEffect`]): its checks against a cell and
//! against the robot an effects file is read for, and its place in the forward model. [`crate::Effects`]
//! is generated from the one list of kinds (module `kinds`), a field per kind holding the type the
//! list names, and walks the effects that are on through this trait, so that a new effect's
//! simulation is its own file and its line in the list.
//!
//! The forward model has four places an effect can act, each a method with a default of none:
//! the links' lengths at the pose ([`SimulatedEffect::grown_model`]: thermal growth), the joint
//! values ([`SimulatedEffect::joint_offset`]: compliance, backlash, gear and screw errors, a
//! coupling), a left twist of the base-to-tool pose at the commanded joints
//! ([`SimulatedEffect::pose_twist`]: link deflection) and a left motion of the whole
//! tracker-to-tool pose ([`SimulatedEffect::tracker_motion`]: base drift). Tracker noise is the
//! measurement itself, drawn by `Effects::measured_pose`.

use crate::{Error, PoseContext, RobotDynamics, SimulatedCell};
use lie::{SE3, Vector6};
use poe::{JointKind, LocalPoe};

/// Largest magnitude of a joint error an effects file may give (gear and coupling amplitudes,
/// backlash half-bands), rad. Industrial transmissions err by arcminutes (3e-4 rad); 0.1 rad
/// (5.7°) is past any joint that still works, and far below where the sums of many terms could
/// overflow into a NaN pose.
pub const MAX_JOINT_ERROR_RAD: f64 = 0.1;

/// Largest harmonic order (periods per joint turn, or per screw turn) an effects file may give:
/// gear errors appear up to the tooth count of the last stage, a few hundred; beyond 1e3 the
/// angle `order · q` loses its digits.
pub const MAX_ORDER: f64 = 1e3;

/// One pose of the forward model, as an effect sees it.
#[derive(Debug, Clone, Copy)]
pub struct PoseInput<'a> {
    /// The model at this pose's temperature (grown if thermal growth is on).
    pub model: &'a LocalPoe,
    /// The cell (its dynamics and tool).
    pub cell: &'a SimulatedCell,
    /// The commanded joint values.
    pub q: &'a [f64],
    /// Payload, temperature and time of the pose.
    pub context: &'a PoseContext,
    /// The static torque at the commanded joints, N·m (empty when the robot has no dynamics).
    pub static_torque_nm: &'a [f64],
}

/// What of the robot's dynamics an effect needs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DynamicsNeed {
    /// Nothing.
    Nothing,
    /// The links' masses (backlash's torque sign, a link's bending moment).
    Masses,
    /// The masses and the joint stiffness (joint compliance).
    MassesAndStiffness,
}

/// The robot an effects file is checked against (`campaign::check_effects`).
#[derive(Debug, Clone, Copy)]
pub struct RobotFacts<'a> {
    /// The kind of each joint.
    pub joints: &'a [JointKind],
    /// The robot's dynamics, if its file gives them.
    pub dynamics: Option<&'a RobotDynamics>,
    /// The range of a screw's pitch an `--effects` item takes, mm (`robot::PITCH_BOUNDS_MM`),
    /// which an effects file's pitch must respect too.
    pub pitch_bounds_mm: (f64, f64),
}

/// What is wrong with an effect of an effects file, and the field to point at.
#[derive(Debug, Clone, PartialEq)]
pub struct EntryFault {
    /// The field of the effect's section to point at (`joint_index` for a list entry).
    pub field: String,
    /// Which occurrence of the field within the section (the entry), 0-based.
    pub index: usize,
    /// What is wrong (without the section's name).
    pub message: String,
}

impl EntryFault {
    /// The fault `message` at list entry `index` (its `joint_index`).
    pub fn entry(index: usize, message: String) -> Self {
        Self { field: "joint_index".into(), index, message }
    }

    /// A loadsim error of a section that is no list, placed at the field it names
    /// (`thermal.reference_temp_c` → `reference_temp_c`; the section itself otherwise).
    pub fn of_section(error: &Error) -> Self {
        let field = match error {
            Error::Dynamics { source: dynamics::Error::InvalidParameter { field, .. } }
            | Error::Dynamics { source: dynamics::Error::LengthMismatch { field, .. } } => {
                field.rsplit('.').next().unwrap_or(field).to_owned()
            }
            _ => String::new(),
        };
        Self { field, index: 0, message: error.to_string() }
    }
}

/// A value that no cell has, as a person writes it: `"amplitude_rad is 0.5, at most 0.1 in
/// magnitude"`; the first of `values` (field, value, limit) beyond its limit.
pub fn beyond(values: &[(&str, f64, f64)]) -> Option<String> {
    values
        .iter()
        .find(|(_, value, limit)| value.abs() > *limit)
        .map(|(field, value, limit)| format!("{field} is {}, at most {limit} in magnitude", short(*value)))
}

/// A number as a person writes it: `1e308` rather than 309 digits.
pub fn short(value: f64) -> String {
    if value != 0.0 && !(1e-4..1e6).contains(&value.abs()) { format!("{value:e}") } else { format!("{value}") }
}

/// What every simulated effect implements. Implemented by the type of every kind of
/// `effect_kinds!` (the type its line names).
pub trait SimulatedEffect: std::fmt::Debug + Send + Sync {
    /// Checks the effect against the cell: indices inside the robot, finite values, the dynamics
    /// present where it needs them.
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error>;

    /// What of the robot's dynamics the effect needs (an effects file is refused for a robot
    /// without them before anything else is checked).
    fn needs_dynamics(&self) -> DynamicsNeed {
        DynamicsNeed::Nothing
    }

    /// Checks the effect as an effects file gives it, against `robot`: what
    /// [`SimulatedEffect::validate`] checks, entry by entry, and the bounds of a real cell (which
    /// also keep the simulation from overflowing into NaN poses). The robot's dynamics are present
    /// where [`SimulatedEffect::needs_dynamics`] says so.
    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault>;

    /// The model at this pose, if the effect changes the links (thermal growth); `None` leaves it.
    fn grown_model(&self, _model: &LocalPoe, _context: &PoseContext) -> Result<Option<LocalPoe>, Error> {
        Ok(None)
    }

    /// The effect's joint offsets at the commanded joints, one per joint (rad, m on a prismatic
    /// joint); `None` for an effect that moves no joint.
    fn joint_offset(&self, _at: &PoseInput<'_>) -> Result<Option<Vec<f64>>, Error> {
        Ok(None)
    }

    /// A left twist of the base-to-tool pose at the commanded joints (first order, as the joint
    /// offsets); `None` for an effect that adds none.
    fn pose_twist(&self, _at: &PoseInput<'_>) -> Result<Option<Vector6>, Error> {
        Ok(None)
    }

    /// A left motion of the whole tracker-to-tool pose at this pose's time; `None` for none.
    fn tracker_motion(&self, _context: &PoseContext) -> Option<SE3> {
        None
    }
}
