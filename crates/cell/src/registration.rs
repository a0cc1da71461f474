//! The registration's least squares: a moved reference frame `X` and changed tool transforms `D_t`
//! such that measured poses are `X · P_i · D_t`, where `P_i` is what a calibrated model predicts
//! (geometry, effects and GP) in the frame it was fitted in.
//!
//! Closed-form start (Kabsch's point-set registration, alternated with the tools' linear
//! least squares), then Levenberg–Marquardt on the left perturbation of `X` and the right
//! perturbation of each `D_t`, with the exact Jacobian (the rotation rows through `J_l⁻¹`).

use crate::ErrorKind;
use errors::{Error, option};
use lie::{Matrix3, SE3, SO3, Twist, Vector3};
use nalgebra::{DMatrix, DVector};
use poe::identify::{kabsch, nearest_rotation};
use serde::{Deserialize, Serialize};

/// The numbers the registration is tuned by.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RegistrationOptions {
    /// Weight of a rotation residual row against a position row, m/rad: 1 mm of position counts
    /// as 1 mrad of orientation, the ratio of a laser tracker's position and orientation
    /// accuracies (Leica AT960 with T-Mac: about 0.03 mm and 0.03 mrad at 3 m).
    pub rotation_weight_m_per_rad: f64,
    /// Alternations of the closed-form start (Kabsch for the frame, linear least squares for
    /// the tools); 20 bring a 0.3 m tool offset within the Levenberg–Marquardt basin in the tests.
    pub alternations: usize,
    /// Levenberg–Marquardt iterations at most; the problem has at most a few dozen parameters
    /// and converges in under ten from the closed-form start.
    pub max_iterations: usize,
    /// Stop when a step moves no parameter by more than this (m or rad): far below a tracker's
    /// resolution (about 1e-6 m).
    pub step_tolerance: f64,
    /// Largest over smallest singular value of the column-scaled Jacobian beyond which the poses
    /// are said not to determine the parameters (1e8: half the digits of a double left).
    pub max_condition: f64,
    /// Rounds of variance-component estimation (Helmert; Koch, *Parameter Estimation and
    /// Hypothesis Testing in Linear Models*, 1999, §3.6) on full-pose rows: the rotation weight
    /// re-set to the ratio of the position and rotation residuals' RMS, so that each kind counts
    /// by what the model actually leaves in it, and the fit repeated. Two: the ratio settles
    /// within a few per cent after the first. Zero keeps `rotation_weight_m_per_rad`.
    pub weight_rounds: usize,
    /// The estimated weight stays within this factor of `rotation_weight_m_per_rad` (100: a
    /// model a hundred times worse in one kind than the other is not one to register).
    pub max_weight_change: f64,
}

impl Default for RegistrationOptions {
    fn default() -> Self {
        Self {
            rotation_weight_m_per_rad: 1.0,
            alternations: 20,
            max_iterations: 100,
            step_tolerance: 1e-12,
            max_condition: 1e8,
            weight_rounds: 2,
            max_weight_change: 100.0,
        }
    }
}

impl RegistrationOptions {
    /// Refuses values out of range.
    pub fn validate(&self) -> Result<(), Error> {
        let positive = [
            ("rotation_weight_m_per_rad", self.rotation_weight_m_per_rad),
            ("step_tolerance", self.step_tolerance),
            ("max_condition", self.max_condition),
            ("max_weight_change", self.max_weight_change),
        ];
        for (field, value) in positive {
            option::positive(field, value)?;
        }
        option::at_least_one("max_iterations", self.max_iterations)?;
        Ok(())
    }
}

/// One measured pose: the model's prediction and what the tracker saw.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegistrationRow {
    /// The model's pose `P_i` (its own frame, its reference tool).
    pub predicted: SE3,
    /// Measured tool point, new tracker frame, m.
    pub point: Vector3,
    /// Measured orientation, where it was measured and is used.
    pub rotation: Option<SO3>,
    /// The re-fitted tool the row belongs to (`None`: its tool is held).
    pub slot: Option<usize>,
}

/// What is re-fitted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Unknowns {
    /// Whether the frame `X` is re-fitted (otherwise it is the identity).
    pub frame: bool,
    /// Re-fitted tools (slots `0..tools`).
    pub tools: usize,
    /// Whether the tools' orientations are re-fitted (full-pose rows), or only their points.
    pub tool_rotations: bool,
}

impl Unknowns {
    /// Parameters of one tool.
    pub fn per_tool(&self) -> usize {
        if self.tool_rotations { 6 } else { 3 }
    }

    /// Number of parameters.
    pub fn count(&self) -> usize {
        6 * usize::from(self.frame) + self.tools * self.per_tool()
    }
}

/// The fitted frame and tools.
#[derive(Debug, Clone, PartialEq)]
pub struct Registration {
    /// `new_frame_from_model_frame`.
    pub frame: SE3,
    /// Each re-fitted tool's `reference_tool_from_tool`.
    pub tools: Vec<SE3>,
    /// Levenberg–Marquardt iterations.
    pub iterations: usize,
    /// Weighted RMS residual per row component at the end, m.
    pub rms_m: f64,
    /// The rotation rows' weight of the final fit, m/rad.
    pub rotation_weight_m_per_rad: f64,
}

impl Registration {
    /// The pose this registration predicts for a row.
    pub fn pose(&self, row: &RegistrationRow) -> SE3 {
        let tool = row.slot.map_or_else(SE3::identity, |s| self.tools[s]);
        self.frame * row.predicted * tool
    }
}

/// Fits the unknowns to the rows: the closed-form start, Levenberg–Marquardt, and with rotation
/// rows [`RegistrationOptions::weight_rounds`] re-weightings.
pub fn register_rows(
    rows: &[RegistrationRow],
    unknowns: Unknowns,
    options: &RegistrationOptions,
) -> Result<Registration, Error> {
    options.validate()?;
    let mut options = *options;
    let mut fit = solve(rows, unknowns, &options, start(rows, unknowns, &options))?;
    if rows.iter().any(|r| r.rotation.is_some()) && rows.iter().any(|r| r.rotation.is_none()) {
        // Mixed rows: no shared scale to estimate against.
        return Ok(fit);
    }
    let initial = options.rotation_weight_m_per_rad;
    for _ in 0..options.weight_rounds {
        let (mut position, mut rotation, mut count) = (0.0, 0.0, 0usize);
        for row in rows {
            let pose = fit.pose(row);
            let Some(measured) = row.rotation else { continue };
            position += (pose.translation() - row.point).norm_squared();
            rotation += (pose.rotation() * measured.inverse()).log().norm_squared();
            count += 1;
        }
        if count == 0 || rotation <= 0.0 || position <= 0.0 {
            break;
        }
        let bound = options.max_weight_change;
        options.rotation_weight_m_per_rad = (position / rotation).sqrt().clamp(initial / bound, initial * bound);
        fit = solve(rows, unknowns, &options, fit)?;
    }
    Ok(fit)
}

/// Levenberg–Marquardt from `fit`.
fn solve(
    rows: &[RegistrationRow],
    unknowns: Unknowns,
    options: &RegistrationOptions,
    mut fit: Registration,
) -> Result<Registration, Error> {
    fit.rotation_weight_m_per_rad = options.rotation_weight_m_per_rad;
    let parameters = unknowns.count();
    if parameters == 0 {
        fit.rms_m = rms(rows, &fit, options);
        return Ok(fit);
    }
    let mut lambda = 1e-3;
    let mut cost = squared_residuals(rows, &fit, options);
    for iteration in 1..=options.max_iterations {
        let (jacobian, residual) = linearise(rows, &fit, unknowns, options);
        if iteration == 1 {
            check_determined(&jacobian, options)?;
        }
        let jtj = jacobian.transpose() * &jacobian;
        let jtr = jacobian.transpose() * &residual;
        let scale = jtj.diagonal().max().max(f64::MIN_POSITIVE);
        let mut accepted = None;
        for _ in 0..30 {
            let mut damped = jtj.clone();
            for k in 0..parameters {
                damped[(k, k)] += lambda * scale.max(jtj[(k, k)]);
            }
            let Some(step) = damped.cholesky().map(|c| -c.solve(&jtr)) else {
                lambda *= 10.0;
                continue;
            };
            let trial = apply(&fit, &step, unknowns);
            let trial_cost = squared_residuals(rows, &trial, options);
            if trial_cost <= cost {
                accepted = Some((trial, trial_cost, step.amax()));
                lambda = (lambda / 10.0).max(1e-12);
                break;
            }
            lambda *= 10.0;
        }
        let Some((next, next_cost, step)) = accepted else {
            // No damping lowers the cost: the start is at the minimum to rounding.
            fit.iterations = iteration;
            break;
        };
        let relative = (cost - next_cost) / cost.max(f64::MIN_POSITIVE);
        fit = next;
        cost = next_cost;
        fit.iterations = iteration;
        if step < options.step_tolerance || relative < 1e-15 {
            break;
        }
        if iteration == options.max_iterations {
            return Err(Error::new(ErrorKind::RegistrationNotConverged {
                iterations: iteration,
                rms_m: rms(rows, &fit, options),
            }));
        }
    }
    fit.rms_m = rms(rows, &fit, options);
    Ok(fit)
}

fn start(rows: &[RegistrationRow], unknowns: Unknowns, options: &RegistrationOptions) -> Registration {
    let mut fit = Registration {
        frame: SE3::identity(),
        tools: vec![SE3::identity(); unknowns.tools],
        iterations: 0,
        rms_m: 0.0,
        rotation_weight_m_per_rad: options.rotation_weight_m_per_rad,
    };
    let rounds = if unknowns.frame && unknowns.tools > 0 { options.alternations.max(1) } else { 1 };
    for _ in 0..rounds {
        if unknowns.frame {
            let from: Vec<Vector3> = rows
                .iter()
                .map(|r| (r.predicted * r.slot.map_or_else(SE3::identity, |s| fit.tools[s])).translation())
                .collect();
            let to: Vec<Vector3> = rows.iter().map(|r| r.point).collect();
            fit.frame = kabsch(&from, &to);
        }
        // Each tool's point from its rows: m = X (R_P u + t_P) ⇒ u = R_Pᵀ (X⁻¹ m − t_P), averaged.
        let inverse = fit.frame.inverse();
        for (slot, tool) in fit.tools.iter_mut().enumerate() {
            let mine: Vec<&RegistrationRow> = rows.iter().filter(|r| r.slot == Some(slot)).collect();
            if mine.is_empty() {
                continue;
            }
            let point = mine
                .iter()
                .map(|r| {
                    r.predicted
                        .rotation()
                        .inverse()
                        .act(&(inverse.transform_point(&r.point) - r.predicted.translation()))
                })
                .sum::<Vector3>()
                / mine.len() as f64;
            let rotation = if unknowns.tool_rotations {
                let sum: Matrix3 = mine
                    .iter()
                    .filter_map(|r| r.rotation.map(|m| ((fit.frame * r.predicted).rotation().inverse() * m).matrix()))
                    .sum();
                if sum.norm() > 0.0 { nearest_rotation(&sum) } else { tool.rotation() }
            } else {
                tool.rotation()
            };
            *tool = SE3::new(rotation, point);
        }
    }
    fit
}

/// Residual rows of one row: the point (m), then the weighted rotation `w log(R Rₘᵀ)` where measured.
fn row_residual(
    row: &RegistrationRow,
    fit: &Registration,
    options: &RegistrationOptions,
) -> (Vector3, Option<Vector3>) {
    let pose = fit.pose(row);
    let point = pose.translation() - row.point;
    let rotation = row.rotation.map(|m| (pose.rotation() * m.inverse()).log() * options.rotation_weight_m_per_rad);
    (point, rotation)
}

fn squared_residuals(rows: &[RegistrationRow], fit: &Registration, options: &RegistrationOptions) -> f64 {
    rows.iter()
        .map(|r| {
            let (p, w) = row_residual(r, fit, options);
            p.norm_squared() + w.map_or(0.0, |w| w.norm_squared())
        })
        .sum()
}

fn rms(rows: &[RegistrationRow], fit: &Registration, options: &RegistrationOptions) -> f64 {
    let count: usize = rows.iter().map(|r| if r.rotation.is_some() { 6 } else { 3 }).sum();
    (squared_residuals(rows, fit, options) / count.max(1) as f64).sqrt()
}

/// The stacked residual and its Jacobian in the parameters `[ξ_X (6)] [δu_t, δφ_t]…`:
/// `X ← exp(ξ̂) X`, `D_t ← (R_D exp(δφ̂), t_D + δu)`.
pub(crate) fn linearise(
    rows: &[RegistrationRow],
    fit: &Registration,
    unknowns: Unknowns,
    options: &RegistrationOptions,
) -> (DMatrix<f64>, DVector<f64>) {
    let count: usize = rows.iter().map(|r| if r.rotation.is_some() { 6 } else { 3 }).sum();
    let mut jacobian = DMatrix::zeros(count, unknowns.count());
    let mut residual = DVector::zeros(count);
    let tool_offset = 6 * usize::from(unknowns.frame);
    let w = options.rotation_weight_m_per_rad;
    let mut at = 0;
    for row in rows {
        let pose = fit.pose(row);
        let p = pose.translation();
        let (point, rotation) = row_residual(row, fit, options);
        residual.fixed_rows_mut::<3>(at).copy_from(&point);
        if unknowns.frame {
            jacobian.fixed_view_mut::<3, 3>(at, 0).copy_from(&Matrix3::identity());
            jacobian.fixed_view_mut::<3, 3>(at, 3).copy_from(&(-SO3::hat(&p)));
        }
        let slot = row.slot.map(|s| tool_offset + s * unknowns.per_tool());
        if let Some(column) = slot {
            // p = R_X (R_P t_D + t_P) + t_X: ∂p/∂δu = R_X R_P.
            let carried = (fit.frame * row.predicted).rotation().matrix();
            jacobian.fixed_view_mut::<3, 3>(at, column).copy_from(&carried);
        }
        if let (Some(e), Some(_)) = (rotation, row.rotation) {
            residual.fixed_rows_mut::<3>(at + 3).copy_from(&e);
            let j_inv = SO3::left_jacobian_inverse(&(e / w)) * w;
            if unknowns.frame {
                jacobian.fixed_view_mut::<3, 3>(at + 3, 3).copy_from(&j_inv);
            }
            if let (Some(column), true) = (slot, unknowns.tool_rotations) {
                // R ← R exp(δφ̂) = exp((R δφ)^) R.
                jacobian.fixed_view_mut::<3, 3>(at + 3, column + 3).copy_from(&(j_inv * pose.rotation().matrix()));
            }
            at += 6;
        } else {
            at += 3;
        }
    }
    (jacobian, residual)
}

pub(crate) fn apply(fit: &Registration, step: &DVector<f64>, unknowns: Unknowns) -> Registration {
    let mut next = fit.clone();
    let mut at = 0;
    if unknowns.frame {
        let xi = Twist::new(Vector3::new(step[0], step[1], step[2]), Vector3::new(step[3], step[4], step[5]));
        next.frame = xi.exp() * fit.frame;
        at = 6;
    }
    for tool in &mut next.tools {
        let du = Vector3::new(step[at], step[at + 1], step[at + 2]);
        let rotation = if unknowns.tool_rotations {
            tool.rotation() * SO3::exp(&Vector3::new(step[at + 3], step[at + 4], step[at + 5]))
        } else {
            tool.rotation()
        };
        *tool = SE3::new(rotation, tool.translation() + du);
        at += unknowns.per_tool();
    }
    next
}

/// Refuses poses that leave a direction of the unknowns undetermined: the singular values of
/// the Jacobian with unit columns.
fn check_determined(jacobian: &DMatrix<f64>, options: &RegistrationOptions) -> Result<(), Error> {
    let mut scaled = jacobian.clone();
    for mut column in scaled.column_iter_mut() {
        let norm = column.norm();
        if norm > 0.0 {
            column /= norm;
        }
    }
    let s = scaled.singular_values();
    let largest = s.max();
    let smallest = s.min();
    let condition = if smallest > 0.0 { largest / smallest } else { f64::INFINITY };
    if jacobian.nrows() < jacobian.ncols() || condition > options.max_condition {
        let rank = s.iter().filter(|&&v| v * options.max_condition > largest).count();
        return Err(Error::new(ErrorKind::PosesUndetermined { rank, parameters: jacobian.ncols(), condition }));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_pose(rng: &mut ChaCha8Rng, reach: f64) -> SE3 {
        let w = Vector3::new(rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5), rng.random_range(-1.5..1.5));
        let t = Vector3::new(
            rng.random_range(-reach..reach),
            rng.random_range(-reach..reach),
            rng.random_range(0.0..reach),
        );
        SE3::new(SO3::exp(&w), t)
    }

    fn rows(truth: &Registration, count: usize, full_pose: bool, tools: usize, seed: u64) -> Vec<RegistrationRow> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..count)
            .map(|i| {
                let slot = (tools > 0).then(|| i % tools);
                let mut row = RegistrationRow {
                    predicted: random_pose(&mut rng, 1.0),
                    point: Vector3::zeros(),
                    rotation: None,
                    slot,
                };
                let pose = truth.pose(&row);
                row.point = pose.translation();
                row.rotation = full_pose.then(|| pose.rotation());
                row
            })
            .collect()
    }

    fn moved() -> SE3 {
        SE3::new(SO3::exp(&Vector3::new(0.3, -2.0, 1.1)), Vector3::new(3.6, -1.2, 0.4))
    }

    #[test]
    fn recovers_a_known_frame_from_positions() {
        let truth =
            Registration { frame: moved(), tools: vec![], iterations: 0, rms_m: 0.0, rotation_weight_m_per_rad: 1.0 };
        let data = rows(&truth, 8, false, 0, 1);
        let unknowns = Unknowns { frame: true, tools: 0, tool_rotations: false };
        let fit = register_rows(&data, unknowns, &RegistrationOptions::default()).unwrap();
        assert!((fit.frame * truth.frame.inverse()).log().to_vector().norm() < 1e-9, "{:?}", fit.frame);
        assert!(fit.rms_m < 1e-9);
    }

    #[test]
    fn recovers_a_known_frame_and_new_tools_from_full_poses() {
        let tools = vec![
            SE3::new(SO3::exp(&Vector3::new(0.2, 0.0, 0.5)), Vector3::new(0.05, -0.1, 0.25)),
            SE3::new(SO3::exp(&Vector3::new(0.0, 0.4, 0.0)), Vector3::new(-0.2, 0.02, 0.1)),
        ];
        let truth = Registration {
            frame: moved(),
            tools: tools.clone(),
            iterations: 0,
            rms_m: 0.0,
            rotation_weight_m_per_rad: 1.0,
        };
        let data = rows(&truth, 12, true, 2, 2);
        let unknowns = Unknowns { frame: true, tools: 2, tool_rotations: true };
        let fit = register_rows(&data, unknowns, &RegistrationOptions::default()).unwrap();
        assert!((fit.frame * truth.frame.inverse()).log().to_vector().norm() < 1e-9);
        for (found, wanted) in fit.tools.iter().zip(&tools) {
            assert!((*found * wanted.inverse()).log().to_vector().norm() < 1e-9, "{found:?} {wanted:?}");
        }
    }

    #[test]
    fn recovers_a_tool_point_from_positions_with_the_frame_held() {
        let tool = SE3::from_translation(Vector3::new(0.3, 0.1, -0.2));
        let truth = Registration {
            frame: SE3::identity(),
            tools: vec![tool],
            iterations: 0,
            rms_m: 0.0,
            rotation_weight_m_per_rad: 1.0,
        };
        let data = rows(&truth, 4, false, 1, 3);
        let unknowns = Unknowns { frame: false, tools: 1, tool_rotations: false };
        let fit = register_rows(&data, unknowns, &RegistrationOptions::default()).unwrap();
        assert!((fit.tools[0].translation() - tool.translation()).norm() < 1e-12);
    }

    #[test]
    fn recovers_a_known_frame_and_a_new_tool_point_from_positions() {
        let tool = SE3::from_translation(Vector3::new(0.06, -0.05, 0.06));
        let truth = Registration {
            frame: moved(),
            tools: vec![tool],
            iterations: 0,
            rms_m: 0.0,
            rotation_weight_m_per_rad: 1.0,
        };
        let data = rows(&truth, 20, false, 1, 6);
        let unknowns = Unknowns { frame: true, tools: 1, tool_rotations: false };
        let fit = register_rows(&data, unknowns, &RegistrationOptions::default()).unwrap();
        assert!((fit.frame * truth.frame.inverse()).log().to_vector().norm() < 1e-9, "{fit:?}");
        assert!((fit.tools[0].translation() - tool.translation()).norm() < 1e-9);
    }

    #[test]
    fn collinear_points_are_refused_as_undetermined() {
        let data: Vec<RegistrationRow> = (0..10)
            .map(|i| {
                let p = Vector3::new(0.1 * i as f64, 0.0, 0.0);
                RegistrationRow { predicted: SE3::from_translation(p), point: p, rotation: None, slot: None }
            })
            .collect();
        let unknowns = Unknowns { frame: true, tools: 0, tool_rotations: false };
        let err = register_rows(&data, unknowns, &RegistrationOptions::default()).unwrap_err();
        assert!(matches!(err.kind::<ErrorKind>(), Some(ErrorKind::PosesUndetermined { parameters: 6, .. })), "{err}");
    }

    #[test]
    fn the_jacobian_matches_finite_differences() {
        let truth = Registration {
            frame: moved(),
            tools: vec![SE3::new(SO3::exp(&Vector3::new(0.1, 0.2, 0.3)), Vector3::new(0.1, 0.0, 0.2))],
            iterations: 0,
            rms_m: 0.0,
            rotation_weight_m_per_rad: 1.0,
        };
        let mut data = rows(&truth, 5, true, 1, 4);
        // Position-only rows too, where the tool's rotation is not a parameter.
        data.extend(rows(&truth, 3, false, 1, 7));
        // Linearise away from the solution, where the rotation residuals are not small.
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let at = Registration {
            frame: random_pose(&mut rng, 0.5) * truth.frame,
            tools: vec![random_pose(&mut rng, 0.2)],
            ..truth.clone()
        };
        let unknowns = Unknowns { frame: true, tools: 1, tool_rotations: true };
        let options = RegistrationOptions { rotation_weight_m_per_rad: 0.7, ..RegistrationOptions::default() };
        let (jacobian, residual) = linearise(&data, &at, unknowns, &options);
        let h = 1e-7;
        for k in 0..unknowns.count() {
            let mut step = DVector::zeros(unknowns.count());
            step[k] = h;
            let (_, plus) = linearise(&data, &apply(&at, &step, unknowns), unknowns, &options);
            step[k] = -h;
            let (_, minus) = linearise(&data, &apply(&at, &step, unknowns), unknowns, &options);
            let numeric = (plus - minus) / (2.0 * h);
            let error = (numeric - jacobian.column(k)).amax();
            assert!(error < 1e-6, "column {k}: {error} (residual {})", residual.amax());
        }
    }
}
