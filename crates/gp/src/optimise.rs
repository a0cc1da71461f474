//! Type-II maximum likelihood: maximise the log marginal likelihood over the kernel's
//! log-parameters with bounded L-BFGS, from the given start and from seeded random starts run in
//! parallel; the best is chosen deterministically (highest likelihood, then lowest start index).

use faer::MatRef;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::config::{OptimiserConfig, Parallelism};
use crate::kernel::{Bounds, Kernel};
use crate::lbfgsb::{self, Settings, Termination};
use crate::lml::{Workspace, evaluate};
use crate::points::Points;

/// What the hyperparameter search did, for one kernel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OptimisationReport {
    /// Log marginal likelihood reached from each start (`None` where the start could not be
    /// evaluated); start 0 is the given start, the others are random.
    pub start_log_marginal_likelihoods: Vec<Option<f64>>,
    /// Index of the start whose result was kept.
    pub best_start: usize,
    /// L-BFGS iterations of the kept start.
    pub iterations: usize,
    /// Likelihood evaluations over all starts.
    pub evaluations: usize,
    /// `true` when the kept start stopped on a tolerance rather than on the iteration limit or a
    /// failed line search.
    pub converged: bool,
}

/// A fitted kernel and how the search went.
#[derive(Debug, Clone)]
pub(crate) struct Optimised {
    pub kernel: Kernel,
    pub report: OptimisationReport,
}

/// The log-space starting points: `start` (projected into the box), then `config.restarts` draws,
/// each uniform in the log box from its own ChaCha stream.
fn starting_points(start: &[f64], lower: &[f64], upper: &[f64], config: &OptimiserConfig) -> Vec<Vec<f64>> {
    let mut points = vec![start.iter().zip(lower).zip(upper).map(|((s, l), u)| s.clamp(*l, *u)).collect()];
    for i in 1..=config.restarts {
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(i as u64);
        points.push(lower.iter().zip(upper).map(|(l, u)| if u > l { rng.random_range(*l..*u) } else { *l }).collect());
    }
    points
}

/// Maximises the log marginal likelihood of `y` (n × m, all columns sharing the kernel).
pub(crate) fn fit_hyperparameters(
    start: &Kernel,
    bounds: &Bounds,
    x: &Points,
    y: MatRef<'_, f64>,
    config: &OptimiserConfig,
    parallelism: Parallelism,
) -> Result<Optimised, Error> {
    let (lower, upper) = bounds.to_log(start)?;
    let starts = starting_points(&start.log_parameters(), &lower, &upper, config);
    let settings = Settings {
        memory: config.memory,
        max_iterations: config.max_iterations,
        gradient_tolerance: config.gradient_tolerance,
        function_tolerance: config.function_tolerance,
    };
    let run = |p0: &Vec<f64>| {
        let mut workspace = Workspace::default();
        let objective = |p: &[f64]| {
            let kernel = start.with_log_parameters(p).ok()?;
            let lml = evaluate(&mut workspace, &kernel, x, y, true, parallelism).ok()?;
            Some((-lml.value, lml.gradient.iter().map(|g| -g).collect()))
        };
        lbfgsb::minimise(objective, p0, &lower, &upper, &settings)
    };
    let results: Vec<_> = match parallelism {
        Parallelism::Sequential => starts.iter().map(run).collect(),
        Parallelism::Rayon => starts.par_iter().map(run).collect(),
    };
    let mut best: Option<(usize, &lbfgsb::Minimum)> = None;
    for (i, r) in results.iter().enumerate() {
        if let Some(m) = r
            && best.is_none_or(|(_, b)| m.f < b.f)
        {
            best = Some((i, m));
        }
    }
    let Some((best_start, minimum)) = best else {
        return Err(Error::OptimisationFailed { starts: starts.len() });
    };
    let kernel = start.with_log_parameters(&minimum.x)?;
    let report = OptimisationReport {
        start_log_marginal_likelihoods: results.iter().map(|r| r.as_ref().map(|m| -m.f)).collect(),
        best_start,
        iterations: minimum.iterations,
        evaluations: results.iter().flatten().map(|m| m.evaluations).sum(),
        converged: matches!(minimum.termination, Termination::GradientTolerance | Termination::FunctionTolerance),
    };
    Ok(Optimised { kernel, report })
}
