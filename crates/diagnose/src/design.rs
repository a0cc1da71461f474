//! The linearised problem the diagnosis scores candidates on: at the geometric solution fitted to
//! all rows, each measured pose gives weighted residual rows `y_i` and kinematic Jacobian rows
//! `A_i`; a candidate effect adds columns `C_i`. One regularised Gauss–Newton step from that
//! solution on the training rows (module `pool`) predicts the held-out rows. The residuals are
//! millimetres against metres of lever, so the step is the converged refit to first order.

use errors::Error;
use faer::Mat;
use lie::{SO3, Vector3, Vector6};
use measurements::MeasurementSet;
use poe::{LocalPoe, RowKind};

/// Weights that make position and orientation rows comparable.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Weights {
    /// Position noise, m (per axis).
    pub position_m: f64,
    /// Orientation noise, rad (per axis).
    pub rotation_rad: f64,
}

/// The rows of every measurement at the geometric solution.
#[derive(Debug, Clone)]
pub(crate) struct Design {
    /// Rows per measurement: 3 (position only) or 6 (full pose).
    pub rows_per_pose: usize,
    /// Weighted residuals `measured − predicted`, `rows_per_pose` per measurement.
    pub y: Vec<f64>,
    /// Weighted kinematic Jacobian, one row per residual, all 6(n + tools) parameters.
    pub kinematic: Mat<f64>,
    /// Predicted tool points, reference frame, one per measurement.
    pub points: Vec<Vector3>,
    /// The weights.
    pub weights: Weights,
}

impl Design {
    /// Linearises `model` at every measurement of `data` (tool indices already the model's).
    pub(crate) fn new(model: &LocalPoe, data: &MeasurementSet, weights: Weights) -> Result<Self, Error> {
        let rows_per_pose = if data.full_pose { 6 } else { 3 };
        let kind = if data.full_pose { RowKind::PointAndRotation } else { RowKind::Position };
        let columns = model.layout().len();
        let total = rows_per_pose * data.rows.len();
        let mut kinematic = Mat::<f64>::zeros(total, columns);
        let mut y = vec![0.0; total];
        let mut points = Vec::with_capacity(data.rows.len());
        let mut buffer = vec![0.0; rows_per_pose * columns];
        for (i, row) in data.rows.iter().enumerate() {
            let pose = model.identification_jacobian(&row.q, row.tool, kind, &mut buffer).map_err(Error::kinematics)?;
            let base = i * rows_per_pose;
            let d = row.position - pose.translation();
            for r in 0..3 {
                y[base + r] = d[r] / weights.position_m;
            }
            if let Some(measured) = row.orientation {
                let w = (measured * pose.rotation().inverse()).log();
                for r in 0..3 {
                    y[base + 3 + r] = w[r] / weights.rotation_rad;
                }
            }
            for r in 0..rows_per_pose {
                let weight = if r < 3 { weights.position_m } else { weights.rotation_rad };
                for c in 0..columns {
                    kinematic[(base + r, c)] = buffer[r * columns + c] / weight;
                }
            }
            points.push(pose.translation());
        }
        Ok(Self { rows_per_pose, y, kinematic, points, weights })
    }

    /// The weighted residual rows of a left twist `c` at measurement `i`: the point moves by
    /// `v + ω × p`, the orientation by `ω`.
    pub(crate) fn twist_rows(&self, i: usize, twist: &Vector6, out: &mut [f64]) {
        let p = self.points[i];
        let w = Vector3::new(twist[3], twist[4], twist[5]);
        let v = Vector3::new(twist[0], twist[1], twist[2]) - SO3::hat(&p) * w;
        for r in 0..3 {
            out[r] = v[r] / self.weights.position_m;
        }
        if self.rows_per_pose == 6 {
            for r in 0..3 {
                out[3 + r] = w[r] / self.weights.rotation_rad;
            }
        }
    }
}
