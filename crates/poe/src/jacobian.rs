//! The identification Jacobian (paper Section III-A-2): `y = log(T' T⁻¹)^∨ = A x`.

use crate::{Block, Error, LocalPoe, ParameterLayout};
use lie::{SE3, Vector3};

/// Which part of the pose a measurement row constrains.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RowKind {
    /// Position and orientation as the paper's twist `y = log(T' T⁻¹)^∨`: six rows `(v, ω)`.
    FullPose,
    /// Position and orientation decoupled: three rows of tool-point displacement, then three of
    /// `log(R' Rᵀ)^∨`. The same information as [`RowKind::FullPose`], but each row is in the unit
    /// the tracker measures, so position and orientation noise can be weighted separately. (The
    /// paper's `v` rows mix orientation noise times the lever arm to the tracker origin, which is
    /// metres away.)
    PointAndRotation,
    /// Position of the tool point only: three rows.
    Position,
}

impl RowKind {
    /// Number of residual rows per measurement.
    pub fn rows(self) -> usize {
        match self {
            RowKind::FullPose | RowKind::PointAndRotation => 6,
            RowKind::Position => 3,
        }
    }
}

impl LocalPoe {
    /// The parameter layout of this model.
    pub fn layout(&self) -> ParameterLayout {
        ParameterLayout { joint_count: self.joint_count(), tool_count: self.tool_count() }
    }

    /// Forward kinematics and the identification Jacobian of one measurement.
    ///
    /// Every local transform is perturbed on the left, `T_{i-1,i}(0) ← exp(δp̂_i) T_{i-1,i}(0)`.
    /// With `M_i` the reference frame from frame `i-1` after its joint's motion (`M_1 = I`), the
    /// pose becomes `exp(Ad(M_i) δp_i) T`, so the full-pose block of joint `i` is `Ad(M_i)` and
    /// the tool block is `Ad(M_{n+1})` (the paper's `A_i = [Ad_0 … Ad_n]`). A position-only row
    /// sees the tool point `p` move by `v + ω × p`, i.e. `[I, −p̂] · A_i`; a decoupled row
    /// ([`RowKind::PointAndRotation`]) adds the rotation rows `[0, I] · A_i`.
    ///
    /// `out` is a row-major `rows × layout().len()` slice (`rows` = 6 or 3); it is overwritten.
    pub fn identification_jacobian(
        &self,
        q: &[f64],
        tool: usize,
        kind: RowKind,
        out: &mut [f64],
    ) -> Result<SE3, Error> {
        let layout = self.layout();
        let columns = layout.len();
        let rows = kind.rows();
        assert_eq!(out.len(), rows * columns, "jacobian buffer has the wrong size");
        let pose = self.forward(q, tool)?;
        out.fill(0.0);
        let projection = match kind {
            RowKind::FullPose => None,
            RowKind::Position | RowKind::PointAndRotation => {
                let mut p = lie::Matrix6::identity();
                p.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-lie::SO3::hat(&pose.translation())));
                Some(p)
            }
        };
        let mut write_block = |offset: usize, frame: &SE3| {
            let ad = frame.adjoint();
            match &projection {
                None => {
                    for r in 0..6 {
                        for c in 0..6 {
                            out[r * columns + offset + c] = ad[(r, c)];
                        }
                    }
                }
                Some(p) => {
                    let block = p * ad;
                    for r in 0..rows {
                        for c in 0..6 {
                            out[r * columns + offset + c] = block[(r, c)];
                        }
                    }
                }
            }
        };
        let mut prefix = SE3::identity();
        for (i, (joint, &value)) in self.joints().iter().zip(q).enumerate() {
            write_block(layout.offset(Block::Joint(i)), &prefix);
            prefix = prefix * joint.previous_from_joint(value);
        }
        write_block(layout.offset(Block::Tool(tool)), &prefix);
        Ok(pose)
    }

    /// Applies an identification update: every block's local transform is multiplied on the left
    /// by `exp(δp̂)`, the perturbation the Jacobian was taken for.
    pub fn apply_update(&mut self, delta: &[f64]) {
        let layout = self.layout();
        assert_eq!(delta.len(), layout.len(), "update has the wrong length");
        let twist = |offset: usize| {
            lie::Twist::new(
                Vector3::new(delta[offset], delta[offset + 1], delta[offset + 2]),
                Vector3::new(delta[offset + 3], delta[offset + 4], delta[offset + 5]),
            )
        };
        for (i, joint) in self.joints_mut().iter_mut().enumerate() {
            let offset = layout.offset(Block::Joint(i));
            joint.previous_from_joint_zero = twist(offset).exp() * joint.previous_from_joint_zero;
        }
        let tools: Vec<SE3> = self
            .tools()
            .iter()
            .enumerate()
            .map(|(t, tool)| twist(layout.offset(Block::Tool(t))).exp() * *tool)
            .collect();
        self.set_tools(tools);
    }
}
