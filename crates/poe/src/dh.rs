//! Construction of the local POE model from Denavit–Hartenberg tables.

use crate::{Joint, JointKind, LocalPoe};
use lie::{SE3, SO3, Vector3};
use serde::{Deserialize, Serialize};

/// Which Denavit–Hartenberg convention a table follows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum DhConvention {
    /// Standard (distal) DH: `T_{i-1,i} = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)`.
    Standard,
    /// Modified (proximal, Craig) DH: `T_{i-1,i} = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)`; row `i`
    /// holds `a_{i-1}` and `α_{i-1}`.
    Modified,
}

/// One row of a DH table, SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DhRow {
    /// Revolute (θ varies) or prismatic (d varies).
    pub kind: JointKind,
    /// Link length `a`, metres.
    pub a: f64,
    /// Link twist `α`, radians.
    pub alpha: f64,
    /// Link offset `d`, metres (added to the joint value of a prismatic joint).
    pub d: f64,
    /// Joint angle offset `θ`, radians (added to the joint value of a revolute joint).
    pub theta: f64,
}

fn rot_z(angle: f64) -> SE3 {
    SE3::new(SO3::exp(&(Vector3::z() * angle)), Vector3::zeros())
}

fn rot_x(angle: f64) -> SE3 {
    SE3::new(SO3::exp(&(Vector3::x() * angle)), Vector3::zeros())
}

fn trans(x: f64, z: f64) -> SE3 {
    SE3::from_translation(Vector3::new(x, 0.0, z))
}

impl LocalPoe {
    /// Builds the model from a DH table; the tool (tool 0) is the last DH frame.
    ///
    /// Every DH joint motion is a rotation about, or a translation along, the z axis of a frame, and
    /// `Rz` commutes with `Tz`, so the chain regroups into the local POE form of Eq. 3:
    /// standard DH `Π Rz(q_i) L_i` with `L_i = Rz(θ_i) Tz(d_i) Tx(a_i) Rx(α_i)` gives
    /// `T_{0,1}(0) = I`, `T_{i,i+1}(0) = L_i`, tool `L_n`; modified DH
    /// `Π L_i Rz(q_i)` with `L_i = Rx(α_{i-1}) Tx(a_{i-1}) Rz(θ_i) Tz(d_i)` gives `T_{i-1,i}(0) = L_i`
    /// and the identity tool.
    pub fn from_dh(rows: &[DhRow], convention: DhConvention) -> Self {
        let mut joints = Vec::with_capacity(rows.len());
        let tool = match convention {
            DhConvention::Standard => {
                let mut previous = SE3::identity();
                for row in rows {
                    joints.push(Joint::new(row.kind, previous));
                    previous = rot_z(row.theta) * trans(0.0, row.d) * trans(row.a, 0.0) * rot_x(row.alpha);
                }
                previous
            }
            DhConvention::Modified => {
                for row in rows {
                    let local = rot_x(row.alpha) * trans(row.a, 0.0) * rot_z(row.theta) * trans(0.0, row.d);
                    joints.push(Joint::new(row.kind, local));
                }
                SE3::identity()
            }
        };
        LocalPoe::new(joints, vec![tool])
    }
}
