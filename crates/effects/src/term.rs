//! What every effect implements: [`EffectTerm`] (what a fitted effect says about itself: its
//! label, its joints, its checks on reading a model file, where it applies) and [`NewEffect`] (how
//! it is made: the arguments of its `--effects` item, from an item for the fit, as candidates for
//! the diagnosis). [`crate::IdentifiedEffect`] is generated from the one list of kinds
//! (`loadsim::effect_kinds!`) and delegates every arm to these traits, so an effect is one file.

use crate::check::{Cursor, EffectFault};
use crate::{Argument, Direction, EffectContext, EffectSpec, IdentifiedEffect, LoadFrame, Regressor};
use errors::Error;
use measurements::Measurement;
use robot::RobotDescription;

/// What the diagnosis builds its candidates from.
#[derive(Debug, Clone, Copy)]
pub struct CandidateContext<'a> {
    /// The robot description.
    pub robot: &'a RobotDescription,
    /// The measurements.
    pub rows: &'a [Measurement],
    /// Each row's model tool.
    pub tools: &'a [usize],
    /// The nominal arm in the base frame, where gravity is known, with the calibrated tools.
    pub load: &'a LoadFrame,
    /// The robot's mass model, or [`crate::stand_in_dynamics`].
    pub dynamics: &'a loadsim::RobotDynamics,
    /// Whether every row has measured joint torques.
    pub measured: bool,
    /// 0-based joints that move.
    pub moving: &'a [usize],
    /// The highest order a Fourier series may take.
    pub longest_order: u32,
}

/// A candidate an effect offers the diagnosis: the effect with its parameters at zero.
#[derive(Debug, Clone)]
pub struct CandidateModel {
    /// The effect as the fit would model it.
    pub effect: IdentifiedEffect,
    /// Its place among one joint's candidates (the selection gives ties to the earlier one).
    pub order: u8,
    /// A Fourier series: the diagnosis gives it the series prior and lets it take any of its orders.
    pub series: bool,
    /// Offered only where its columns are not zero on every row (a torque sign that never changes).
    pub only_if_nonzero: bool,
}

impl CandidateModel {
    /// A candidate with the default prior, offered whenever it has columns.
    pub fn plain(effect: IdentifiedEffect, order: u8) -> Self {
        Self { effect, order, series: false, only_if_nonzero: false }
    }
}

/// What a fitted effect says about itself. Implemented by the type of every identified kind.
pub(crate) trait EffectTerm: Regressor + std::fmt::Debug + Send + Sync {
    /// A name for reports: the SPEC item where there is one (`gear_periodic:1:24`), with what
    /// drives it.
    fn label(&self) -> String;

    /// The 1-based joints the effect acts on (empty for effects of no joint).
    fn joints(&self) -> Vec<usize>;

    /// Checks the effect as read from a model file with `n` joints and `tools` tools: every index
    /// within the robot, every count consistent, every value finite (`theta`'s values are checked
    /// for every effect by `check_effects`).
    fn check(&self, cursor: &Cursor<'_>, n: usize, tools: usize) -> Result<(), EffectFault>;

    /// Counts the fields the effect writes into a model file (`add(field, occurrences)`), `theta`
    /// excepted, so that a fault of the next effect is placed at its own occurrence.
    fn count_fields(&self, add: &mut dyn FnMut(&'static str, usize));

    /// How fully the effect applies at `row`: 1 where it was fitted, fading to 0 where it is not
    /// trusted.
    fn coverage_weight(&self, _row: &Measurement) -> f64 {
        1.0
    }

    /// What the effect leaves uncorrected at `row`: a standard deviation along a direction, if any.
    fn uncovered(&self, _row: &Measurement) -> Option<(Direction, f64)> {
        None
    }

    /// Whether the effect can report [`EffectTerm::uncovered`].
    fn has_sigma(&self) -> bool {
        false
    }

    /// Each parameter's prior standard deviation relative to the effects' common one.
    fn prior_scale(&self) -> Vec<f64> {
        vec![1.0; self.theta().len()]
    }
}

/// How an effect is made. Implemented by the type of every identified kind.
pub(crate) trait NewEffect: EffectTerm + Sized {
    /// The arguments of its `--effects` item, in order.
    const ARGUMENTS: &'static [Argument];

    /// The effect an `--effects` item names, its features scaled on `rows` (`tools`: each row's
    /// model tool), its parameters at zero. Its joint, if any, is within the robot.
    fn build(
        spec: &EffectSpec,
        context: &EffectContext<'_>,
        rows: &[Measurement],
        tools: &[usize],
    ) -> Result<Self, Error>;

    /// The diagnosis's candidates of this kind on 0-based joint `joint`.
    fn joint_candidates(_context: &CandidateContext<'_>, _joint: usize) -> Result<Vec<CandidateModel>, Error> {
        Ok(Vec::new())
    }

    /// The diagnosis's candidates of this kind that concern no one joint.
    fn global_candidates(_context: &CandidateContext<'_>) -> Result<Vec<CandidateModel>, Error> {
        Ok(Vec::new())
    }
}
