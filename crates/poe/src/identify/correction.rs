//! Parameters beyond the kinematic ones, identified jointly with them: a non-geometric effect
//! whose pose change is linear in its parameters.

use crate::LocalPoe;
use lie::{Matrix6, SE3, Twist, Vector6};

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

    /// The joint (0-based) whose spatial twist parameter `parameter`'s twist is a multiple of, if
    /// any. The identification then also differentiates that twist with respect to the kinematic
    /// parameters (a left perturbation `η` of block `i ≤ j` turns `S_j` into `Ad(exp η) S_j`), so
    /// that the Jacobian is exact and the solver can meet its gradient criterion. `None` (the
    /// default) for a twist that does not follow the kinematics.
    fn joint(&self, parameter: usize) -> Option<usize> {
        let _ = parameter;
        None
    }
}

/// A correction together with its current parameter values.
#[derive(Clone, Copy)]
pub(crate) struct Corrected<'a> {
    pub(crate) correction: &'a dyn PoseCorrection,
    pub(crate) theta: &'a [f64],
}

/// How a correction moves the kinematic columns of one observation: a kinematic column `η` (a
/// left twist of the uncorrected pose) of joint block `i` becomes `Ad(exp ξ) η − J_l(ξ) ad(Z_i) η`,
/// `Z_i = Σ_{j ≥ i} Σ_{l on joint j} θ_l c_l` (the part of `ξ` that block `i` turns with it); a
/// tool block's column becomes `Ad(exp ξ) η`.
pub(crate) struct KinematicMap {
    /// One 6×6 map per joint block, then one for the tools.
    pub blocks: Vec<Matrix6>,
}

impl Corrected<'_> {
    /// `exp((Σ θ_l c_l)^) · pose`, with `twists` set to the derivative of that pose with respect to
    /// each `θ_l` as a left twist: `J_l(ξ) c_l`, `ξ = Σ θ_l c_l` (exact, for the Jacobian's extra
    /// columns).
    pub(crate) fn apply(&self, model: &LocalPoe, index: usize, pose: SE3, twists: &mut Vec<Vector6>) -> SE3 {
        self.apply_with_map(model, index, pose, twists).0
    }

    /// [`Corrected::apply`], and the map of the kinematic columns ([`KinematicMap`]), `None` when
    /// the correction is zero at this observation.
    pub(crate) fn apply_with_map(
        &self,
        model: &LocalPoe,
        index: usize,
        pose: SE3,
        twists: &mut Vec<Vector6>,
    ) -> (SE3, Option<KinematicMap>) {
        twists.clear();
        twists.resize(self.theta.len(), Vector6::zeros());
        self.correction.twists(model, index, twists);
        let total: Vector6 = twists.iter().zip(self.theta).map(|(c, t)| c * *t).sum();
        if total == Vector6::zeros() {
            return (pose, None);
        }
        let n = model.joint_count();
        let mut per_joint = vec![Vector6::zeros(); n];
        for (l, (c, t)) in twists.iter().zip(self.theta).enumerate() {
            if let Some(j) = self.correction.joint(l).filter(|&j| j < n) {
                per_joint[j] += c * *t;
            }
        }
        let xi = Twist::from_vector(&total);
        let jacobian = SE3::left_jacobian(&xi);
        let exp = xi.exp();
        let ad_exp = exp.adjoint();
        let mut blocks = vec![ad_exp; n + 1];
        let mut suffix = Vector6::zeros();
        for i in (0..n).rev() {
            suffix += per_joint[i];
            if suffix != Vector6::zeros() {
                blocks[i] = ad_exp - jacobian * Twist::from_vector(&suffix).ad();
            }
        }
        for twist in twists.iter_mut() {
            *twist = jacobian * *twist;
        }
        (exp * pose, Some(KinematicMap { blocks }))
    }
}
