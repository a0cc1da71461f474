//! What `calib register` re-fits and how it is tuned.

use crate::registration::RegistrationOptions;
use errors::{Error, OptionOutOfRange};
use serde::{Deserialize, Serialize};

/// What `register` re-fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Refit {
    /// The tracker-to-base transform (the model's reference frame).
    pub base: bool,
    /// Every tool in the data (a tool the model does not know becomes a new one).
    pub tools: bool,
}

impl std::str::FromStr for Refit {
    type Err = String;

    /// `base`, `tools`, `base,tools` (either order).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let mut refit = Refit { base: false, tools: false };
        for item in s.split(',').map(str::trim) {
            match item {
                "base" => refit.base = true,
                "tools" | "tool" => refit.tools = true,
                other => return Err(format!("unknown refit item '{other}': expected base, tools or base,tools")),
            }
        }
        Ok(refit)
    }
}

/// Everything `register` is tuned by.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RegisterOptions {
    /// The least squares.
    pub registration: RegistrationOptions,
    /// Residual rows wanted per re-fitted parameter: 3, as `pipeline::FitOptions::min_redundancy`
    /// (below it the residual on the poses flatters by more than 40 % and says little).
    pub min_redundancy: f64,
    /// Poses wanted of every re-fitted tool: 3, so that each tool's own residual is checked by
    /// more poses than fix it (one full pose, or three points, fix a tool).
    pub min_poses_per_tool: usize,
    /// The residual, made unbiased for the parameters fitted (`× √(r / (r − p))`), against the
    /// model's held-out error: above this ratio the robot itself is said to have changed. 1.5:
    /// the held-out error of the UR10 of series C varies by ±15 % between sets of 30 poses
    /// (0.444 mm on all odd rows, 0.505 mm median on 30), and a sound registration stays near 1;
    /// a change beyond half the model's error is one a re-calibration removes.
    pub changed_ratio: f64,
    /// A re-fitted tool point this far (mm) from the one a position-only model was fitted with
    /// is warned about ([`crate::RegisterWarning::PositionModelToolPoint`]): 1 mm, where the orientation
    /// a position-only fit leaves free (tens of mrad on the simulated IRB 4400) starts to cost
    /// more than a tracker's noise.
    pub moved_point_mm: f64,
}

impl Default for RegisterOptions {
    fn default() -> Self {
        Self {
            registration: RegistrationOptions::default(),
            min_redundancy: 3.0,
            min_poses_per_tool: 3,
            changed_ratio: 1.5,
            moved_point_mm: 1.0,
        }
    }
}

impl RegisterOptions {
    /// Refuses values out of range.
    pub fn validate(&self) -> Result<(), Error> {
        self.registration.validate()?;
        for (field, value) in [("min_redundancy", self.min_redundancy), ("changed_ratio", self.changed_ratio)] {
            OptionOutOfRange::check(field, value, value.is_finite() && value >= 1.0, "a finite number of at least 1")?;
        }
        Ok(())
    }
}
