//! Sparse GP for training sets beyond a few thousand points: the variational approximation (VFE,
//! Titsias 2009) with `m` inducing inputs, `O(n m²)` time and `O(m² + chunk·m)` memory besides the
//! data, instead of `O(n³)` and `O(n²)`.
//!
//! The fit: hyperparameters first from the exact GP on a random subset of the rows (the "subset of
//! data" estimate, [`SparseConfig::hyperparameter_subset`]), inducing inputs by k-means on all the
//! rows, then the hyperparameters refined by maximising Titsias' bound ([`crate::elbo`]) with its
//! analytic gradient on [`SparseConfig::bound_rows`] rows, and the posterior on every row.
//! Prediction (Quiñonero-Candela & Rasmussen 2005, Eq. 20–21, VFE's predictive), with
//! `A* = L_uu⁻¹ K_u*`: `μ* = A*ᵀ w`, `σ*² = k** − ‖A*‖² + ‖L_B⁻¹ A*‖²`.
//!
//! The stored model is the posterior itself (inducing inputs, `w` and `L_B`), not the training
//! data: a model fitted on 100,000 poses reads back in milliseconds.

use dense::product;
use faer::{Accum, Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::elbo::{CHUNK_ROWS, Posterior, evidence_lower_bound};
use crate::inducing::{InducingSelection, select_inducing};
use gp::blocks::{
    Factor, Points, check_served, cross_covariance, full_covariance, prior_variances, random_indices,
    training_covariance, validate_training_data,
};
use gp::{
    ComponentReport, ExactGp, GpConfig, InputStandardiser, JitterOutcome, Kernel, OutputMode, OutputNormaliser,
    Parallelism, PredictOptions, Prediction,
};
use lbfgsb::{Objective, Settings, Termination};

/// Configuration of the sparse approximation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SparseConfig {
    /// Kernel, outputs, scaling, optimiser (of the subset's exact fit), jitter and parallelism.
    pub gp: GpConfig,
    /// Number of inducing inputs `m` (at most the number of rows).
    pub inducing_points: usize,
    /// How they are chosen.
    pub selection: InducingSelection,
    /// Rows of the random subset on which the exact GP gives the first hyperparameters.
    pub hyperparameter_subset: usize,
    /// Rows of the random subset on which the bound is maximised from there (0: keep the
    /// subset's hyperparameters).
    pub bound_rows: usize,
    /// L-BFGS iterations on the bound.
    pub bound_iterations: usize,
    /// Seed of the subsets and of the inducing-point selection.
    pub seed: u64,
}

impl Default for SparseConfig {
    fn default() -> Self {
        Self {
            gp: GpConfig::default(),
            inducing_points: 500,
            selection: InducingSelection::default(),
            // The exact GP's evaluation on 1000 rows costs 1 GFLOP, the bound's on 2000 rows with
            // 500 inducing inputs 2 GFLOP: both searches take seconds, whatever n is.
            hyperparameter_subset: 1000,
            bound_rows: 2000,
            bound_iterations: 40,
            seed: 0,
        }
    }
}

impl SparseConfig {
    /// Refuses numbers that would make the fit meaningless.
    pub fn validate(&self) -> Result<(), Error> {
        self.gp.validate()?;
        let (points, subset) = (self.inducing_points, self.hyperparameter_subset);
        let checks = [("inducing_points", points, 1, "at least 1"), ("hyperparameter_subset", subset, 2, "at least 2")];
        let refused = checks.into_iter().find(|&(_, value, least, _)| value < least);
        refused.map_or(Ok(()), |(field, n, _, expected)| {
            Err(gp::Error::InvalidOption { field, value: n as f64, expected }.into())
        })
    }
}

/// A sparse GP: inducing inputs and, per kernel, the posterior.
///
/// Serialises to the inducing inputs, the scaling maps, the report and each posterior's `w` and
/// `L_B`; `L_uu` is rebuilt with the recorded jitter when it is read back.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "StoredSparseGp", into = "StoredSparseGp")]
pub struct SparseGp {
    inputs: InputStandardiser,
    outputs: OutputNormaliser,
    inducing: Points,
    components: Vec<SparseComponent>,
    parallelism: Parallelism,
    report: SparseFitReport,
}

#[derive(Debug, Clone)]
struct SparseComponent {
    kernel: Kernel,
    outputs: Vec<usize>,
    posterior: Posterior,
}

/// What the sparse fit did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SparseFitReport {
    /// Rows the model was fitted on.
    pub rows: usize,
    /// Rows of the subset the first hyperparameters were fitted on (0 when they were given).
    pub hyperparameter_subset: usize,
    /// Rows on which the bound was maximised (0 when it was not).
    pub bound_rows: usize,
    /// One entry per kernel.
    pub components: Vec<SparseComponentReport>,
}

/// The sparse fit of one kernel.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SparseComponentReport {
    /// Output columns this kernel models.
    pub outputs: Vec<usize>,
    /// Hyperparameters (standardised inputs, normalised outputs).
    pub kernel: Kernel,
    /// Titsias' collapsed lower bound on the log marginal likelihood of all `n` normalised
    /// outputs it serves, summed over them.
    pub evidence_lower_bound: f64,
    /// Jitter added to factor `K_uu`.
    pub jitter: JitterOutcome,
    /// The exact fit on the subset (`None` when the hyperparameters were given).
    pub subset_fit: Option<ComponentReport>,
    /// L-BFGS iterations on the bound (0 when it was not maximised).
    pub bound_iterations: usize,
    /// Whether the bound's search stopped on a tolerance (`false` also when it was not run).
    pub bound_converged: bool,
}

/// The negative bound in log-parameters (value and gradient come together: the gradient costs
/// about as much again as the value, and a rejected trial is rare on this smooth objective).
struct NegativeBound<'a> {
    start: &'a Kernel,
    x: &'a Points,
    y: MatRef<'a, f64>,
    z: &'a Points,
    config: &'a GpConfig,
    gradient: Option<Vec<f64>>,
}

impl Objective for NegativeBound<'_> {
    fn value(&mut self, p: &[f64]) -> Option<f64> {
        let kernel = self.start.with_log_parameters(p).ok()?;
        let jitter = (&self.config.jitter, None);
        let (posterior, g) =
            evidence_lower_bound(&kernel, self.x, self.y, self.z, jitter, true, self.config.parallelism).ok()?;
        self.gradient = Some(g.iter().map(|v| -v).collect());
        Some(-posterior.bound)
    }
    fn gradient(&mut self) -> Option<Vec<f64>> {
        self.gradient.take()
    }
}

/// Maximises the bound on `x, y` from `start`; returns the kernel, iterations and convergence.
fn maximise_bound(
    start: &Kernel,
    x: &Points,
    y: MatRef<'_, f64>,
    z: &Points,
    config: &SparseConfig,
) -> Result<(Kernel, usize, bool), Error> {
    let gp = &config.gp;
    let bounds = gp.bounds.clone().unwrap_or_else(|| start.default_bounds());
    let (lower, upper) = bounds.to_log(start)?;
    let settings = Settings {
        memory: gp.optimiser.memory,
        max_iterations: config.bound_iterations,
        gradient_tolerance: gp.optimiser.gradient_tolerance,
        function_tolerance: gp.optimiser.function_tolerance,
    };
    let mut objective = NegativeBound { start, x, y, z, config: gp, gradient: None };
    let minimum = lbfgsb::minimise(&mut objective, &start.log_parameters(), &lower, &upper, &settings)
        .ok_or(gp::Error::OptimisationFailed { starts: 1 })?;
    let converged = matches!(minimum.termination, Termination::GradientTolerance | Termination::FunctionTolerance);
    Ok((start.with_log_parameters(&minimum.x)?, minimum.iterations, converged))
}

fn select_rows(x: &Points, y: MatRef<'_, f64>, count: usize, seed: u64) -> (Points, Mat<f64>) {
    let idx = random_indices(x.len(), count, seed);
    (x.select(&idx), Mat::from_fn(idx.len(), y.ncols(), |i, j| y[(idx[i], j)]))
}

impl SparseGp {
    /// Fits hyperparameters (exact GP on a subset, then the bound), inducing inputs and the
    /// posterior on all points.
    pub fn fit(x: MatRef<'_, f64>, y: MatRef<'_, f64>, config: &SparseConfig) -> Result<Self, Error> {
        Self::fit_impl(x, y, None, config)
    }

    /// The sparse posterior with given kernels (one for all outputs, or one per output), no search.
    pub fn fit_fixed(
        x: MatRef<'_, f64>,
        y: MatRef<'_, f64>,
        kernels: &[Kernel],
        config: &SparseConfig,
    ) -> Result<Self, Error> {
        let valid = kernels.len() == 1 || (config.gp.outputs == OutputMode::Independent && kernels.len() == y.ncols());
        if !valid {
            return Err(gp::Error::InvalidConfig { field: "kernels", value: kernels.len() as f64 }.into());
        }
        Self::fit_impl(x, y, Some(kernels), config)
    }

    fn fit_impl(
        x: MatRef<'_, f64>,
        y: MatRef<'_, f64>,
        kernels: Option<&[Kernel]>,
        config: &SparseConfig,
    ) -> Result<Self, Error> {
        config.validate()?;
        let raw = validate_training_data(x, y)?;
        let (n, m) = (y.nrows(), y.ncols());
        if config.inducing_points > n {
            return Err(Error::TooManyInducingPoints { requested: config.inducing_points, available: n });
        }
        let gp = &config.gp;
        let inputs =
            if gp.standardise_inputs { InputStandardiser::fit(&raw) } else { InputStandardiser::identity(x.ncols()) };
        let outputs = if gp.normalise_outputs { OutputNormaliser::fit(y) } else { OutputNormaliser::identity(m) };
        let xs = inputs.apply_points(&raw);
        let yn = outputs.normalise(y);
        let groups: Vec<Vec<usize>> = match gp.outputs {
            OutputMode::Independent => (0..m).map(|j| vec![j]).collect(),
            OutputMode::Shared => vec![(0..m).collect()],
        };
        // First hyperparameters: given, or the exact GP on a random subset (already scaled, so the
        // exact fit is told not to scale again).
        let (starts, subset_len): (Vec<(Kernel, Option<ComponentReport>)>, usize) = match kernels {
            Some(ks) => ((0..groups.len()).map(|g| (ks[g.min(ks.len() - 1)].clone(), None)).collect(), 0),
            None => {
                let (sx, sy) = select_rows(&xs, yn.as_ref(), config.hyperparameter_subset, config.seed);
                let xsub = Mat::from_fn(sx.len(), sx.dim(), |i, j| sx.row(i)[j]);
                let unscaled = GpConfig { standardise_inputs: false, normalise_outputs: false, ..gp.clone() };
                let exact = ExactGp::fit(xsub.as_ref(), sy.as_ref(), &unscaled)?;
                let reports = exact.report().components.iter().map(|c| (c.kernel.clone(), Some(c.clone())));
                (reports.collect(), sx.len())
            }
        };
        let inducing = select_inducing(&xs, config.inducing_points, config.selection, config.seed, gp.parallelism);
        let refine = kernels.is_none() && config.bound_rows > 0;
        let (bx, by) = if refine && config.bound_rows < n {
            select_rows(&xs, yn.as_ref(), config.bound_rows, config.seed.wrapping_add(1))
        } else {
            (xs.clone(), yn.clone())
        };
        let mut components = Vec::with_capacity(groups.len());
        let mut reports = Vec::with_capacity(groups.len());
        for (cols, (start, subset_fit)) in groups.into_iter().zip(starts) {
            start.validate(xs.dim())?;
            let (kernel, iterations, converged) = if refine {
                let yc = Mat::from_fn(by.nrows(), cols.len(), |i, k| by[(i, cols[k])]);
                maximise_bound(&start, &bx, yc.as_ref(), &inducing, config)?
            } else {
                (start, 0, false)
            };
            let yc = Mat::from_fn(n, cols.len(), |i, k| yn[(i, cols[k])]);
            let (posterior, _) =
                evidence_lower_bound(&kernel, &xs, yc.as_ref(), &inducing, (&gp.jitter, None), false, gp.parallelism)?;
            reports.push(SparseComponentReport {
                outputs: cols.clone(),
                kernel: kernel.clone(),
                evidence_lower_bound: posterior.bound,
                jitter: posterior.jitter,
                subset_fit,
                bound_iterations: iterations,
                bound_converged: converged,
            });
            components.push(SparseComponent { kernel, outputs: cols, posterior });
        }
        let bound_rows = if refine { bx.len() } else { 0 };
        Ok(Self {
            inputs,
            outputs,
            inducing,
            components,
            parallelism: gp.parallelism,
            report: SparseFitReport { rows: n, hyperparameter_subset: subset_len, bound_rows, components: reports },
        })
    }

    /// What the fit did.
    pub fn report(&self) -> &SparseFitReport {
        &self.report
    }

    /// The input standardisation (the training inputs' mean and standard deviation).
    pub fn input_standardiser(&self) -> &InputStandardiser {
        &self.inputs
    }

    /// Number of inducing inputs.
    pub fn inducing_len(&self) -> usize {
        self.inducing.len()
    }

    /// Number of inputs `d`.
    pub fn input_dim(&self) -> usize {
        self.inducing.dim()
    }

    /// Number of outputs.
    pub fn output_count(&self) -> usize {
        self.outputs.mean.len()
    }

    /// Sum of the evidence lower bounds of all kernels.
    pub fn evidence_lower_bound(&self) -> f64 {
        self.report.components.iter().map(|c| c.evidence_lower_bound).sum()
    }

    /// Posterior mean and variance (latent, no noise) at the rows of `x`.
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Prediction, gp::Error> {
        self.predict_with(x, &PredictOptions::default())
    }

    /// Posterior at the rows of `x` with the quantities `options` asks for; the rows are taken in
    /// chunks, so memory stays `O(chunk · m)` besides the result.
    pub fn predict_with(&self, x: MatRef<'_, f64>, options: &PredictOptions) -> Result<Prediction, gp::Error> {
        let z = self.inputs.apply(x)?;
        let par = self.parallelism.faer();
        let (ns, m) = (z.len(), self.output_count());
        let mut mean = Mat::zeros(ns, m);
        let mut variance = if options.variance { Mat::zeros(ns, m) } else { Mat::zeros(0, 0) };
        let mut prior_variance = variance.clone();
        let mut covariance = if options.full_covariance { vec![Mat::zeros(0, 0); m] } else { Vec::new() };
        for c in &self.components {
            let post = &c.posterior;
            let (_, zp_all) = c.kernel.prepare(&z);
            let noise = if options.include_noise { c.kernel.noise_variance() } else { 0.0 };
            // The full covariance couples every query: one block; otherwise chunks of rows.
            let step = if options.full_covariance { ns.max(1) } else { CHUNK_ROWS };
            let ranges: Vec<std::ops::Range<usize>> = (0..ns).step_by(step).map(|s| s..(s + step).min(ns)).collect();
            for r in ranges {
                let zp = zp_all.rows(r.clone());
                let nc = r.len();
                // A* = L_uu⁻¹ K_u*, m × n*.
                let mut a = cross_covariance(&post.evaluator, &post.inducing, &zp, self.parallelism);
                post.l_uu.solve_lower_in_place(a.as_mut(), par);
                let mut f = Mat::zeros(nc, c.outputs.len());
                product(f.as_mut(), Accum::Replace, a.transpose(), post.w.as_ref(), 1.0, par);
                let mut b = Mat::zeros(0, 0);
                if options.variance || options.full_covariance {
                    b = a.clone();
                    post.l_b.solve_lower_in_place(b.as_mut(), par);
                }
                let prior = if options.variance { prior_variances(&post.evaluator, &zp) } else { Vec::new() };
                let latent_variance: Vec<f64> = (0..prior.len())
                    .map(|j| {
                        let qa: f64 = a.col(j).iter().map(|v| v * v).sum();
                        let qb: f64 = b.col(j).iter().map(|v| v * v).sum();
                        (prior[j] - qa + qb).max(0.0) + noise
                    })
                    .collect();
                let latent_covariance = options.full_covariance.then(|| {
                    let mut cov = full_covariance(&post.evaluator, &zp, self.parallelism);
                    product(cov.as_mut(), Accum::Add, a.transpose(), a.as_ref(), -1.0, par);
                    product(cov.as_mut(), Accum::Add, b.transpose(), b.as_ref(), 1.0, par);
                    for i in 0..nc {
                        cov[(i, i)] += noise;
                    }
                    cov
                });
                for (k, &out) in c.outputs.iter().enumerate() {
                    let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                    for i in 0..nc {
                        mean[(r.start + i, out)] = f[(i, k)] * s + mu;
                    }
                    for (i, (v, p)) in latent_variance.iter().zip(&prior).enumerate() {
                        variance[(r.start + i, out)] = v * s * s;
                        prior_variance[(r.start + i, out)] = p * s * s;
                    }
                    if let Some(cov) = &latent_covariance {
                        covariance[out] = Mat::from_fn(nc, nc, |i, j| cov[(i, j)] * s * s);
                    }
                }
            }
        }
        Ok(Prediction { mean, variance, covariance, prior_variance })
    }
}

/// The serialised form: inducing inputs, maps, report, and per kernel `w` and `L_B`.
#[derive(Serialize, Deserialize)]
struct StoredSparseGp {
    inputs: InputStandardiser,
    outputs: OutputNormaliser,
    /// Standardised inducing inputs, one row per point.
    inducing_inputs: Vec<Vec<f64>>,
    parallelism: Parallelism,
    report: SparseFitReport,
    /// Per kernel, in the report's order.
    posteriors: Vec<StoredPosterior>,
}

#[derive(Serialize, Deserialize)]
struct StoredPosterior {
    /// `w`, one row per inducing input.
    w: Vec<Vec<f64>>,
    /// Lower triangle of `L_B`, row `i` holding `i + 1` entries.
    l_b: Vec<Vec<f64>>,
}

impl From<SparseGp> for StoredSparseGp {
    fn from(gp: SparseGp) -> Self {
        let posteriors = gp
            .components
            .iter()
            .map(|c| {
                let (w, l) = (&c.posterior.w, c.posterior.l_b.lower());
                StoredPosterior {
                    w: (0..w.nrows()).map(|i| (0..w.ncols()).map(|j| w[(i, j)]).collect()).collect(),
                    l_b: (0..l.nrows()).map(|i| (0..=i).map(|j| l[(i, j)]).collect()).collect(),
                }
            })
            .collect();
        Self {
            inducing_inputs: (0..gp.inducing.len()).map(|i| gp.inducing.row(i).to_vec()).collect(),
            inputs: gp.inputs,
            outputs: gp.outputs,
            parallelism: gp.parallelism,
            report: gp.report,
            posteriors,
        }
    }
}

impl TryFrom<StoredSparseGp> for SparseGp {
    type Error = gp::Error;

    fn try_from(s: StoredSparseGp) -> Result<Self, gp::Error> {
        let (d, m) = (s.inputs.mean.len(), s.outputs.mean.len());
        s.inputs.check(d)?;
        s.outputs.check(m)?;
        let nu = s.inducing_inputs.len();
        if nu == 0 {
            return Err(gp::Error::TooFewPoints { rows: 0, required: 1 });
        }
        if let Some(row) = s.inducing_inputs.iter().find(|r| r.len() != d) {
            return Err(gp::Error::InputDimensionMismatch { expected: d, found: row.len() });
        }
        let zm = Mat::from_fn(nu, d, |i, j| s.inducing_inputs[i][j]);
        let inducing = Points::from_rows(zm.as_ref())?;
        check_served(s.report.components.iter().map(|c| &c.outputs), m)?;
        if s.posteriors.len() != s.report.components.len() {
            return Err(gp::Error::InvalidConfig { field: "posteriors", value: s.posteriors.len() as f64 });
        }
        let par = s.parallelism.faer();
        let mut components = Vec::with_capacity(s.posteriors.len());
        for (c, stored) in s.report.components.iter().zip(&s.posteriors) {
            c.kernel.validate(d)?;
            let k = c.outputs.len();
            let w_ok = stored.w.len() == nu && stored.w.iter().all(|r| r.len() == k && r.iter().all(|v| v.is_finite()));
            if !w_ok {
                return Err(gp::Error::InvalidConfig { field: "posteriors.w", value: stored.w.len() as f64 });
            }
            let l_ok = stored.l_b.len() == nu && stored.l_b.iter().enumerate().all(|(i, r)| r.len() == i + 1);
            if !l_ok {
                return Err(gp::Error::InvalidConfig { field: "posteriors.l_b", value: stored.l_b.len() as f64 });
            }
            let l = Mat::from_fn(nu, nu, |i, j| if j <= i { stored.l_b[i][j] } else { 0.0 });
            let l_b = Factor::from_lower(l).map_err(|pivot| gp::Error::CholeskyFailed {
                size: nu,
                pivot,
                jitter_tried: 0.0,
            })?;
            let w = Mat::from_fn(nu, k, |i, j| stored.w[i][j]);
            let (evaluator, zp) = c.kernel.prepare(&inducing);
            let kuu = training_covariance(&evaluator, &zp, 0.0, s.parallelism);
            let l_uu = Factor::with_fixed_jitter(&kuu, c.jitter.added, par)?;
            let posterior =
                Posterior { evaluator, inducing: zp, l_uu, jitter: c.jitter, l_b, w, bound: c.evidence_lower_bound };
            components.push(SparseComponent { kernel: c.kernel.clone(), outputs: c.outputs.clone(), posterior });
        }
        Ok(Self {
            inputs: s.inputs,
            outputs: s.outputs,
            inducing,
            components,
            parallelism: s.parallelism,
            report: s.report,
        })
    }
}
