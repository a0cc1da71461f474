//! Parameters beyond the kinematic ones, identified jointly with them: a non-geometric effect
//! whose pose change is linear in its parameters.

use crate::LocalPoe;
use lie::{SE3, Twist, Vector6};

/// A pose correction linear in its parameters `θ`: the predicted pose of observation `i` is
/// `exp((Σ_l θ_l c_l)^) · T(q_i)`, with `c_l` twists in the model's reference frame that may depend
/// on the model (e.g. a joint's spatial twist times a torque regressor, paper Eq. 9's placement of
/// the correction before the POE model).
///
/// A joint-space effect `δq_j = Σ_l θ_l φ_l(q)` is written this way with `c_l = ξ_j(q) φ_l(q)`,
/// `ξ_j` the joint's spatial twist: `T(q + δq) = exp(ξ_j δq_j) T(q)` up to second order in `δq`.
pub trait PoseCorrection: Sync {
    /// Number of parameters `θ`.
    fn parameter_count(&self) -> usize;

    /// The twists `c_l` of observation `index` under `model`, one per parameter, written into
    /// `out` (length [`PoseCorrection::parameter_count`]).
    fn twists(&self, model: &LocalPoe, index: usize, out: &mut [Vector6]);

    /// Prior standard deviation of parameter `parameter` about zero, used by Levenberg–Marquardt
    /// ([`crate::identify::Solver::LevenbergMarquardt`]); `f64::INFINITY` (the default) for none.
    fn prior_sigma(&self, parameter: usize) -> f64 {
        let _ = parameter;
        f64::INFINITY
    }
}

/// A correction together with its current parameter values.
#[derive(Clone, Copy)]
pub(crate) struct Corrected<'a> {
    pub(crate) correction: &'a dyn PoseCorrection,
    pub(crate) theta: &'a [f64],
}

impl Corrected<'_> {
    /// `exp((Σ θ_l c_l)^) · pose`, with `twists` set to the derivative of that pose with respect to
    /// each `θ_l` as a left twist: `J_l(ξ) c_l`, `ξ = Σ θ_l c_l` (exact, for the Jacobian's extra
    /// columns).
    pub(crate) fn apply(&self, model: &LocalPoe, index: usize, pose: SE3, twists: &mut Vec<Vector6>) -> SE3 {
        twists.clear();
        twists.resize(self.theta.len(), Vector6::zeros());
        self.correction.twists(model, index, twists);
        let total: Vector6 = twists.iter().zip(self.theta).map(|(c, t)| c * *t).sum();
        if total == Vector6::zeros() {
            return pose;
        }
        let xi = Twist::from_vector(&total);
        let jacobian = SE3::left_jacobian(&xi);
        for twist in twists.iter_mut() {
            *twist = jacobian * *twist;
        }
        xi.exp() * pose
    }
}
