//! Levenberg–Marquardt with a Gaussian prior about the start (a maximum a posteriori fit): the
//! damping is a trust region that Nielsen's rule widens after good steps and narrows after bad
//! ones (Madsen, Nielsen, Tingleff 2004, §3.2); the prior keeps directions the data does not
//! excite at the start rather than letting noise move them, without a rank cut-off that would also
//! drop weakly excited but real directions. Every accepted step lowers the cost, so a fit started
//! from a smaller model's solution (the new parameters at zero) can only end below it.

use super::normal::{Normal, gradient_cosine};
use super::problem::{Problem, Solved, State, cost, record};
use super::{IterationRecord, Termination};
use crate::Error;

/// The prior weight `1/σ` of every parameter: kinematic blocks are `(v, ω)` sextuples, held by
/// the problem's [`super::KinematicPrior`] where it has one, else by the options' prior about the
/// start.
pub(super) fn prior_weights(problem: &Problem<'_>) -> Vec<f64> {
    let options = problem.options;
    let mut weights: Vec<f64> = match problem.prior {
        Some(prior) => prior.weights(&problem.free),
        None => problem
            .free
            .iter()
            .map(
                |&index| {
                    if index % 6 < 3 { 1.0 / options.prior_translation_m } else { 1.0 / options.prior_rotation_rad }
                },
            )
            .collect(),
    };
    if let Some(correction) = problem.correction {
        weights.extend((0..correction.parameter_count()).map(|l| 1.0 / correction.prior_sigma(l)));
    }
    weights
}

fn prior_cost(weights: &[f64], deviation: &[f64]) -> f64 {
    weights.iter().zip(deviation).map(|(w, d)| (w * d).powi(2)).sum()
}

pub(super) fn levenberg_marquardt(problem: &Problem<'_>, start: State) -> Result<Solved, Error> {
    let weights = prior_weights(problem);
    damped(problem, start, &weights, problem.options.max_iterations, Vec::new())
}

/// Levenberg–Marquardt without a prior, continuing from `start` for at most `max_iterations`:
/// the pseudo-inverse iteration's fallback when no step along its direction lowers the cost
/// (the undamped direction overshoots along weakly determined directions; damping shortens and
/// turns it towards the gradient, so a descent step exists wherever the gradient is not zero).
/// `history` holds the records of the iterations before it, `start`'s last.
pub(super) fn continue_damped(
    problem: &Problem<'_>,
    start: State,
    max_iterations: usize,
    history: Vec<IterationRecord>,
) -> Result<Solved, Error> {
    let weights = vec![0.0; problem.parameter_count()];
    damped(problem, start, &weights, max_iterations, history)
}

fn damped(
    problem: &Problem<'_>,
    start: State,
    weights: &[f64],
    max_iterations: usize,
    history: Vec<IterationRecord>,
) -> Result<Solved, Error> {
    let options = problem.options;
    let weights = weights.to_vec();
    let mut state = start;
    let (mut a, stats) = problem.linearise(&state)?;
    let mut current = a.residual_sq + prior_cost(&weights, &state.deviation);
    let mut iterations = history;
    if iterations.is_empty() {
        iterations.push(record(stats, 0.0, current));
    }
    let mut lambda = options.initial_damping;
    let mut growth = 2.0;
    let mut normal = Normal::new(&a, &weights, &state.deviation);
    let mut termination = Termination::IterationLimit { iterations: options.max_iterations };
    let mut iteration = 0;
    while iteration < max_iterations {
        let cosine = gradient_cosine(&a, &weights, &state.deviation);
        if cosine <= options.gradient_tolerance {
            termination = Termination::GradientTolerance { gradient_cosine: cosine };
            break;
        }
        iteration += 1;
        let Some(step) = normal.damped_solve(lambda) else {
            // Not definite even damped: widen the damping, as after a rejected step.
            lambda *= growth;
            growth *= 2.0;
            if lambda > options.max_damping {
                return Err(Error::LinearSolveFailed { iteration, decomposition: "damped Cholesky factorisation" });
            }
            continue;
        };
        let trial = problem.step(&state, &step);
        let (trial_y, _) = problem.residuals(&trial)?;
        let trial_cost = cost(&trial_y) + prior_cost(&weights, &trial.deviation);
        let predicted = normal.predicted_decrease(&step);
        if trial_cost.is_finite() && trial_cost < current {
            let rho = (current - trial_cost) / predicted.max(f64::MIN_POSITIVE);
            lambda = (lambda * (1.0 / 3.0_f64).max(1.0 - (2.0 * rho - 1.0).powi(3))).max(options.min_damping);
            growth = 2.0;
            let relative_decrease = (current - trial_cost) / current.max(f64::MIN_POSITIVE);
            state = trial;
            current = trial_cost;
            let (next_a, next_stats) = problem.linearise(&state)?;
            a = next_a;
            normal = Normal::new(&a, &weights, &state.deviation);
            let step_norm = step.iter().map(|v| v * v).sum::<f64>().sqrt();
            iterations.push(record(next_stats, step_norm, current));
            if relative_decrease < options.cost_tolerance {
                termination = Termination::CostTolerance { relative_decrease };
                break;
            }
            let deviation = state.deviation.iter().map(|v| v * v).sum::<f64>().sqrt();
            if step_norm <= options.step_tolerance * (deviation + options.step_tolerance) {
                termination = Termination::StepTolerance { step_norm };
                break;
            }
        } else {
            // MINPACK's xtol: when even a step this short does not lower the cost, the minimum is
            // within it (the trust region has shrunk below the step tolerance).
            let step_norm = step.iter().map(|v| v * v).sum::<f64>().sqrt();
            let deviation = state.deviation.iter().map(|v| v * v).sum::<f64>().sqrt();
            if step_norm <= options.step_tolerance * (deviation + options.step_tolerance) {
                termination = Termination::StepTolerance { step_norm };
                break;
            }
            lambda *= growth;
            growth *= 2.0;
            if lambda > options.max_damping {
                let gradient_cosine = gradient_cosine(&a, &weights, &state.deviation);
                termination = if gradient_cosine <= options.gradient_tolerance {
                    Termination::GradientTolerance { gradient_cosine }
                } else {
                    Termination::DampingLimit { damping: lambda, gradient_cosine }
                };
                break;
            }
        }
    }
    let gradient_cosine = gradient_cosine(&a, &weights, &state.deviation);
    let held_at_prior = held_at_prior(problem, &normal, &weights);
    Ok(Solved {
        state,
        a,
        iterations,
        termination,
        final_cost: current,
        gradient_cosine,
        held_at_prior,
        damping_fallback: None,
    })
}

/// Correction parameters whose posterior standard deviation is more than half the prior's: the
/// data barely moves them.
fn held_at_prior(problem: &Problem<'_>, normal: &Normal, weights: &[f64]) -> Vec<usize> {
    let Some(variances) = normal.posterior_variances() else {
        return Vec::new();
    };
    let offset = problem.free.len();
    (offset..weights.len())
        .filter(|&j| weights[j] > 0.0 && variances[j].sqrt() * weights[j] > 0.5)
        .map(|j| j - offset)
        .collect()
}
