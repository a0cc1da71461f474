//! Weighted residuals and Jacobians of a set of observations.

use super::{IdentificationOptions, Observation, Target};
use crate::{Error, LocalPoe, RowKind};
use faer::Mat;

/// Root-mean-square errors of a model on a set of observations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResidualStats {
    /// RMS distance between measured and modelled tool points, metres.
    pub rms_position_m: f64,
    /// RMS orientation error angle over the full-pose rows, radians; `None` without such rows.
    pub rms_rotation_rad: Option<f64>,
}

#[derive(Default)]
struct Accumulator {
    position_sq: f64,
    rotation_sq: f64,
    rows: usize,
    pose_rows: usize,
}

impl Accumulator {
    fn stats(&self) -> ResidualStats {
        ResidualStats {
            rms_position_m: (self.position_sq / self.rows.max(1) as f64).sqrt(),
            rms_rotation_rad: (self.pose_rows > 0).then(|| (self.rotation_sq / self.pose_rows as f64).sqrt()),
        }
    }
}

/// Total number of residual rows of a set of observations.
pub(crate) fn row_count(observations: &[Observation]) -> usize {
    observations.iter().map(|o| row_kind(o).rows()).sum()
}

fn row_kind(observation: &Observation) -> RowKind {
    match observation.target {
        Target::Pose(_) => RowKind::PointAndRotation,
        Target::Point(_) => RowKind::Position,
    }
}

/// Writes the weighted residual of one observation into `out` and accounts for its errors:
/// `(p'_i − p_i, log(R'_i R_iᵀ)^∨)` for a pose, `p'_i − p_i` for a point. The decoupled form
/// ([`RowKind::PointAndRotation`]) carries the same first-order information as the paper's
/// `log(T'_i T_i⁻¹)^∨` but lets position and orientation noise be weighted each in its own unit.
fn weighted_residual(
    observation: &Observation,
    model_pose: &lie::SE3,
    options: &IdentificationOptions,
    out: &mut [f64],
    acc: &mut Accumulator,
) {
    let wp = 1.0 / options.position_sigma_m;
    let wr = 1.0 / options.rotation_sigma_rad;
    acc.rows += 1;
    match observation.target {
        Target::Pose(measured) => {
            let d = measured.translation() - model_pose.translation();
            let w = (measured.rotation() * model_pose.rotation().inverse()).log();
            for k in 0..3 {
                out[k] = d[k] * wp;
                out[k + 3] = w[k] * wr;
            }
            acc.position_sq += d.norm_squared();
            acc.rotation_sq += w.norm_squared();
            acc.pose_rows += 1;
        }
        Target::Point(measured) => {
            let d = measured - model_pose.translation();
            for k in 0..3 {
                out[k] = d[k] * wp;
            }
            acc.position_sq += d.norm_squared();
        }
    }
}

/// The weighted residual vector and the error statistics of `model` on `observations`.
pub(crate) fn residuals(
    model: &LocalPoe,
    observations: &[Observation],
    options: &IdentificationOptions,
) -> Result<(Vec<f64>, ResidualStats), Error> {
    let mut y = vec![0.0; row_count(observations)];
    let mut acc = Accumulator::default();
    let mut row = 0;
    for observation in observations {
        let rows = row_kind(observation).rows();
        let pose = model.forward(&observation.q, observation.tool)?;
        weighted_residual(observation, &pose, options, &mut y[row..row + rows], &mut acc);
        row += rows;
    }
    Ok((y, acc.stats()))
}

/// The weighted Jacobian restricted to the `free` columns, the weighted residual and the errors.
pub(crate) fn linearise(
    model: &LocalPoe,
    observations: &[Observation],
    free: &[usize],
    options: &IdentificationOptions,
) -> Result<(Mat<f64>, Vec<f64>, ResidualStats), Error> {
    let columns = model.layout().len();
    let total_rows = row_count(observations);
    let mut a = Mat::<f64>::zeros(total_rows, free.len());
    let mut y = vec![0.0; total_rows];
    let mut acc = Accumulator::default();
    let mut scratch = vec![0.0; 6 * columns];
    let mut row = 0;
    for observation in observations {
        let kind = row_kind(observation);
        let rows = kind.rows();
        let buffer = &mut scratch[..rows * columns];
        let pose = model.identification_jacobian(&observation.q, observation.tool, kind, buffer)?;
        weighted_residual(observation, &pose, options, &mut y[row..row + rows], &mut acc);
        for r in 0..rows {
            let weight = if r < 3 { 1.0 / options.position_sigma_m } else { 1.0 / options.rotation_sigma_rad };
            for (c, &column) in free.iter().enumerate() {
                a[(row + r, c)] = buffer[r * columns + column] * weight;
            }
        }
        row += rows;
    }
    Ok((a, y, acc.stats()))
}
