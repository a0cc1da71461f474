//! The identification loop: the paper's iterative linearised least squares with a pseudo-inverse
//! (Section III-A-2), or Levenberg–Marquardt with a prior (`levenberg.rs`). Both stop only on a
//! stated criterion and say which ([`Termination`]).

use super::correction::PoseCorrection;
use super::levenberg::{continue_damped, levenberg_marquardt};
use super::prior::KinematicPrior;
use super::problem::{Problem, Solved, State, cost, record};
use super::reduced::Reduced;
use super::redundancy::find_redundancies;
use super::residual::row_errors;
use super::robust::{self, RobustReport};
use super::{DampingFallback, IdentificationOptions, IdentificationReport, Observation, ParameterMask, Solver};
use super::{Termination, normal};
use crate::{Error, LocalPoe};

/// The result of an identification: the identified model and how it got there.
#[derive(Debug, Clone)]
pub struct Identification {
    /// The identified model.
    pub model: LocalPoe,
    /// The identified correction parameters (empty without a [`PoseCorrection`]).
    pub correction: Vec<f64>,
    /// The posterior covariance of the free parameters, the free kinematic ones in the mask's
    /// order (their left perturbations, as [`LocalPoe::identification_jacobian`] orders them),
    /// then [`Identification::correction`]'s, row-major `p × p`: `s² (AᵀA + W²)⁻¹` at the solution
    /// (`A` the weighted Jacobian, `W` the prior weights the solver used, `s²` the reduced χ² of
    /// the weighted residual, so that a model that misses by more than the stated noise is the
    /// less certain for it). Directions the data and the prior leave undetermined (below
    /// `rcond`, [`IdentificationReport::rank`]) get no variance: on a local POE model they are
    /// the ones no pose sees. Empty where the decomposition fails.
    pub covariance: Vec<f64>,
    /// Iterations, identifiability and the unidentifiable directions.
    pub report: IdentificationReport,
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
/// kinematic ones (starting from zero).
///
/// Refuses data with fewer residual rows than free parameters. The report says which criterion
/// ended the iterations; `converged` is true only when one of the convergence criteria was met.
pub fn identify_with_correction(
    initial: &LocalPoe,
    observations: &[Observation],
    mask: &ParameterMask,
    correction: Option<&dyn PoseCorrection>,
    options: &IdentificationOptions,
) -> Result<Identification, Error> {
    identify_with_prior(initial, observations, mask, correction, None, options)
}

/// [`identify_with_correction`] under a [`KinematicPrior`] (a maximum a posteriori fit): the
/// kinematic parameters it names are held about its centre, whatever `initial` is, by
/// Levenberg–Marquardt whatever `options.solver` says (the pseudo-inverse has no prior); the
/// options' own prior about the start is then not used. `None`: [`identify_with_correction`].
pub fn identify_with_prior(
    initial: &LocalPoe,
    observations: &[Observation],
    mask: &ParameterMask,
    correction: Option<&dyn PoseCorrection>,
    prior: Option<&KinematicPrior>,
    options: &IdentificationOptions,
) -> Result<Identification, Error> {
    options.validate()?;
    if let Some(prior) = prior {
        prior.validate(initial)?;
    }
    let layout = initial.layout();
    if mask.flags().len() != layout.len() {
        return Err(Error::MaskLength { given: mask.flags().len(), expected: layout.len() });
    }
    let stated = super::stated_noise::Stated::new(observations, &options.stated_noise);
    // The first solve takes the stated noise alone (no scatter beyond it); the reweighted solves
    // then estimate that scatter from their residuals.
    let noise = stated.as_ref().map_or_else(Vec::new, |s| s.factors([0.0, 0.0]));
    let mut problem =
        Problem { observations, free: mask.free_indices(), correction, options, row_weights: Vec::new(), noise, prior };
    let rows = super::residual::row_count(observations);
    let parameters = problem.parameter_count();
    if rows < parameters {
        return Err(Error::TooFewObservations { observations: observations.len(), rows, parameters });
    }
    let theta = vec![0.0; correction.map_or(0, |c| c.parameter_count())];
    let deviation = match prior {
        Some(prior) => prior.deviation(initial, &problem.free).into_iter().chain(theta.iter().copied()).collect(),
        None => vec![0.0; parameters],
    };
    let start = State { model: initial.clone(), theta, deviation };
    let (solved, robust, excess) = reweighted(&mut problem, stated.as_ref(), start)?;
    let stated_noise = stated.map(|s| s.report(excess));
    let svd = normal::Decomposition::new(&solved.a, solved.iterations.len())?;
    let smax = svd.singular_values.first().copied().unwrap_or(0.0);
    let kept: Vec<f64> = svd.singular_values.iter().copied().filter(|&s| s > options.rcond * smax && s > 0.0).collect();
    let rank = kept.len();
    let condition_number = match kept.last() {
        Some(&smin) => smax / smin,
        None => f64::INFINITY,
    };
    let unidentifiable =
        find_redundancies(&solved.state.model, observations, mask, solved.a.r.ncols().saturating_sub(rank));
    let covariance = covariance(&problem, &solved.a, &solved.state.deviation, rows.saturating_sub(rank));
    Ok(Identification {
        model: solved.state.model,
        correction: solved.state.theta,
        covariance,
        report: IdentificationReport {
            iterations: solved.iterations,
            converged: solved.termination.converged(),
            termination: solved.termination,
            final_cost: solved.final_cost,
            gradient_cosine: solved.gradient_cosine,
            free_parameters: parameters,
            residual_rows: rows,
            rank,
            singular_values: svd.singular_values,
            condition_number,
            unidentifiable,
            held_at_prior: solved.held_at_prior,
            damping_fallback: solved.damping_fallback,
            robust,
            stated_noise,
        },
    })
}

/// The posterior covariance of the free parameters of `model` under `prior`, at `model` itself:
/// [`Identification::covariance`] of a fit that ended there (the free kinematic parameters in
/// `mask`'s order, then `correction`'s at its `θ`; the robust loss's weights the residuals at
/// `model` call for, as the last reweighting of [`identify_with_prior`] takes them), with a
/// prior other than the one it was fitted under: where a fit held the links more tightly than
/// their tolerance (a strength chosen by held-out error), what the data and the tolerance alone
/// say of the geometry. Empty where the decomposition fails, as there.
pub fn posterior_covariance(
    model: &LocalPoe,
    observations: &[Observation],
    mask: &ParameterMask,
    correction: Option<(&dyn PoseCorrection, &[f64])>,
    prior: &KinematicPrior,
    options: &IdentificationOptions,
) -> Result<Vec<f64>, Error> {
    options.validate()?;
    prior.validate(model)?;
    let layout = model.layout();
    if mask.flags().len() != layout.len() {
        return Err(Error::MaskLength { given: mask.flags().len(), expected: layout.len() });
    }
    let theta = correction.map_or_else(Vec::new, |(_, theta)| theta.to_vec());
    if let Some((c, _)) = correction
        && c.parameter_count() != theta.len()
    {
        return Err(Error::MaskLength { given: theta.len(), expected: c.parameter_count() });
    }
    let mut problem = Problem {
        observations,
        free: mask.free_indices(),
        correction: correction.map(|(c, _)| c),
        options,
        row_weights: Vec::new(),
        // Unweighted by the rows' stated standard deviations: not yet carried here.
        noise: Vec::new(),
        prior: Some(prior),
    };
    if options.robust.loss == robust::Loss::Huber {
        let errors = row_errors(model, observations, problem.corrected(&theta))?;
        problem.row_weights = robust::assess(&errors, &options.robust).weights;
    }
    let deviation = prior.deviation(model, &problem.free).into_iter().chain(theta.iter().copied()).collect();
    let state = State { model: model.clone(), theta, deviation };
    let (a, _) = problem.linearise(&state)?;
    let svd = normal::Decomposition::new(&a, 0)?;
    let smax = svd.singular_values.first().copied().unwrap_or(0.0);
    let rank = svd.singular_values.iter().filter(|&&s| s > options.rcond * smax && s > 0.0).count();
    let rows = super::residual::row_count(observations);
    Ok(covariance(&problem, &a, &state.deviation, rows.saturating_sub(rank)))
}

/// [`Identification::covariance`]: the pseudo-inverse of the normal matrix under the prior the
/// solver used (none for the pseudo-inverse iteration), the directions below `rcond` dropped as
/// the rank drops them, times the reduced χ² (`dof`: residual rows less the rank), at the
/// linearisation `a` whose prior deviation is `deviation`.
fn covariance(problem: &Problem<'_>, a: &Reduced, deviation: &[f64], dof: usize) -> Vec<f64> {
    let weights = match problem.options.solver {
        Solver::PseudoInverse if problem.prior.is_none() => vec![0.0; problem.parameter_count()],
        _ => super::levenberg::prior_weights(problem),
    };
    let normal = normal::Normal::new(a, &weights, deviation);
    let Some(inverse) = normal.pseudo_inverse(problem.options.rcond) else { return Vec::new() };
    let scale = a.residual_sq / dof.max(1) as f64;
    let p = inverse.nrows();
    (0..p).flat_map(|i| (0..p).map(move |j| (i, j))).map(|(i, j)| inverse[(i, j)] * scale).collect()
}

/// Each row's residual norms over its stated noise relative to the median row's (the root mean
/// square of its point's and of its orientation's factors; module `stated_noise`): the robust loss
/// then judges a row by what its own σ lets it miss, and its scales are a median row's. Unchanged
/// where no row states a σ.
fn relative_to_stated(errors: &[robust::RowError], noise: &[[f64; 6]]) -> Vec<robust::RowError> {
    if noise.is_empty() {
        return errors.to_vec();
    }
    let rms = |f: &[f64]| (f.iter().map(|x| x * x).sum::<f64>() / f.len() as f64).sqrt();
    errors
        .iter()
        .zip(noise)
        .map(|(e, f)| robust::RowError {
            position_m: e.position_m / rms(&f[..3]),
            rotation_rad: e.rotation_rad.map(|r| r / rms(&f[3..])),
        })
        .collect()
}

fn solve(problem: &Problem<'_>, start: State) -> Result<Solved, Error> {
    match problem.options.solver {
        Solver::PseudoInverse if problem.prior.is_none() => gauss_newton(problem, start),
        Solver::PseudoInverse => levenberg_marquardt(problem, start),
        Solver::LevenbergMarquardt => levenberg_marquardt(problem, start),
    }
}

/// The solve under the robust loss (module `robust`): a first solve, then, while the residuals
/// call for other weights, a solve from where the last ended under the weights they call for
/// (iteratively reweighted least squares). The iteration records of the later solves follow the
/// first's.
///
/// The first solve leaves out the rows already beyond the outlier threshold at the start (and
/// only those): a row a metre off would otherwise drag the first solve far from the solution,
/// where Gauss–Newton crawls back for its whole iteration limit. Where no row is beyond the
/// thresholds, at the start or at the end, this is the plain solve alone.
///
/// Where observations state their σ (`stated`), each solve also estimates the residuals' scatter
/// beyond the stated noise, and the solves go on while the stated noise's weights it calls for
/// change (module `stated_noise`); that scatter is returned (per axis, of the point and of the
/// orientation).
fn reweighted(
    problem: &mut Problem<'_>,
    stated: Option<&super::stated_noise::Stated>,
    start: State,
) -> Result<(Solved, RobustReport, [f64; 2]), Error> {
    let options = &problem.options.robust;
    if options.loss == robust::Loss::Huber {
        let errors = row_errors(&start.model, problem.observations, problem.corrected(&start.theta))?;
        let at_start = robust::assess(&relative_to_stated(&errors, &problem.noise), options);
        if !at_start.report.outliers.is_empty() {
            problem.row_weights =
                at_start.weights.iter().map(|w| if *w == [0.0, 0.0] { *w } else { [1.0, 1.0] }).collect();
        }
    }
    let mut solved = solve(problem, start)?;
    let mut reweightings = 0;
    let mut excess = [0.0; 2];
    loop {
        let errors = row_errors(&solved.state.model, problem.observations, problem.corrected(&solved.state.theta))?;
        let mut assessment = robust::assess(&relative_to_stated(&errors, &problem.noise), options);
        // The outliers are named with their own residuals, not those relative to their σ.
        for outlier in &mut assessment.report.outliers {
            outlier.position_m = errors[outlier.observation].position_m;
            outlier.rotation_rad = errors[outlier.observation].rotation_rad;
        }
        let current: &[[f64; 2]] =
            if problem.row_weights.is_empty() { &vec![[1.0, 1.0]; errors.len()] } else { &problem.row_weights };
        let mut settled = robust::settled(current, &assessment.weights, options.weight_tolerance);
        if let Some(stated) = stated {
            let rows = super::residual::row_count(problem.observations) as f64;
            let inflation = rows / (rows - problem.parameter_count() as f64).max(1.0);
            excess = stated.excess(&errors, inflation);
            let noise = stated.factors(excess);
            // Noise factors are weights' inverse square roots: compare them as the robust
            // weights are compared, by the weight each implies.
            let moved = noise.iter().zip(&problem.noise).any(|(a, b)| {
                a.iter().zip(b).any(|(x, y)| (1.0 / (x * x) - 1.0 / (y * y)).abs() > options.weight_tolerance)
            });
            if moved {
                settled = false;
                problem.noise = noise;
            }
        }
        if settled || reweightings == options.max_reweightings {
            let report = RobustReport { reweightings, settled, ..assessment.report };
            return Ok((solved, report, excess));
        }
        reweightings += 1;
        problem.row_weights = assessment.weights;
        let history = std::mem::take(&mut solved.iterations);
        let mut next = solve(problem, solved.state)?;
        // The new solve's first record is its start under the new weights: the last record
        // of the previous solve is the same model, so it is dropped.
        next.iterations = history.into_iter().chain(next.iterations.into_iter().skip(1)).collect();
        solved = next;
    }
}

/// The paper's iteration: `x = A⁺ y` with the directions below `rcond · σ_max` dropped, each step
/// halved until it lowers the cost (Gauss–Newton can overshoot far from the solution).
fn gauss_newton(problem: &Problem<'_>, start: State) -> Result<Solved, Error> {
    let options = problem.options;
    let mut state = start;
    let (mut a, stats) = problem.linearise(&state)?;
    let mut current = a.residual_sq;
    let mut iterations = vec![record(stats, 0.0, current)];
    let mut termination = Termination::IterationLimit { iterations: options.max_iterations };
    for iteration in 1..=options.max_iterations {
        let decomposition = normal::Decomposition::new(&a, iteration)?;
        let step = decomposition.pseudo_inverse_solve(&a.z, options.rcond);
        let mut accepted = None;
        let mut scale = 1.0;
        for _ in 0..=options.line_search_halvings {
            let scaled: Vec<f64> = step.iter().map(|s| s * scale).collect();
            let trial = problem.step(&state, &scaled);
            let (trial_y, _) = problem.residuals(&trial)?;
            let trial_cost = cost(&trial_y);
            if trial_cost.is_finite() && trial_cost <= current {
                accepted = Some((trial, trial_cost, scaled));
                break;
            }
            scale *= 0.5;
        }
        let Some((trial, trial_cost, scaled)) = accepted else {
            let gradient_cosine = normal::gradient_cosine(&a, &[], &[]);
            if gradient_cosine <= options.gradient_tolerance {
                termination = Termination::GradientTolerance { gradient_cosine };
                break;
            }
            // Not stationary, yet the undamped direction lowers nothing within the halvings: it
            // overshoots along weakly determined directions. Damped steps do lower the cost
            // wherever the gradient is not zero, so try them before giving up; their own
            // criteria (or the damping limit) say how the iterations end.
            let after_iteration = iteration - 1;
            let remaining = options.max_iterations - after_iteration;
            let mut damped = continue_damped(problem, state, remaining, iterations)?;
            if let Termination::IterationLimit { .. } = damped.termination {
                damped.termination = Termination::IterationLimit { iterations: options.max_iterations };
            }
            damped.damping_fallback = Some(DampingFallback { after_iteration, gradient_cosine });
            return Ok(damped);
        };
        let relative_decrease = (current - trial_cost) / current.max(f64::MIN_POSITIVE);
        state = trial;
        current = trial_cost;
        let (next_a, next_stats) = problem.linearise(&state)?;
        a = next_a;
        let step_norm = scaled.iter().map(|v| v * v).sum::<f64>().sqrt();
        iterations.push(record(next_stats, step_norm, current));
        if !current.is_finite() {
            return Err(Error::NotConverged { iterations: iteration, residual: next_stats.rms_position_m });
        }
        if relative_decrease < options.cost_tolerance {
            termination = Termination::CostTolerance { relative_decrease };
            break;
        }
        let deviation = state.deviation.iter().map(|v| v * v).sum::<f64>().sqrt();
        if step_norm <= options.step_tolerance * (deviation + options.step_tolerance) {
            termination = Termination::StepTolerance { step_norm };
            break;
        }
    }
    let gradient_cosine = normal::gradient_cosine(&a, &[], &[]);
    Ok(Solved {
        state,
        a,
        iterations,
        termination,
        final_cost: current,
        gradient_cosine,
        held_at_prior: Vec::new(),
        damping_fallback: None,
    })
}
