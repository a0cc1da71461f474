//! Drift of the base (or the tracker) over time: the robot base settles, the tracker stand creeps,
//! the floor warms. Over the hours of a measurement campaign it is a slow rigid motion of the
//! base in the tracker frame, taken here as a constant rate: `T' = exp(t ξ̂) · T`, with `t = t_s`
//! and `ξ` a twist per second in the tracker frame, `(v, ω)` order. Its regressor is exact:
//! `log(T' T⁻¹)^∨ = t ξ`.

use crate::Error;
use crate::{EntryFault, PoseContext, RobotFacts, SimulatedCell, SimulatedEffect, beyond};
use lie::{SE3, Twist, Vector6};
use serde::{Deserialize, Serialize};

/// A constant-rate drift of the base placement in the tracker frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct TimeDriftModel {
    /// Drift twist per second, tracker frame, `(v m/s, ω rad/s)`. Default: 10 µm/h along x,
    /// −5 µm/h along z and 5 µrad/h about z, an engineering estimate of a settling cell.
    pub twist_per_s: [f64; 6],
}

impl Default for TimeDriftModel {
    fn default() -> Self {
        let per_hour = 1.0 / 3600.0;
        Self { twist_per_s: [10e-6 * per_hour, 0.0, -5e-6 * per_hour, 0.0, 0.0, 5e-6 * per_hour] }
    }
}

impl TimeDriftModel {
    /// Checks that every component is finite.
    pub fn validate(&self) -> Result<(), Error> {
        match self.twist_per_s.iter().find(|x| !x.is_finite()) {
            Some(&value) => Err(Error::from(dynamics::Error::InvalidParameter { field: "drift.twist_per_s", value })),
            None => Ok(()),
        }
    }

    /// The drift twist accumulated at time `t_s`, tracker frame.
    pub fn twist_at(&self, t_s: f64) -> Twist {
        Twist::from_vector(&(Vector6::from(self.twist_per_s) * t_s))
    }

    /// The rigid motion `exp(t ξ̂)` that left-multiplies the tracker-frame pose at time `t_s`.
    pub fn motion_at(&self, t_s: f64) -> SE3 {
        self.twist_at(t_s).exp()
    }
}

/// Largest drift rate per component an effects file may give, m/s or rad/s: a settling cell
/// drifts by micrometres per hour; a base moving a metre per second is not drifting.
pub const MAX_DRIFT_PER_S: f64 = 1.0;

impl SimulatedEffect for TimeDriftModel {
    fn validate(&self, _cell: &SimulatedCell) -> Result<(), Error> {
        TimeDriftModel::validate(self)
    }

    fn check_entries(&self, _robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        TimeDriftModel::validate(self).map_err(|e| EntryFault::of_section(&e))?;
        let bounds: Vec<_> = self.twist_per_s.iter().map(|&v| ("twist_per_s", v, MAX_DRIFT_PER_S)).collect();
        match beyond(&bounds) {
            Some(message) => Err(EntryFault { field: "twist_per_s".into(), index: 0, message }),
            None => Ok(()),
        }
    }

    fn tracker_motion(&self, context: &PoseContext) -> Option<SE3> {
        Some(self.motion_at(context.t_s))
    }
}
