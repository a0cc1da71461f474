//! Weighted residuals and Jacobians of a set of observations.

use super::correction::Corrected;
use super::reduced::Reduced;
use super::robust::RowError;
use super::{IdentificationOptions, Observation, Target};
use crate::{Error, LocalPoe, RowKind};
use faer::{Mat, MatMut};
use lie::{SE3, SO3, Vector6};
use rayon::prelude::*;

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

/// What one observation adds to the error statistics. Blocks of observations linearised side by
/// side hand these back, and they are added in observation order: the sums are then the same
/// bits on any number of threads.
#[derive(Debug, Clone, Copy)]
struct ObservationError {
    position_sq: f64,
    /// `None` for a point.
    rotation_sq: Option<f64>,
}

impl Accumulator {
    fn add(&mut self, error: ObservationError) {
        self.rows += 1;
        self.position_sq += error.position_sq;
        if let Some(rotation_sq) = error.rotation_sq {
            self.rotation_sq += rotation_sq;
            self.pose_rows += 1;
        }
    }

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

/// How each observation's rows are weighted beyond the options' sigmas: the robust loss's weight
/// of its position and orientation rows, and its stated noise relative to the sigmas per residual
/// component (`stated_noise.rs`); an empty slice weighs every observation 1.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Weights<'a> {
    pub robust: &'a [[f64; 2]],
    pub noise: &'a [[f64; 6]],
}

impl Weights<'_> {
    /// The multiplier of each residual component of observation `index`: `1/σ` of its kind times
    /// the square root of the robust loss's row weight (module `robust`), so that the squared
    /// residual counts `w` times, over the observation's relative stated noise.
    fn of(&self, options: &IdentificationOptions, index: usize) -> [f64; 6] {
        let [wp, wr] = scaled_weights(options, row_weight(self.robust, index));
        let noise = self.noise.get(index).copied().unwrap_or([1.0; 6]);
        std::array::from_fn(|k| if k < 3 { wp } else { wr } / noise[k])
    }
}

/// Writes the weighted residual of one observation into `out` and returns its errors:
/// `(p'_i − p_i, log(R'_i R_iᵀ)^∨)` for a pose, `p'_i − p_i` for a point. The decoupled form
/// ([`RowKind::PointAndRotation`]) carries the same first-order information as the paper's
/// `log(T'_i T_i⁻¹)^∨` but lets position and orientation noise be weighted each in its own unit.
fn weighted_residual(
    observation: &Observation,
    model_pose: &SE3,
    weight: [f64; 6],
    out: &mut [f64],
) -> ObservationError {
    match observation.target {
        Target::Pose(measured) => {
            let d = measured.translation() - model_pose.translation();
            let w = (measured.rotation() * model_pose.rotation().inverse()).log();
            for k in 0..3 {
                out[k] = d[k] * weight[k];
                out[k + 3] = w[k] * weight[k + 3];
            }
            ObservationError { position_sq: d.norm_squared(), rotation_sq: Some(w.norm_squared()) }
        }
        Target::Point(measured) => {
            let d = measured - model_pose.translation();
            for k in 0..3 {
                out[k] = d[k] * weight[k];
            }
            ObservationError { position_sq: d.norm_squared(), rotation_sq: None }
        }
    }
}

/// The multipliers of an observation's position and orientation rows: `1/σ` of each kind times
/// the square root of the robust loss's row weight (module `robust`), so that the squared
/// residual counts `w` times.
fn scaled_weights(options: &IdentificationOptions, row_weight: [f64; 2]) -> [f64; 2] {
    [row_weight[0].sqrt() / options.position_sigma_m, row_weight[1].sqrt() / options.rotation_sigma_rad]
}

/// The robust weight of observation `index`: `[1, 1]` where `row_weights` is empty.
fn row_weight(row_weights: &[[f64; 2]], index: usize) -> [f64; 2] {
    row_weights.get(index).copied().unwrap_or([1.0, 1.0])
}

/// Each observation's residual norms: the tool point's distance and the orientation's angle.
pub(crate) fn row_errors(
    model: &LocalPoe,
    observations: &[Observation],
    correction: Option<Corrected<'_>>,
) -> Result<Vec<RowError>, Error> {
    let mut twists = Vec::new();
    observations
        .iter()
        .enumerate()
        .map(|(index, observation)| {
            let pose = predict(model, observation, index, correction, &mut twists)?;
            Ok(match observation.target {
                Target::Pose(measured) => RowError {
                    position_m: (measured.translation() - pose.translation()).norm(),
                    rotation_rad: Some((measured.rotation() * pose.rotation().inverse()).log().norm()),
                },
                Target::Point(measured) => {
                    RowError { position_m: (measured - pose.translation()).norm(), rotation_rad: None }
                }
            })
        })
        .collect()
}

/// The predicted pose of observation `index`: the model's, moved by the correction if any.
pub(crate) fn predict(
    model: &LocalPoe,
    observation: &Observation,
    index: usize,
    correction: Option<Corrected<'_>>,
    twists: &mut Vec<Vector6>,
) -> Result<SE3, Error> {
    let pose = model.forward(&observation.q, observation.tool)?;
    Ok(match correction {
        Some(c) => c.apply(model, index, pose, twists),
        None => pose,
    })
}

/// The weighted residual vector and the error statistics of `model` on `observations`, each
/// observation's rows also weighted by its robust weight and its stated noise (`weights`).
pub(crate) fn residuals(
    model: &LocalPoe,
    observations: &[Observation],
    correction: Option<Corrected<'_>>,
    weights: Weights<'_>,
    options: &IdentificationOptions,
) -> Result<(Vec<f64>, ResidualStats), Error> {
    // Blocks of observations side by side, their rows and errors then taken in observation order
    // (as `linearise_reduced` does): the same bits on any number of threads.
    let size = options.block_observations.max(1);
    let block = |(k, chunk): (usize, &[Observation])| -> Result<(Vec<f64>, Vec<ObservationError>), Error> {
        let mut y = vec![0.0; row_count(chunk)];
        let mut errors = Vec::with_capacity(chunk.len());
        let mut twists = Vec::new();
        let mut row = 0;
        for (index, observation) in (k * size..).zip(chunk) {
            let rows = row_kind(observation).rows();
            let pose = predict(model, observation, index, correction, &mut twists)?;
            errors.push(weighted_residual(observation, &pose, weights.of(options, index), &mut y[row..row + rows]));
            row += rows;
        }
        Ok((y, errors))
    };
    let blocks: Vec<_> = observations.par_chunks(size).enumerate().map(block).collect();
    let mut y = Vec::with_capacity(row_count(observations));
    let mut acc = Accumulator::default();
    for result in blocks {
        let (rows, errors) = result?;
        y.extend(rows);
        errors.into_iter().for_each(|e| acc.add(e));
    }
    Ok((y, acc.stats()))
}

/// The weighted Jacobian restricted to the `free` kinematic columns followed by one column per
/// correction parameter, the weighted residual and the errors; rows weighted as by [`residuals`].
///
/// With a correction `exp(ξ)`, the kinematic columns are those of the corrected pose: each left
/// twist of the uncorrected pose is carried through `exp(ξ)`, and the joint twists that `ξ` is made
/// of turn with the blocks before them (`correction::KinematicMap`); rows are then taken at the corrected
/// tool point. Rotation rows take `d log = I`, first order in the residual angle, as everywhere.
#[cfg(test)]
pub(crate) fn linearise(
    model: &LocalPoe,
    observations: &[Observation],
    free: &[usize],
    correction: Option<Corrected<'_>>,
    weights: Weights<'_>,
    options: &IdentificationOptions,
) -> Result<(Mat<f64>, Vec<f64>, ResidualStats), Error> {
    let extra = correction.map_or(0, |c| c.theta.len());
    let total_rows = row_count(observations);
    let mut a = Mat::<f64>::zeros(total_rows, free.len() + extra);
    let mut y = vec![0.0; total_rows];
    let mut acc = Accumulator::default();
    let block = Block { observations, first: 0 };
    let mut errors = Vec::new();
    linearise_block(model, block, free, correction, weights, options, a.as_mut(), &mut y, &mut errors)?;
    errors.into_iter().for_each(|e| acc.add(e));
    Ok((a, y, acc.stats()))
}

/// [`linearise`] folded into its QR triangle ([`Reduced`]) `options.block_observations`
/// observations at a time, so that memory stays that of one block however many rows there are.
pub(crate) fn linearise_reduced(
    model: &LocalPoe,
    observations: &[Observation],
    free: &[usize],
    correction: Option<Corrected<'_>>,
    weights: Weights<'_>,
    options: &IdentificationOptions,
) -> Result<(Reduced, ResidualStats), Error> {
    let columns = free.len() + correction.map_or(0, |c| c.theta.len());
    let mut reduced = Reduced::new(columns);
    let mut acc = Accumulator::default();
    let size = options.block_observations.max(1);
    let blocks: Vec<Block<'_>> = observations
        .chunks(size)
        .enumerate()
        .map(|(k, chunk)| Block { observations: chunk, first: k * size })
        .collect();
    // As many blocks linearised side by side as there are threads (memory: that many blocks),
    // then folded and counted in block order, so that the triangle and the statistics are the
    // same bits on any number of threads.
    let linearised = |block: &Block<'_>| -> Result<Linearised, Error> {
        let rows = row_count(block.observations);
        let mut a = Mat::<f64>::zeros(rows, columns);
        let mut y = vec![0.0; rows];
        let mut errors = Vec::with_capacity(block.observations.len());
        linearise_block(model, *block, free, correction, weights, options, a.as_mut(), &mut y, &mut errors)?;
        Ok(Linearised { a, y, errors })
    };
    for group in blocks.chunks(rayon::current_num_threads().max(1)) {
        let done: Vec<_> = group.par_iter().map(linearised).collect();
        for result in done {
            let Linearised { a, y, errors } = result?;
            reduced.fold(a.as_ref(), &y);
            errors.into_iter().for_each(|e| acc.add(e));
        }
    }
    Ok((reduced, acc.stats()))
}

/// One block's weighted rows, residuals and errors, before they are folded in.
struct Linearised {
    a: Mat<f64>,
    y: Vec<f64>,
    errors: Vec<ObservationError>,
}

/// Consecutive observations and the index of the first among all of them (the correction's
/// twists are per observation).
#[derive(Clone, Copy)]
struct Block<'a> {
    observations: &'a [Observation],
    first: usize,
}

/// The rows of one [`Block`] written into `a` and `y`, each observation's errors pushed to `errors`.
#[allow(clippy::too_many_arguments)]
fn linearise_block(
    model: &LocalPoe,
    block: Block<'_>,
    free: &[usize],
    correction: Option<Corrected<'_>>,
    weights: Weights<'_>,
    options: &IdentificationOptions,
    mut a: MatMut<'_, f64>,
    y: &mut [f64],
    errors: &mut Vec<ObservationError>,
) -> Result<(), Error> {
    let columns = model.layout().len();
    let joint_columns = 6 * model.joint_count();
    let extra = correction.map_or(0, |c| c.theta.len());
    let mut scratch = vec![0.0; 6 * columns];
    let mut twists = Vec::new();
    let mut row = 0;
    for (offset, observation) in block.observations.iter().enumerate() {
        let index = block.first + offset;
        let kind = row_kind(observation);
        let rows = kind.rows();
        let (pose, map) = match correction {
            None => {
                let buffer = &mut scratch[..rows * columns];
                (model.identification_jacobian(&observation.q, observation.tool, kind, buffer)?, None)
            }
            Some(c) => {
                // Twist columns of the uncorrected pose, carried through the correction below
                // (`correction::KinematicMap`).
                let pose =
                    model.identification_jacobian(&observation.q, observation.tool, RowKind::FullPose, &mut scratch)?;
                c.apply_with_map(model, index, pose, &mut twists)
            }
        };
        let row_weights = weights.of(options, index);
        errors.push(weighted_residual(observation, &pose, row_weights, &mut y[row..row + rows]));
        let weight = |r: usize| row_weights[r];
        // A left twist c moves the tool point by v + ω × p and the orientation by ω.
        let p = pose.translation();
        let rows_of = |twist: &Vector6, out: &mut [f64; 6]| {
            let v = twist.fixed_rows::<3>(0) - SO3::hat(&p) * twist.fixed_rows::<3>(3);
            for r in 0..3 {
                out[r] = v[r];
                out[r + 3] = twist[r + 3];
            }
        };
        match (correction, map) {
            (None, _) => {
                for r in 0..rows {
                    for (c, &column) in free.iter().enumerate() {
                        a[(row + r, c)] = scratch[r * columns + column] * weight(r);
                    }
                }
            }
            (Some(_), map) => {
                let mut values = [0.0; 6];
                for (c, &column) in free.iter().enumerate() {
                    let eta = Vector6::from_fn(|r, _| scratch[r * columns + column]);
                    let moved = match &map {
                        Some(map) => map.blocks[(column / 6).min(joint_columns / 6)] * eta,
                        None => eta,
                    };
                    rows_of(&moved, &mut values);
                    for r in 0..rows {
                        a[(row + r, c)] = values[r] * weight(r);
                    }
                }
            }
        }
        let mut values = [0.0; 6];
        for (l, twist) in twists.iter().enumerate().take(extra) {
            rows_of(twist, &mut values);
            for r in 0..rows {
                a[(row + r, free.len() + l)] = values[r] * weight(r);
            }
        }
        row += rows;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::identify::PoseCorrection;
    use crate::{JointAxis, JointKind};
    use lie::{SE3, Twist, Vector3};

    /// Two fixed twists scaled by the first joint value: enough to exercise the columns.
    struct Fixed;

    impl PoseCorrection for Fixed {
        fn parameter_count(&self) -> usize {
            2
        }
        fn twists(&self, _: &LocalPoe, index: usize, out: &mut [Vector6]) {
            let s = 1.0 + index as f64;
            out[0] = Vector6::new(0.3, -0.2, 0.1, 0.5, 0.2, -0.4) * s;
            out[1] = Vector6::new(-0.1, 0.4, 0.2, -0.3, 0.6, 0.1) / s;
        }
    }

    /// Joint-space features: parameter `l` turns joint `l % 2` by `θ_l (1 + q_0 l)`.
    struct OnJoints;

    impl PoseCorrection for OnJoints {
        fn parameter_count(&self) -> usize {
            3
        }
        fn twists(&self, model: &LocalPoe, index: usize, out: &mut [Vector6]) {
            let q = [[0.4, -0.7], [-1.0, 0.2]][index];
            let spatial = model.spatial_twists(&q).unwrap();
            for (l, o) in out.iter_mut().enumerate() {
                *o = spatial[l % 2].to_vector() * (1.0 + q[0] * l as f64);
            }
        }
        fn joint(&self, parameter: usize) -> Option<usize> {
            Some(parameter % 2)
        }
    }

    fn two_joint_arm() -> LocalPoe {
        let axis =
            |d: [f64; 3], p: [f64; 3]| JointAxis { kind: JointKind::Revolute, direction: d.into(), point: p.into() };
        LocalPoe::from_zero_configuration(
            &[axis([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]), axis([0.0, 1.0, 0.0], [0.3, 0.0, 0.5])],
            SE3::from_translation(Vector3::new(0.8, 0.1, 0.6)),
        )
        .unwrap()
    }

    /// A pose and a point measured near the prediction of `model` (a small left nudge), as at
    /// convergence, where Gauss–Newton's first-order columns are exact.
    fn near_prediction(model: &LocalPoe) -> Vec<Observation> {
        let nudge = Twist::new(Vector3::new(2e-4, -1e-4, 5e-5), Vector3::new(3e-4, 1e-4, 2e-4)).exp();
        let pose = nudge * model.forward(&[0.4, -0.7], 0).unwrap();
        vec![
            Observation { q: vec![0.4, -0.7], tool: 0, target: Target::Pose(pose), stated_sigma: None },
            Observation { q: vec![-1.0, 0.2], tool: 0, target: Target::Point(pose.translation()), stated_sigma: None },
        ]
    }

    #[test]
    fn blocks_linearised_or_evaluated_side_by_side_give_the_same_bits_as_one_thread() {
        let model = two_joint_arm();
        let base = near_prediction(&model);
        // 37 observations in blocks of 4: ten blocks, the last one short.
        let observations: Vec<Observation> = (0..37)
            .map(|i| {
                let mut o = base[i % 2].clone();
                o.q = vec![0.4 - 0.05 * i as f64, -0.7 + 0.03 * i as f64];
                o
            })
            .collect();
        let options = IdentificationOptions { block_observations: 4, ..IdentificationOptions::default() };
        let free: Vec<usize> = (0..model.layout().len()).collect();
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (reduced, stats) = pool
                .install(|| linearise_reduced(&model, &observations, &free, None, Weights::default(), &options))
                .unwrap();
            let r: Vec<u64> = (0..reduced.r.nrows())
                .flat_map(|i| (0..reduced.r.ncols()).map(move |j| (i, j)))
                .map(|(i, j)| reduced.r[(i, j)].to_bits())
                .collect();
            let z: Vec<u64> = reduced.z.iter().map(|v| v.to_bits()).collect();
            let stats = (stats.rms_position_m.to_bits(), stats.rms_rotation_rad.map(f64::to_bits));
            (r, z, reduced.residual_sq.to_bits(), stats)
        };
        let one = run(1);
        assert!(!one.0.is_empty() && one.3.1.is_some());
        assert_eq!(one, run(3));
        let residual = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let (y, stats) =
                pool.install(|| residuals(&model, &observations, None, Weights::default(), &options)).unwrap();
            let y: Vec<u64> = y.iter().map(|v| v.to_bits()).collect();
            (y, stats.rms_position_m.to_bits(), stats.rms_rotation_rad.map(f64::to_bits))
        };
        let serial = residual(1);
        assert_eq!(serial.0.len(), row_count(&observations));
        assert_eq!(serial, residual(3));
    }

    #[test]
    fn kinematic_columns_under_a_correction_match_finite_differences_of_the_residual() {
        let model = two_joint_arm();
        let observations = near_prediction(&model);
        let options = IdentificationOptions::default();
        // A correction of a few mrad, so that leaving it out of the kinematic columns would show.
        let theta = [4e-3, -3e-3, 2e-3];
        let corrected = || Some(Corrected { correction: &OnJoints, theta: &theta });
        let free: Vec<usize> = (0..model.layout().len()).collect();
        let (a, _, _) = linearise(&model, &observations, &free, corrected(), Weights::default(), &options).unwrap();
        let h = 1e-7;
        for &k in &free {
            let moved = |sign: f64| {
                let mut step = vec![0.0; free.len()];
                step[k] = sign * h;
                let mut m = model.clone();
                m.apply_update(&step);
                residuals(&m, &observations, corrected(), Weights::default(), &options).unwrap().0
            };
            let (yp, ym) = (moved(1.0), moved(-1.0));
            for r in 0..yp.len() {
                let numeric = -(yp[r] - ym[r]) / (2.0 * h);
                // In weighted units (1/σ = 1e4 per metre or radian). Position rows are exact to the
                // finite difference's rounding; rotation rows take d log = I, first order in the
                // residual angle (about 5e-3 rad with the correction here).
                let tolerance = if (3..6).contains(&r) { 5e-3 * 1e4 } else { 1e-6 * 1e4 };
                assert!((a[(r, k)] - numeric).abs() < tolerance, "row {r} column {k}: {} vs {numeric}", a[(r, k)]);
            }
        }
    }

    #[test]
    fn correction_columns_match_finite_differences_of_the_residual() {
        let model = two_joint_arm();
        let observations = near_prediction(&model);
        let options = IdentificationOptions::default();
        let theta = [2e-3, -1e-3];
        let corrected = Some(Corrected { correction: &Fixed, theta: &theta });
        let (a, _, _) = linearise(&model, &observations, &[], corrected, Weights::default(), &options).unwrap();
        let h = 1e-7;
        for l in 0..2 {
            let mut plus = theta;
            let mut minus = theta;
            plus[l] += h;
            minus[l] -= h;
            let (yp, _) = residuals(
                &model,
                &observations,
                Some(Corrected { correction: &Fixed, theta: &plus }),
                Weights::default(),
                &options,
            )
            .unwrap();
            let (ym, _) = residuals(
                &model,
                &observations,
                Some(Corrected { correction: &Fixed, theta: &minus }),
                Weights::default(),
                &options,
            )
            .unwrap();
            for r in 0..yp.len() {
                // The residual is measured − predicted, so its derivative is −A.
                let numeric = -(yp[r] - ym[r]) / (2.0 * h);
                // The columns carry the left Jacobian of the correction's exponential, so position
                // rows (0..3, 6..9) are exact; rotation rows (3..6) take d log = I, first order
                // in the residual angle (about 2e-3 rad here), like the kinematic columns.
                let tolerance = if (3..6).contains(&r) { 5e-3 } else { 1e-6 };
                assert!(
                    (a[(r, l)] - numeric).abs() < tolerance * (1.0 + numeric.abs()),
                    "row {r} column {l}: {} vs {numeric}",
                    a[(r, l)]
                );
            }
        }
    }

    /// The robust loss's row weights scale each observation's rows by `√w`, and its stated noise
    /// (relative, per component) divides each component: the Jacobian so weighted is still the
    /// derivative of the residual so weighted.
    #[test]
    fn row_weighted_columns_match_finite_differences_of_the_row_weighted_residual() {
        let model = two_joint_arm();
        let observations = near_prediction(&model);
        let options = IdentificationOptions::default();
        let robust = [[0.25, 0.64], [0.09, 1.0]];
        let noise = [[2.0, 1.0, 0.5, 1.0, 4.0, 1.0], [1.0, 1.0, 2.0, 1.0, 1.0, 1.0]];
        let weights = Weights { robust: &robust, noise: &noise };
        let free: Vec<usize> = (0..model.layout().len()).collect();
        let (a, y, _) = linearise(&model, &observations, &free, None, weights, &options).unwrap();
        let (plain_a, plain_y, _) =
            linearise(&model, &observations, &free, None, Weights::default(), &options).unwrap();
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1.0);
        assert!(close(y[0], plain_y[0] * 0.5 / 2.0) && close(y[3], plain_y[3] * 0.8) && close(y[6], plain_y[6] * 0.3));
        assert!(close(y[4], plain_y[4] * 0.8 / 4.0) && close(y[8], plain_y[8] * 0.3 / 2.0));
        assert!(close(a[(7, 4)], plain_a[(7, 4)] * 0.3) && close(a[(4, 2)], plain_a[(4, 2)] * 0.8 / 4.0));
        assert!(close(a[(2, 3)], plain_a[(2, 3)] * 0.5 / 0.5));
        let h = 1e-7;
        for &k in &free {
            let moved = |sign: f64| {
                let mut step = vec![0.0; free.len()];
                step[k] = sign * h;
                let mut m = model.clone();
                m.apply_update(&step);
                residuals(&m, &observations, None, weights, &options).unwrap().0
            };
            let (yp, ym) = (moved(1.0), moved(-1.0));
            for r in 0..yp.len() {
                let numeric = -(yp[r] - ym[r]) / (2.0 * h);
                // Weighted units as above; rotation rows first order in the residual angle.
                let tolerance = if (3..6).contains(&r) { 1e-3 * 1e4 } else { 1e-6 * 1e4 };
                assert!((a[(r, k)] - numeric).abs() < tolerance, "row {r} column {k}: {} vs {numeric}", a[(r, k)]);
            }
        }
    }
}
