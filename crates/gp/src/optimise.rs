//! Type-II maximum likelihood: maximise the log marginal likelihood over the kernel's
//! log-parameters with bounded L-BFGS, from the given start and from seeded random starts run in
//! parallel; the best is chosen deterministically (highest likelihood, then lowest start index).
//!
//! With a warm-start subset ([`OptimiserConfig::warm_start_rows`]) every start is first searched on
//! a seeded random subset of the rows, where an evaluation costs `(s/n)³` of a full one, and the
//! full data are searched once, from the subset's best optimum: the subset's optimum is the data's
//! own first guess, a few full iterations away from the full optimum.

use faer::{Mat, MatRef};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::config::{OptimiserConfig, Parallelism};
use crate::inducing::random_indices;
use crate::kernel::{Bounds, Kernel};
use crate::lbfgsb::{self, Objective, Settings, Termination};
use crate::lml::{Workspace, evaluate_gradient, evaluate_value};
use crate::points::Points;

/// What the hyperparameter search did, for one kernel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OptimisationReport {
    /// Log marginal likelihood reached from each start (`None` where the start could not be
    /// evaluated); start 0 is the given start, the others are random. With a warm-start subset,
    /// these are the subset's likelihoods.
    pub start_log_marginal_likelihoods: Vec<Option<f64>>,
    /// Index of the start whose result was kept.
    pub best_start: usize,
    /// L-BFGS iterations of the kept start (on the full data when there was a warm start).
    pub iterations: usize,
    /// Likelihood evaluations over all starts (full data only when there was a warm start).
    pub evaluations: usize,
    /// `true` when the kept start stopped on a tolerance rather than on the iteration limit or a
    /// failed line search.
    pub converged: bool,
    /// Rows of the warm-start subset (0: none, every start searched on the full data).
    #[serde(default)]
    pub warm_start_rows: usize,
    /// Likelihood evaluations on the warm-start subset, over all starts.
    #[serde(default)]
    pub warm_start_evaluations: usize,
    /// Gradients computed on the full data (a line search's rejected trial points need none).
    #[serde(default)]
    pub gradient_evaluations: usize,
}

/// A fitted kernel and how the search went.
#[derive(Debug, Clone)]
pub(crate) struct Optimised {
    pub kernel: Kernel,
    pub report: OptimisationReport,
}

/// The log-space starting points: `start` and then `nested` (each projected into the box), then
/// `config.restarts` draws, each uniform in the log box from its own ChaCha stream.
fn starting_points(
    start: &[f64],
    nested: &[Vec<f64>],
    lower: &[f64],
    upper: &[f64],
    config: &OptimiserConfig,
) -> Vec<Vec<f64>> {
    let project = |p: &Vec<f64>| p.iter().zip(lower).zip(upper).map(|((s, l), u)| s.clamp(*l, *u)).collect();
    let mut points: Vec<Vec<f64>> = std::iter::once(&start.to_vec()).chain(nested).map(project).collect();
    for i in 1..=config.restarts {
        let mut rng = ChaCha8Rng::seed_from_u64(config.seed);
        rng.set_stream(i as u64);
        points.push(lower.iter().zip(upper).map(|(l, u)| if u > l { rng.random_range(*l..*u) } else { *l }).collect());
    }
    points
}

/// The negative log marginal likelihood in log-parameters, in two stages (value, then gradient at
/// the same point from the factor it left).
struct NegativeLml<'a> {
    start: &'a Kernel,
    x: &'a Points,
    y: MatRef<'a, f64>,
    parallelism: Parallelism,
    workspace: Workspace,
}

impl Objective for NegativeLml<'_> {
    fn value(&mut self, p: &[f64]) -> Option<f64> {
        let kernel = self.start.with_log_parameters(p).ok()?;
        evaluate_value(&mut self.workspace, &kernel, self.x, self.y, self.parallelism).ok().map(|v| -v)
    }
    fn gradient(&mut self) -> Option<Vec<f64>> {
        let g = evaluate_gradient(&mut self.workspace, self.x.dim(), self.parallelism);
        (!g.is_empty()).then(|| g.iter().map(|v| -v).collect())
    }
}

/// Every start searched on `x, y`; the results in start order.
fn search_all(
    start: &Kernel,
    starts: &[Vec<f64>],
    (lower, upper): (&[f64], &[f64]),
    x: &Points,
    y: MatRef<'_, f64>,
    settings: &Settings,
    parallelism: Parallelism,
) -> Vec<Option<lbfgsb::Minimum>> {
    let run = |p0: &Vec<f64>| {
        let mut objective = NegativeLml { start, x, y, parallelism, workspace: Workspace::default() };
        lbfgsb::minimise(&mut objective, p0, lower, upper, settings)
    };
    match parallelism {
        Parallelism::Sequential => starts.iter().map(run).collect(),
        Parallelism::Rayon => starts.par_iter().map(run).collect(),
    }
}

/// The best result (lowest negative likelihood, then lowest index).
fn best(results: &[Option<lbfgsb::Minimum>]) -> Option<(usize, &lbfgsb::Minimum)> {
    let mut best: Option<(usize, &lbfgsb::Minimum)> = None;
    for (i, r) in results.iter().enumerate() {
        if let Some(m) = r
            && best.is_none_or(|(_, b)| m.f < b.f)
        {
            best = Some((i, m));
        }
    }
    best
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
    let nested: Vec<Vec<f64>> = start.nested_starts().iter().map(Kernel::log_parameters).collect();
    let starts = starting_points(&start.log_parameters(), &nested, &lower, &upper, config);
    let settings = Settings {
        memory: config.memory,
        max_iterations: config.max_iterations,
        gradient_tolerance: config.gradient_tolerance,
        function_tolerance: config.function_tolerance,
    };
    let n = x.len();
    let warm = config.warm_start_rows;
    let (results, warm_rows, warm_evaluations, full) = if warm > 0 && n > warm {
        let idx = random_indices(n, warm, config.seed);
        let xs = x.select(&idx);
        let ys = Mat::from_fn(idx.len(), y.ncols(), |i, j| y[(idx[i], j)]);
        let sub = search_all(start, &starts, (&lower, &upper), &xs, ys.as_ref(), &settings, parallelism);
        let Some((_, from)) = best(&sub) else {
            return Err(Error::OptimisationFailed { starts: starts.len() });
        };
        let evaluations = sub.iter().flatten().map(|m| m.evaluations).sum();
        let full = search_all(start, std::slice::from_ref(&from.x), (&lower, &upper), x, y, &settings, parallelism);
        (sub, idx.len(), evaluations, full.into_iter().next().flatten())
    } else {
        let results = search_all(start, &starts, (&lower, &upper), x, y, &settings, parallelism);
        (results, 0, 0, None)
    };
    let Some((best_start, best_minimum)) = best(&results) else {
        return Err(Error::OptimisationFailed { starts: starts.len() });
    };
    let (minimum, evaluations, gradients) = match &full {
        Some(m) => (m, m.evaluations, m.gradients),
        None => (
            best_minimum,
            results.iter().flatten().map(|m| m.evaluations).sum(),
            results.iter().flatten().map(|m| m.gradients).sum(),
        ),
    };
    if warm_rows > 0 && full.is_none() {
        return Err(Error::OptimisationFailed { starts: 1 });
    }
    let kernel = start.with_log_parameters(&minimum.x)?;
    let report = OptimisationReport {
        start_log_marginal_likelihoods: results.iter().map(|r| r.as_ref().map(|m| -m.f)).collect(),
        best_start,
        iterations: minimum.iterations,
        evaluations,
        converged: matches!(minimum.termination, Termination::GradientTolerance | Termination::FunctionTolerance),
        warm_start_rows: warm_rows,
        warm_start_evaluations: warm_evaluations,
        gradient_evaluations: gradients,
    };
    Ok(Optimised { kernel, report })
}
