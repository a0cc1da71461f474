//! Distance from a kinematic singularity, for rejecting poses that identification cannot use.

use crate::{Error, gravity::point_rate};
use nalgebra::DMatrix;
use poe::LocalPoe;

/// The 6 × n Jacobian of the tool point: column j is `(v_j + ω_j × p, ω_j)`, the tool point's
/// velocity and the angular velocity per unit rate of joint j. Unlike the spatial Jacobian its
/// singular values do not depend on where the reference origin is, only on the arm's posture.
pub fn tool_point_jacobian(model: &LocalPoe, q: &[f64], tool: usize) -> Result<DMatrix<f64>, Error> {
    let p = model.forward(q, tool)?.translation();
    let twists = model.spatial_twists(q)?;
    let mut jacobian = DMatrix::zeros(6, twists.len());
    for (j, s) in twists.iter().enumerate() {
        let rate = point_rate(s, &p);
        for r in 0..3 {
            jacobian[(r, j)] = rate[r];
            jacobian[(r + 3, j)] = s.w[r];
        }
    }
    Ok(jacobian)
}

/// The smallest singular value of [`tool_point_jacobian`] (of its `min(6, n)` singular values):
/// zero at a singularity (e.g. joints 4 and 6 aligned when `q5 = 0` on a 6R wrist).
pub fn smallest_singular_value(model: &LocalPoe, q: &[f64], tool: usize) -> Result<f64, Error> {
    let jacobian = tool_point_jacobian(model, q, tool)?;
    Ok(jacobian.singular_values().iter().copied().fold(f64::INFINITY, f64::min))
}

/// The smallest singular value of the columns of [`tool_point_jacobian`] that belong to `joints`
/// (0-based), for a campaign that moves only those: a posture is singular for it when the joints
/// that move cannot move the tool in as many directions as there are of them.
pub fn smallest_singular_value_of_joints(
    model: &LocalPoe,
    q: &[f64],
    tool: usize,
    joints: &[usize],
) -> Result<f64, Error> {
    let jacobian = tool_point_jacobian(model, q, tool)?;
    let n = jacobian.ncols();
    if let Some(&joint_index) = joints.iter().find(|&&j| j >= n) {
        return Err(Error::from(dynamics::Error::UnknownJoint { field: "moving_joints", joint_index, joint_count: n }));
    }
    let columns = DMatrix::from_fn(6, joints.len(), |r, c| jacobian[(r, joints[c])]);
    Ok(columns.singular_values().iter().copied().fold(f64::INFINITY, f64::min))
}
