//! Type-II maximum likelihood: maximise the log marginal likelihood over the kernel's
//! log-parameters with bounded L-BFGS, from the given start and from seeded random starts run in
//! parallel; the best is chosen deterministically (highest likelihood, then lowest start index).
//!
//! With a warm-start subset ([`OptimiserConfig::warm_start_rows`]) every start is first searched on
//! a seeded random subset of the rows, where an evaluation costs `(s/n)³` of a full one, and the
//! full data are searched once, from the subset's best optimum: the subset's optimum is the data's
//! own first guess, a few full iterations away from the full optimum.

use std::cell::Cell;
use std::sync::atomic::{AtomicUsize, Ordering};

use faer::{Mat, MatRef};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::config::{OptimiserConfig, Parallelism};
use crate::kernel::{Bounds, Kernel};
use crate::lml::{Workspace, evaluate_gradient, evaluate_value};
use crate::points::Points;
use crate::subset::random_indices;
use lbfgsb::{Objective, Settings, Termination};

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

/// Output groups [`crate::ExactGp`] fits one thread each, not yet finished, over the process: a
/// group's evaluations stay on its thread (faer's parallel routines wait for threads busy with
/// groups of their own) but for the last one, alone, which uses the pool. Results are the same.
static UNFINISHED_GROUPS: AtomicUsize = AtomicUsize::new(0);
thread_local!(static IN_GROUP: Cell<bool> = const { Cell::new(false) });

/// The groups one fit counted in [`UNFINISHED_GROUPS`]. Each group run by [`Self::run`] takes
/// itself back when it ends, a panic included; dropping this takes back the groups that never ran
/// (a panic elsewhere ended the fit), so the count stays true for the process's later fits.
pub(crate) struct ExpectedGroups {
    left: AtomicUsize,
}

impl ExpectedGroups {
    /// Counts `groups` more in [`UNFINISHED_GROUPS`], before any of them runs.
    pub(crate) fn new(groups: usize) -> Self {
        UNFINISHED_GROUPS.fetch_add(groups, Ordering::SeqCst);
        Self { left: AtomicUsize::new(groups) }
    }

    /// `f()` on this thread as one of the counted groups.
    pub(crate) fn run<T>(&self, f: impl FnOnce() -> T) -> T {
        struct Finish<'a>(&'a AtomicUsize, bool);
        impl Drop for Finish<'_> {
            fn drop(&mut self) {
                IN_GROUP.set(self.1);
                self.0.fetch_sub(1, Ordering::SeqCst);
                UNFINISHED_GROUPS.fetch_sub(1, Ordering::SeqCst);
            }
        }
        let _finish = Finish(&self.left, IN_GROUP.replace(true));
        f()
    }
}

impl Drop for ExpectedGroups {
    fn drop(&mut self) {
        UNFINISHED_GROUPS.fetch_sub(*self.left.get_mut(), Ordering::SeqCst);
    }
}

/// `parallelism`, or the pool for the last of [`UNFINISHED_GROUPS`].
fn tail_aware(parallelism: Parallelism) -> Parallelism {
    let last = IN_GROUP.get() && UNFINISHED_GROUPS.load(Ordering::SeqCst) == 1;
    if last { Parallelism::Rayon } else { parallelism }
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

impl<'a> NegativeLml<'a> {
    fn new(
        start: &'a Kernel,
        x: &'a Points,
        y: MatRef<'a, f64>,
        config: &OptimiserConfig,
        parallelism: Parallelism,
    ) -> Self {
        let workspace = Workspace::default().with_cache_budget(config.kernel_cache_bytes);
        Self { start, x, y, parallelism, workspace }
    }
}

impl Objective for NegativeLml<'_> {
    fn value(&mut self, p: &[f64]) -> Option<f64> {
        let kernel = self.start.with_log_parameters(p).ok()?;
        evaluate_value(&mut self.workspace, &kernel, self.x, self.y, tail_aware(self.parallelism)).ok().map(|v| -v)
    }
    fn gradient(&mut self) -> Option<Vec<f64>> {
        let g = evaluate_gradient(&mut self.workspace, self.x.dim(), tail_aware(self.parallelism));
        (!g.is_empty()).then(|| g.iter().map(|v| -v).collect())
    }
}

/// Every start searched on `x, y`; the results in start order.
fn search_all(
    start: &Kernel,
    starts: &[Vec<f64>],
    (lower, upper): (&[f64], &[f64]),
    (x, y): (&Points, MatRef<'_, f64>),
    settings: &Settings,
    config: &OptimiserConfig,
    parallelism: Parallelism,
) -> Vec<Option<lbfgsb::Minimum>> {
    let run = |p0: &Vec<f64>| {
        let mut objective = NegativeLml::new(start, x, y, config, parallelism);
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

/// The searches of every start on the warm-start subset, before the one full-data search.
#[derive(Debug, Clone)]
pub(crate) struct WarmStage {
    results: Vec<Option<lbfgsb::Minimum>>,
    /// The subset's rows, in the order the searches saw them.
    indices: Vec<usize>,
    evaluations: usize,
    best: usize,
}

impl WarmStage {
    /// The highest log marginal likelihood a start reached on the subset.
    pub(crate) fn best_log_marginal_likelihood(&self) -> f64 {
        self.results[self.best].as_ref().map_or(f64::NEG_INFINITY, |m| -m.f)
    }

    /// Rows of the subset.
    pub(crate) fn rows(&self) -> usize {
        self.indices.len()
    }

    /// The subset's rows.
    pub(crate) fn indices(&self) -> &[usize] {
        &self.indices
    }

    /// The searches of `self` and then `other` (of one family, on one subset) as one stage.
    pub(crate) fn join(self, other: WarmStage) -> WarmStage {
        debug_assert_eq!(self.indices, other.indices);
        let mut results = self.results;
        results.extend(other.results);
        let best = best(&results).map_or(0, |(i, _)| i);
        WarmStage { results, indices: self.indices, evaluations: self.evaluations + other.evaluations, best }
    }

    /// The subset's best optimum as a kernel of `start`'s family.
    pub(crate) fn best_kernel(&self, start: &Kernel) -> Result<Kernel, Error> {
        let minimum =
            self.results[self.best].as_ref().ok_or(Error::OptimisationFailed { starts: self.results.len() })?;
        start.with_log_parameters(&minimum.x)
    }
}

/// The search's box (log-parameters), starting points and settings for `start`.
struct Prepared {
    lower: Vec<f64>,
    upper: Vec<f64>,
    starts: Vec<Vec<f64>>,
    settings: Settings,
}

/// The search's settings and box for `start`, with `nested` as its deterministic starts after
/// `start` itself.
fn prepare(start: &Kernel, nested: &[Kernel], bounds: &Bounds, config: &OptimiserConfig) -> Result<Prepared, Error> {
    let (lower, upper) = bounds.to_log(start)?;
    let nested: Vec<Vec<f64>> = nested.iter().map(Kernel::log_parameters).collect();
    let starts = starting_points(&start.log_parameters(), &nested, &lower, &upper, config);
    let settings = Settings {
        memory: config.memory,
        max_iterations: config.max_iterations,
        gradient_tolerance: config.gradient_tolerance,
        function_tolerance: config.function_tolerance,
    };
    Ok(Prepared { lower, upper, starts, settings })
}

/// `settings` for a search from an optimum found elsewhere
/// ([`OptimiserConfig::refine_function_tolerance`], [`OptimiserConfig::refine_max_iterations`]).
fn refining(settings: Settings, config: &OptimiserConfig) -> Settings {
    Settings {
        function_tolerance: config.refine_function_tolerance.unwrap_or(settings.function_tolerance),
        max_iterations: config.refine_max_iterations.unwrap_or(settings.max_iterations),
        ..settings
    }
}

/// Every start searched on the warm-start subset (`None` when the configuration has no subset or
/// the data are no larger than it): `start` itself, then `nested` (usually
/// [`Kernel::nested_starts`]), all of one family, then the configured random restarts.
pub(crate) fn warm_stage_from(
    start: &Kernel,
    nested: &[Kernel],
    bounds: &Bounds,
    x: &Points,
    y: MatRef<'_, f64>,
    config: &OptimiserConfig,
    parallelism: Parallelism,
) -> Result<Option<WarmStage>, Error> {
    let n = x.len();
    let warm = config.warm_start_rows;
    if warm == 0 || n <= warm {
        return Ok(None);
    }
    let Prepared { lower, upper, starts, settings } = prepare(start, nested, bounds, config)?;
    let idx = random_indices(n, warm, config.seed);
    let xs = x.select(&idx);
    let ys = Mat::from_fn(idx.len(), y.ncols(), |i, j| y[(idx[i], j)]);
    let results = search_all(start, &starts, (&lower, &upper), (&xs, ys.as_ref()), &settings, config, parallelism);
    let Some((best, _)) = best(&results) else {
        return Err(Error::OptimisationFailed { starts: starts.len() });
    };
    let evaluations = results.iter().flatten().map(|m| m.evaluations).sum();
    Ok(Some(WarmStage { results, indices: idx, evaluations, best }))
}

/// The full-data search: from the warm stage's best optimum when there is one, else from
/// `start`, then `nested` (usually [`Kernel::nested_starts`]) and the configured random restarts.
#[allow(clippy::too_many_arguments)]
pub(crate) fn finish_from(
    start: &Kernel,
    nested: &[Kernel],
    bounds: &Bounds,
    x: &Points,
    y: MatRef<'_, f64>,
    config: &OptimiserConfig,
    parallelism: Parallelism,
    warm: Option<WarmStage>,
) -> Result<Optimised, Error> {
    let Prepared { lower, upper, starts, settings } = prepare(start, nested, bounds, config)?;
    let (results, warm_rows, warm_evaluations, full) = match warm {
        Some(stage) => {
            let settings = refining(settings, config);
            let full = if settings.max_iterations == 0 {
                // No iteration on all rows: the subset's optimum as it is, converged as its search
                // did there, and no evaluation on all rows counted.
                stage.results[stage.best].clone().map(|m| lbfgsb::Minimum {
                    iterations: 0,
                    evaluations: 0,
                    gradients: 0,
                    ..m
                })
            } else {
                let from = stage.results[stage.best]
                    .as_ref()
                    .map(|m| m.x.clone())
                    .ok_or(Error::OptimisationFailed { starts: starts.len() })?;
                // The subset's curvature carried over: the likelihood is a sum over rows, so its
                // Hessian grows about in proportion to them and each gradient change is scaled by
                // n / s. The full search then starts with a quasi-Newton step instead of
                // relearning the curvature down the gradient.
                let scale = x.len() as f64 / stage.rows().max(1) as f64;
                let pairs: Vec<lbfgsb::Pair> = match (&stage.results[stage.best], config.warm_start_curvature) {
                    (Some(m), true) => m
                        .history
                        .iter()
                        .map(|p| lbfgsb::Pair { s: p.s.clone(), y: p.y.iter().map(|v| v * scale).collect() })
                        .collect(),
                    _ => Vec::new(),
                };
                let mut objective = NegativeLml::new(start, x, y, config, parallelism);
                lbfgsb::minimise_with(&mut objective, &from, &lower, &upper, &settings, &pairs)
            };
            (stage.results, stage.indices.len(), stage.evaluations, full)
        }
        None => {
            let results = search_all(start, &starts, (&lower, &upper), (x, y), &settings, config, parallelism);
            (results, 0, 0, None)
        }
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

/// One search on all rows from `start` alone (no nested or random starts, no subset): the
/// refinement of a kernel fitted to similar data, as [`crate::GpConfig::follower_groups`] does.
pub(crate) fn refine(
    start: &Kernel,
    bounds: &Bounds,
    x: &Points,
    y: MatRef<'_, f64>,
    config: &OptimiserConfig,
    parallelism: Parallelism,
) -> Result<Optimised, Error> {
    let Prepared { lower, upper, settings, .. } = prepare(start, &[], bounds, config)?;
    let from: Vec<f64> =
        start.log_parameters().iter().zip(&lower).zip(&upper).map(|((s, l), u)| s.clamp(*l, *u)).collect();
    let mut objective = NegativeLml::new(start, x, y, config, parallelism);
    let minimum = lbfgsb::minimise(&mut objective, &from, &lower, &upper, &refining(settings, config))
        .ok_or(Error::OptimisationFailed { starts: 1 })?;
    let kernel = start.with_log_parameters(&minimum.x)?;
    let report = OptimisationReport {
        start_log_marginal_likelihoods: vec![Some(-minimum.f)],
        best_start: 0,
        iterations: minimum.iterations,
        evaluations: minimum.evaluations,
        converged: matches!(minimum.termination, Termination::GradientTolerance | Termination::FunctionTolerance),
        warm_start_rows: 0,
        warm_start_evaluations: 0,
        gradient_evaluations: minimum.gradients,
    };
    Ok(Optimised { kernel, report })
}
