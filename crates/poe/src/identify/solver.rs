//! Iterative linearised least squares (paper Section III-A-2) and Levenberg–Marquardt.

use super::correction::{Corrected, PoseCorrection};
use super::redundancy::find_redundancies;
use super::residual::{ResidualStats, linearise, residuals};
use super::{IdentificationOptions, IdentificationReport, IterationRecord, Observation, ParameterMask, Solver};
use crate::{Error, LocalPoe};
use faer::prelude::Solve;
use faer::{Mat, Side};

/// The result of an identification: the identified model and how it got there.
#[derive(Debug, Clone)]
pub struct Identification {
    /// The identified model.
    pub model: LocalPoe,
    /// The identified correction parameters (empty without a [`PoseCorrection`]).
    pub correction: Vec<f64>,
    /// Iterations, identifiability and the unidentifiable directions.
    pub report: IdentificationReport,
}

fn cost(y: &[f64]) -> f64 {
    y.iter().map(|v| v * v).sum()
}

/// Singular value decomposition of the weighted Jacobian, as plain vectors.
struct Decomposition {
    singular_values: Vec<f64>,
    u: Mat<f64>,
    v: Mat<f64>,
}

fn decompose(a: &Mat<f64>, iterations: usize, residual: f64) -> Result<Decomposition, Error> {
    let svd = a.thin_svd().map_err(|_| Error::NotConverged { iterations, residual })?;
    let s = svd.S().column_vector();
    Ok(Decomposition {
        singular_values: (0..s.nrows()).map(|i| s[i]).collect(),
        u: svd.U().to_owned(),
        v: svd.V().to_owned(),
    })
}

/// `x = A⁺ y` with the directions below `rcond · σ_max` dropped (the paper's pseudo-inverse).
fn pseudo_inverse_step(d: &Decomposition, y: &[f64], rcond: f64) -> Vec<f64> {
    let threshold = rcond * d.singular_values.first().copied().unwrap_or(0.0);
    let mut x = vec![0.0; d.v.nrows()];
    for (k, &sigma) in d.singular_values.iter().enumerate() {
        if sigma <= threshold || sigma == 0.0 {
            continue;
        }
        let uty: f64 = (0..y.len()).map(|i| d.u[(i, k)] * y[i]).sum();
        let scale = uty / sigma;
        for (j, xj) in x.iter_mut().enumerate() {
            *xj += scale * d.v[(j, k)];
        }
    }
    x
}

/// Solves `(AᵀA + λ diag(AᵀA)) x = Aᵀy`.
fn damped_step(normal: &Mat<f64>, gradient: &[f64], lambda: f64) -> Option<Vec<f64>> {
    let p = normal.nrows();
    let mut damped = normal.clone();
    for i in 0..p {
        // A column that no row sees keeps a unit floor so that the system stays definite.
        damped[(i, i)] += lambda * normal[(i, i)].max(1e-12) + 1e-12;
    }
    let llt = damped.llt(Side::Lower).ok()?;
    let rhs = Mat::<f64>::from_fn(p, 1, |i, _| gradient[i]);
    let x = llt.solve(rhs);
    Some((0..p).map(|i| x[(i, 0)]).collect())
}

fn with<'a>(correction: Option<&'a dyn PoseCorrection>, theta: &'a [f64]) -> Option<Corrected<'a>> {
    correction.map(|correction| Corrected { correction, theta })
}

fn scatter(free: &[usize], step: &[f64], length: usize) -> Vec<f64> {
    let mut full = vec![0.0; length];
    for (&index, &value) in free.iter().zip(step) {
        full[index] = value;
    }
    full
}

fn record(stats: ResidualStats, step_norm: f64) -> IterationRecord {
    IterationRecord { rms_position_m: stats.rms_position_m, rms_rotation_rad: stats.rms_rotation_rad, step_norm }
}

/// Identifies the free parameters of `initial` from `observations` by iterating
/// linearise → solve → update (paper: "until the errors converge or a pre-defined number of
/// iterations has passed").
pub fn identify(
    initial: &LocalPoe,
    observations: &[Observation],
    mask: &ParameterMask,
    options: &IdentificationOptions,
) -> Result<Identification, Error> {
    identify_with_correction(initial, observations, mask, None, options)
}

/// [`identify`], with the parameters of a [`PoseCorrection`] identified jointly with the free
/// kinematic ones (starting from zero). The pseudo-inverse drops directions the correction shares
/// with the kinematics, so a correction partly absorbed by the geometry is harmless.
pub fn identify_with_correction(
    initial: &LocalPoe,
    observations: &[Observation],
    mask: &ParameterMask,
    correction: Option<&dyn PoseCorrection>,
    options: &IdentificationOptions,
) -> Result<Identification, Error> {
    let mut theta = vec![0.0; correction.map_or(0, |c| c.parameter_count())];
    let layout = initial.layout();
    if mask.flags().len() != layout.len() {
        return Err(Error::MaskLength { given: mask.flags().len(), expected: layout.len() });
    }
    let free = mask.free_indices();
    let rows = super::residual::row_count(observations);
    if rows < free.len().min(6) {
        return Err(Error::TooFewObservations { rows: observations.len(), needed: free.len().div_ceil(6) });
    }
    let mut model = initial.clone();
    let (a, mut y, stats) = linearise(&model, observations, &free, with(correction, &theta), options)?;
    let mut a = a;
    let mut iterations = vec![record(stats, 0.0)];
    let mut current = cost(&y);
    let mut lambda = 1e-3;
    let mut converged = false;
    for iteration in 1..=options.max_iterations {
        let step = match options.solver {
            Solver::PseudoInverse => {
                let d = decompose(&a, iteration, stats.rms_position_m)?;
                pseudo_inverse_step(&d, &y, options.rcond)
            }
            Solver::LevenbergMarquardt => {
                let normal = a.transpose() * &a;
                let gradient: Vec<f64> = (0..a.ncols()).map(|j| (0..y.len()).map(|i| a[(i, j)] * y[i]).sum()).collect();
                damped_step(&normal, &gradient, lambda).unwrap_or_else(|| vec![0.0; a.ncols()])
            }
        };
        // Line search by halving: Gauss–Newton can overshoot far from the solution.
        let mut scale = 1.0;
        let mut accepted = None;
        for _ in 0..12 {
            let scaled: Vec<f64> = step.iter().map(|s| s * scale).collect();
            let mut trial = model.clone();
            trial.apply_update(&scatter(&free, &scaled[..free.len()], layout.len()));
            let trial_theta: Vec<f64> = theta.iter().zip(&scaled[free.len()..]).map(|(t, s)| t + s).collect();
            let (trial_y, _) = residuals(&trial, observations, with(correction, &trial_theta), options)?;
            let trial_cost = cost(&trial_y);
            if trial_cost.is_finite() && trial_cost <= current {
                accepted = Some((trial, trial_theta, trial_cost, scaled));
                break;
            }
            match options.solver {
                Solver::PseudoInverse => scale *= 0.5,
                Solver::LevenbergMarquardt => break,
            }
        }
        let Some((trial, trial_theta, trial_cost, scaled)) = accepted else {
            if options.solver == Solver::LevenbergMarquardt && lambda < 1e12 {
                lambda *= 10.0;
                continue;
            }
            converged = true;
            break;
        };
        let decrease = (current - trial_cost) / current.max(f64::MIN_POSITIVE);
        model = trial;
        theta = trial_theta;
        current = trial_cost;
        lambda = (lambda / 10.0).max(1e-12);
        let (next_a, next_y, next_stats) = linearise(&model, observations, &free, with(correction, &theta), options)?;
        a = next_a;
        y = next_y;
        let step_norm = scaled.iter().map(|v| v * v).sum::<f64>().sqrt();
        iterations.push(record(next_stats, step_norm));
        if !current.is_finite() {
            return Err(Error::NotConverged { iterations: iteration, residual: next_stats.rms_position_m });
        }
        if decrease < options.tolerance || step_norm < 1e-14 {
            converged = true;
            break;
        }
    }
    let last = iterations.last().map_or(f64::NAN, |r| r.rms_position_m);
    let d = decompose(&a, iterations.len(), last)?;
    let smax = d.singular_values.first().copied().unwrap_or(0.0);
    let kept: Vec<f64> = d.singular_values.iter().copied().filter(|&s| s > options.rcond * smax && s > 0.0).collect();
    let rank = kept.len();
    let condition_number = match kept.last() {
        Some(&smin) => smax / smin,
        None => f64::INFINITY,
    };
    let unidentifiable = find_redundancies(&model, observations, mask, a.ncols().saturating_sub(rank));
    Ok(Identification {
        model,
        correction: theta,
        report: IdentificationReport {
            iterations,
            converged,
            free_parameters: a.ncols(),
            rank,
            singular_values: d.singular_values,
            condition_number,
            unidentifiable,
        },
    })
}
