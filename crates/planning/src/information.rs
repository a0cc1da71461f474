//! Every candidate pose's rows of the identification, on the directions the candidates can
//! determine: `A_i = W J_i S⁻¹ V_r` with `J_i` the identification Jacobian of `poe` (paper
//! Section III-A-2; position rows, or point and rotation rows for full poses), `W` the rows'
//! inverse noise, `S` the columns' RMS over the candidates (so that metres and radians weigh
//! alike) and `V_r` the eigenvectors of the scaled information that are not redundant (a local
//! POE model has 6(n + tools) parameters, of which only some are identifiable: Chen, Yang et al.).
//! The information of a set of poses is then `M = Σ A_iᵀ A_i`, in units of the noise.

use crate::ErrorKind;
use errors::Error;
use nalgebra::{DMatrix, SymmetricEigen};
use poe::{LocalPoe, RowKind};
use rayon::prelude::*;

/// One candidate pose: its joint values and the model tool it is measured with.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Joint values, rad (m for a prismatic joint).
    pub q: Vec<f64>,
    /// Tool index in the model.
    pub tool: usize,
    /// Payload, kg (only for coverage).
    pub payload_kg: f64,
}

/// The candidates' reduced rows.
#[derive(Debug, Clone)]
pub struct CandidateRows {
    /// Rows per candidate: 3 (position) or 6 (point and rotation).
    pub k: usize,
    /// Directions kept.
    pub r: usize,
    /// Parameters of the model.
    pub p: usize,
    /// `candidates × k × r`, row-major per candidate.
    pub a: Vec<f64>,
}

impl CandidateRows {
    /// Candidate `c`'s `k × r` rows.
    pub fn rows(&self, c: usize) -> &[f64] {
        &self.a[c * self.k * self.r..(c + 1) * self.k * self.r]
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.a.len() / (self.k * self.r).max(1)
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.a.is_empty()
    }
}

/// The rows' noise and which directions count as determined.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowWeights {
    /// Position noise per axis, m.
    pub position_m: f64,
    /// Orientation noise per axis, rad; `None`: position-only measurements.
    pub rotation_rad: Option<f64>,
    /// Eigenvalues of the scaled information below this fraction of the largest are redundant
    /// directions.
    pub rank_tolerance: f64,
}

/// Builds every candidate's reduced rows.
pub fn candidate_rows(
    model: &LocalPoe,
    candidates: &[Candidate],
    weights: &RowWeights,
) -> Result<CandidateRows, Error> {
    let kind = if weights.rotation_rad.is_some() { RowKind::PointAndRotation } else { RowKind::Position };
    let k = kind.rows();
    let p = model.layout().len();
    let rotation_scale = weights.rotation_rad.map_or(0.0, |r| 1.0 / r);
    let jacobians: Vec<Vec<f64>> = candidates
        .par_iter()
        .map(|c| {
            let mut out = vec![0.0; k * p];
            model.identification_jacobian(&c.q, c.tool, kind, &mut out)?;
            for (row, chunk) in out.chunks_mut(p).enumerate() {
                let w = if row < 3 { 1.0 / weights.position_m } else { rotation_scale };
                chunk.iter_mut().for_each(|v| *v *= w);
            }
            Ok(out)
        })
        .collect::<Result<_, poe::Error>>()
        .map_err(Error::kinematics)?;
    let mut gram = DMatrix::<f64>::zeros(p, p);
    for j in &jacobians {
        let m = DMatrix::from_row_slice(k, p, j);
        gram += m.transpose() * m;
    }
    let count = candidates.len().max(1) as f64;
    let scale: Vec<f64> = (0..p).map(|j| (gram[(j, j)] / count).sqrt()).collect();
    let inverse_scale: Vec<f64> = scale.iter().map(|&s| if s > 0.0 { 1.0 / s } else { 0.0 }).collect();
    let scaled = DMatrix::from_fn(p, p, |i, j| gram[(i, j)] * inverse_scale[i] * inverse_scale[j] / count);
    let eigen = SymmetricEigen::new(scaled);
    let largest = eigen.eigenvalues.max();
    let kept: Vec<usize> =
        (0..p).filter(|&i| largest > 0.0 && eigen.eigenvalues[i] > weights.rank_tolerance * largest).collect();
    if kept.is_empty() {
        return Err(Error::new(ErrorKind::NoIdentifiableDirection { candidates: candidates.len() }));
    }
    let r = kept.len();
    // S⁻¹ V_r: p × r.
    let basis = DMatrix::from_fn(p, r, |i, c| inverse_scale[i] * eigen.eigenvectors[(i, kept[c])]);
    let a: Vec<f64> = jacobians
        .par_iter()
        .flat_map_iter(|j| {
            let reduced = DMatrix::from_row_slice(k, p, j) * &basis;
            let mut out = Vec::with_capacity(k * r);
            for row in 0..k {
                out.extend((0..r).map(|c| reduced[(row, c)]));
            }
            out
        })
        .collect();
    Ok(CandidateRows { k, r, p, a })
}
