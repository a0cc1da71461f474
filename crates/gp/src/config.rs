//! Configuration of a fit: named fields, `Default`, serde, validated once by [`GpConfig::validate`].

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::kernel::{Bounds, KernelChoice};

/// How several outputs (e.g. the six components of a twist) are modelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum OutputMode {
    /// Each output has its own hyperparameters and its own factorisation.
    #[default]
    Independent,
    /// All outputs share one set of hyperparameters (fitted on the sum of their log marginal
    /// likelihoods) and one Cholesky factorisation.
    Shared,
}

/// Whether kernel matrices, factorisations and restarts run on the rayon pool.
///
/// Either way the result is the same to the last bit: parallel loops write disjoint entries and
/// partial sums are combined in a fixed order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Parallelism {
    /// One thread.
    Sequential,
    /// The global rayon pool.
    #[default]
    Rayon,
}

impl Parallelism {
    /// The faer equivalent.
    pub fn faer(self) -> faer::Par {
        match self {
            Self::Sequential => faer::Par::Seq,
            Self::Rayon => faer::Par::rayon(0),
        }
    }
}

/// Diagonal jitter added when a Cholesky factorisation fails.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct JitterConfig {
    /// First jitter tried, relative to the mean of the kernel matrix's diagonal.
    pub initial_relative: f64,
    /// Factor by which the jitter grows after each failure.
    pub growth: f64,
    /// Attempts with jitter after the first attempt without.
    pub max_attempts: usize,
}

impl Default for JitterConfig {
    fn default() -> Self {
        // 1e-10 … 1e-4 of the signal scale: the last is still far below any noise a tracker sees.
        Self { initial_relative: 1e-10, growth: 10.0, max_attempts: 7 }
    }
}

/// Hyperparameter search: bounded L-BFGS in log space from several starting points.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct OptimiserConfig {
    /// Random starting points drawn (log-uniformly in the bounds) in addition to the default start.
    pub restarts: usize,
    /// Seed of the starting points; start `i` uses its own stream, so the draw does not depend on
    /// the order in which threads run.
    pub seed: u64,
    /// Iterations per start.
    pub max_iterations: usize,
    /// L-BFGS memory (number of correction pairs kept).
    pub memory: usize,
    /// Stop when the largest projected-gradient component of the negative log marginal likelihood
    /// falls below this.
    pub gradient_tolerance: f64,
    /// Stop when the relative decrease of the negative log marginal likelihood in one iteration
    /// falls below this.
    pub function_tolerance: f64,
    /// Search every start on a seeded random subset of this many rows first, then the full data
    /// from the subset's best optimum only (0: every start on the full data). An evaluation on `s`
    /// rows costs `(s/n)³` of a full one, so restarts become nearly free and the full search starts
    /// a few iterations from its optimum. Off by default in the library (it changes which local
    /// optimum a search can reach); the calibration's GP stage turns it on.
    pub warm_start_rows: usize,
    /// With a warm-start subset, start the full-data search with the subset search's L-BFGS
    /// curvature pairs (gradient changes scaled by the ratio of the row counts) rather than an
    /// empty memory. Off by default: on the UR10 series C (1387 rows, position only, a 500-row
    /// subset, the GP stage's kernel) it cut the full-data evaluations 123 → 94 but the first
    /// output's search stopped on its function tolerance 35 nats below the optimum it reaches
    /// without (held out 0.1358 → 0.1381 mm).
    pub warm_start_curvature: bool,
    /// The relative function tolerance of a search that starts from an optimum found elsewhere:
    /// the full-data search after a warm-start subset, and a refinement from a fitted kernel
    /// ([`crate::ExactGp::refit`]). `None`: [`OptimiserConfig::function_tolerance`]. Such a
    /// search starts a few nats from its optimum and then gains a few hundredths of a nat per
    /// iteration for many iterations, each costing `n³` flops on every row.
    #[serde(default)]
    pub refine_function_tolerance: Option<f64>,
    /// At most this many iterations of a search that starts from an optimum found elsewhere (as
    /// [`OptimiserConfig::refine_function_tolerance`]); `Some(0)` keeps that optimum as it is.
    /// `None`: [`OptimiserConfig::max_iterations`]. A search stopped by this budget reports
    /// `converged: false`: it was not run to a tolerance, by choice. With `Some(0)` after a
    /// warm-start subset, the kernel is the subset's optimum and the report is that search's (no
    /// evaluation on all rows).
    #[serde(default)]
    pub refine_max_iterations: Option<usize>,
    /// Bytes of the kernel's exponentials an evaluation of the likelihood may keep from its value
    /// stage for its gradient stage, which otherwise computes every one of them again (the
    /// squared-exponential shapes: `d + 1` per entry of the lower triangle with an additive term
    /// on `d` inputs; 0 keeps none). The search's results are the same to the bit either way.
    #[serde(default = "default_kernel_cache_bytes")]
    pub kernel_cache_bytes: usize,
}

fn default_kernel_cache_bytes() -> usize {
    OptimiserConfig::default().kernel_cache_bytes
}

impl Default for OptimiserConfig {
    fn default() -> Self {
        Self {
            restarts: 3,
            seed: 0,
            max_iterations: 200,
            memory: 10,
            gradient_tolerance: 1e-5,
            // scipy's L-BFGS-B default factr = 1e7 times machine epsilon.
            function_tolerance: 1e7 * f64::EPSILON,
            warm_start_rows: 0,
            warm_start_curvature: false,
            refine_function_tolerance: None,
            refine_max_iterations: None,
            // 64 MiB: n = 1,387 rows with six additive inputs (UR10 C's even rows) need 54 MB,
            // small against the two n × n buffers and the GP's own data at that size; at a few
            // thousand rows the exponentials would be hundreds of MB, written and read again
            // once per evaluation, where recomputing them costs little beside the n³ factor.
            kernel_cache_bytes: 64 << 20,
        }
    }
}

/// Everything that decides an exact GP fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct GpConfig {
    /// Covariance family.
    pub kernel: KernelChoice,
    /// Search box in natural units for standardised inputs and normalised outputs; `None` takes
    /// [`crate::Kernel::default_bounds`].
    pub bounds: Option<Bounds>,
    /// One set of hyperparameters per output, or one shared.
    pub outputs: OutputMode,
    /// Subtract the mean and divide by the standard deviation of each input.
    pub standardise_inputs: bool,
    /// Subtract the mean and divide by the standard deviation of each output.
    pub normalise_outputs: bool,
    /// Hyperparameter search.
    pub optimiser: OptimiserConfig,
    /// Jitter escalation.
    pub jitter: JitterConfig,
    /// Serial or rayon.
    pub parallelism: Parallelism,
    /// With a kernel that has an additive term, also fit it without that term and keep, for each
    /// kernel (output or shared group), the smaller model unless the additive term raises the log
    /// marginal likelihood by more than the Schwarz (BIC) penalty `½ k ln N` for its `k = 2d`
    /// extra hyperparameters and `N` observed values. Off by default in the library; the
    /// calibration's GP stage turns it on (see `model::ResidualGpOptions`).
    pub additive_by_bic: bool,
    /// Also fit the paper's isotropic Eq. 5 kernel ([`crate::QuadraticKernel`]: one length scale,
    /// a constant and a linear term) for each kernel (output or shared group) and keep it where its
    /// closed-form leave-one-out log predictive probability (R&W Eq. 5.11) beats the searched
    /// kernel's: a criterion that sees a kernel with many length scales overfit a few hundred
    /// poses, which its marginal likelihood does not. With a warm-start subset the isotropic
    /// kernel is searched there, compared on all rows at the subset's optimum, and searched on
    /// all rows only when it wins there. Off by default in the library; the calibration's GP
    /// stage turns it on.
    #[serde(default)]
    pub isotropic_by_loo: bool,
    /// With [`OutputMode::Independent`]: groups of output columns that share one kernel (one
    /// search on the sum of their likelihoods, one factorisation) and are fitted after the other
    /// columns, each group's search started on all rows from whichever of the others' fitted
    /// kernels gives the group the highest likelihood, without subset, nested or random starts of
    /// its own (its kernel keeps that kernel's form, additive term or not). Where the group's
    /// outputs depend on the inputs much as the others do (the rotation error of a pose beside its
    /// position error) this costs one refinement instead of a full search per column. Columns in
    /// no group are fitted as usual; at least one must be. Empty by default; the calibration's GP
    /// stage makes the rotation outputs of full-pose data one group.
    #[serde(default)]
    pub follower_groups: Vec<Vec<usize>>,
}

impl Default for GpConfig {
    fn default() -> Self {
        Self {
            kernel: KernelChoice::default(),
            bounds: None,
            outputs: OutputMode::default(),
            standardise_inputs: true,
            normalise_outputs: true,
            optimiser: OptimiserConfig::default(),
            jitter: JitterConfig::default(),
            parallelism: Parallelism::default(),
            additive_by_bic: false,
            isotropic_by_loo: false,
            follower_groups: Vec::new(),
        }
    }
}

impl GpConfig {
    /// Refuses numbers that would make the fit meaningless (bounds are checked against the kernel
    /// when the fit starts).
    pub fn validate(&self) -> Result<(), Error> {
        let (o, j) = (&self.optimiser, &self.jitter);
        let refine = o.refine_function_tolerance.unwrap_or(o.function_tolerance);
        let (initial, at_least_0) = (j.initial_relative, "a number of at least 0");
        let checks: [(&'static str, f64, bool, &'static str); 6] = [
            ("optimiser.memory", o.memory as f64, o.memory >= 1, "at least 1"),
            ("optimiser.gradient_tolerance", o.gradient_tolerance, o.gradient_tolerance >= 0.0, at_least_0),
            ("optimiser.function_tolerance", o.function_tolerance, o.function_tolerance >= 0.0, at_least_0),
            ("optimiser.refine_function_tolerance", refine, refine >= 0.0, at_least_0),
            ("jitter.initial_relative", initial, initial > 0.0 && initial.is_finite(), "a finite number above 0"),
            ("jitter.growth", j.growth, j.growth > 1.0 && j.growth.is_finite(), "a finite number above 1"),
        ];
        let refused = checks.into_iter().find(|check| !check.2);
        refused.map_or(Ok(()), |(field, value, _, expected)| Err(Error::InvalidOption { field, value, expected }))
    }
}
