//! Sparse GP for training sets beyond a few thousand points: the variational (VFE, Titsias 2009)
//! / DTC approximation with `m` inducing inputs, `O(n m²)` instead of `O(n³)`.
//!
//! Hyperparameters come from an exact GP fitted on a random subset of the data (the "subset of
//! data" estimate); the inducing inputs are k-means centres or a random subset; the posterior then
//! uses every training point. Predictive equations are Quiñonero-Candela & Rasmussen (2005),
//! Eq. 20–21 (DTC, which is also VFE's predictive), in the numerically stable form
//! `A = L_uu⁻¹ K_uf / σ`, `B = I + A Aᵀ = L_B L_Bᵀ`:
//! `μ* = A*ᵀ B⁻¹ A y / σ`, `σ*² = k** − ‖A*‖² + ‖L_B⁻¹ A*‖²`, with `A* = L_uu⁻¹ K_u*`.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatRef};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::cholesky::{Factor, JitterOutcome};
use crate::config::{GpConfig, OutputMode, Parallelism};
use crate::exact::{ComponentReport, ExactGp, validate_training_data};
use crate::gram::{cross_covariance, full_covariance, prior_variances, training_covariance};
use crate::inducing::{InducingSelection, random_indices, select_inducing};
use crate::kernel::{Evaluator, Kernel, Prepared};
use crate::points::Points;
use crate::predict::{PredictOptions, Prediction};
use crate::scaling::{InputStandardiser, OutputNormaliser};

/// Configuration of the sparse approximation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SparseConfig {
    /// Kernel, outputs, scaling, optimiser, jitter and parallelism, as for the exact GP.
    pub gp: GpConfig,
    /// Number of inducing inputs `m`.
    pub inducing_points: usize,
    /// How they are chosen.
    pub selection: InducingSelection,
    /// Size of the random subset on which the hyperparameters are fitted by the exact GP.
    pub hyperparameter_subset: usize,
    /// Seed of the subset and of the inducing-point selection.
    pub seed: u64,
}

impl Default for SparseConfig {
    fn default() -> Self {
        Self {
            gp: GpConfig::default(),
            inducing_points: 300,
            selection: InducingSelection::default(),
            hyperparameter_subset: 600,
            seed: 0,
        }
    }
}

/// A sparse GP: training data, inducing inputs and per-kernel factors.
///
/// Serialises to its data, inducing inputs, scaling maps and report; the factors are rebuilt with
/// the recorded jitter when it is read back.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "StoredSparseGp", into = "StoredSparseGp")]
pub struct SparseGp {
    inputs: InputStandardiser,
    outputs: OutputNormaliser,
    x: Points,
    y: Mat<f64>,
    inducing: Points,
    components: Vec<SparseComponent>,
    parallelism: Parallelism,
    report: SparseFitReport,
}

/// Output columns, their kernel and (when fitted) the exact fit on the subset that found it.
type KernelGroup = (Vec<usize>, Kernel, Option<ComponentReport>);

#[derive(Debug, Clone)]
struct SparseComponent {
    kernel: Kernel,
    outputs: Vec<usize>,
    evaluator: Evaluator,
    /// Inducing inputs prepared for `evaluator`.
    inducing: Prepared,
    l_uu: Factor,
    l_b: Factor,
    /// `B⁻¹ A y / σ`, `m × k`: `μ* = A*ᵀ w`.
    w: Mat<f64>,
}

/// What the sparse fit did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SparseFitReport {
    /// Rows of the subset the hyperparameters were fitted on (0 when they were given).
    pub hyperparameter_subset: usize,
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
}

impl SparseGp {
    /// Fits hyperparameters on a subset with the exact GP, then the sparse posterior on all points.
    pub fn fit(x: MatRef<'_, f64>, y: MatRef<'_, f64>, config: &SparseConfig) -> Result<Self, Error> {
        Self::fit_impl(x, y, None, config)
    }

    /// The sparse posterior with given kernels (one for all outputs, or one per output).
    pub fn fit_fixed(
        x: MatRef<'_, f64>,
        y: MatRef<'_, f64>,
        kernels: &[Kernel],
        config: &SparseConfig,
    ) -> Result<Self, Error> {
        let valid = kernels.len() == 1 || (config.gp.outputs == OutputMode::Independent && kernels.len() == y.ncols());
        if !valid {
            return Err(Error::InvalidConfig { field: "kernels", value: kernels.len() as f64 });
        }
        Self::fit_impl(x, y, Some(kernels), config)
    }

    fn fit_impl(
        x: MatRef<'_, f64>,
        y: MatRef<'_, f64>,
        kernels: Option<&[Kernel]>,
        config: &SparseConfig,
    ) -> Result<Self, Error> {
        config.gp.validate()?;
        let raw = validate_training_data(x, y)?;
        let (n, m) = (y.nrows(), y.ncols());
        if config.inducing_points == 0 || config.inducing_points > n {
            return Err(Error::TooManyInducingPoints { requested: config.inducing_points, available: n });
        }
        let gp = &config.gp;
        let inputs =
            if gp.standardise_inputs { InputStandardiser::fit(&raw) } else { InputStandardiser::identity(x.ncols()) };
        let outputs = if gp.normalise_outputs { OutputNormaliser::fit(y) } else { OutputNormaliser::identity(m) };
        let xs = inputs.apply_points(&raw);
        let yn = outputs.normalise(y);
        // Hyperparameters: given, or the exact GP on a random subset (already scaled, so the
        // exact fit is told not to scale again).
        let (groups, subset_len): (Vec<KernelGroup>, usize) = match kernels {
            Some(ks) => {
                let cols: Vec<Vec<usize>> = match gp.outputs {
                    OutputMode::Independent => (0..m).map(|j| vec![j]).collect(),
                    OutputMode::Shared => vec![(0..m).collect()],
                };
                let groups = cols.into_iter().enumerate().map(|(g, c)| (c, ks[g.min(ks.len() - 1)].clone(), None));
                (groups.collect(), 0)
            }
            None => {
                let idx = random_indices(n, config.hyperparameter_subset.max(1), config.seed);
                let sub = xs.select(&idx);
                let xsub = Mat::from_fn(idx.len(), sub.dim(), |i, j| sub.row(i)[j]);
                let ysub = Mat::from_fn(idx.len(), m, |i, j| yn[(idx[i], j)]);
                let unscaled = GpConfig { standardise_inputs: false, normalise_outputs: false, ..gp.clone() };
                let exact = ExactGp::fit(xsub.as_ref(), ysub.as_ref(), &unscaled)?;
                let groups =
                    exact.report().components.iter().map(|c| (c.outputs.clone(), c.kernel.clone(), Some(c.clone())));
                (groups.collect(), idx.len())
            }
        };
        let inducing = select_inducing(&xs, config.inducing_points, config.selection, config.seed, gp.parallelism);
        let mut components = Vec::with_capacity(groups.len());
        let mut reports = Vec::with_capacity(groups.len());
        for (cols, kernel, subset_fit) in groups {
            kernel.validate(xs.dim())?;
            let yc = Mat::from_fn(n, cols.len(), |i, k| yn[(i, cols[k])]);
            let (component, jitter, elbo) =
                SparseComponent::build(kernel.clone(), cols.clone(), &xs, yc.as_ref(), &inducing, None, gp)?;
            components.push(component);
            reports.push(SparseComponentReport {
                outputs: cols,
                kernel,
                evidence_lower_bound: elbo,
                jitter,
                subset_fit,
            });
        }
        Ok(Self {
            inputs,
            outputs,
            x: xs,
            y: yn,
            inducing,
            components,
            parallelism: gp.parallelism,
            report: SparseFitReport { hyperparameter_subset: subset_len, components: reports },
        })
    }

    /// What the fit did.
    pub fn report(&self) -> &SparseFitReport {
        &self.report
    }

    /// Number of inducing inputs.
    pub fn inducing_len(&self) -> usize {
        self.inducing.len()
    }

    /// Sum of the evidence lower bounds of all kernels.
    pub fn evidence_lower_bound(&self) -> f64 {
        self.report.components.iter().map(|c| c.evidence_lower_bound).sum()
    }

    /// Posterior mean and variance (latent, no noise) at the rows of `x`.
    pub fn predict(&self, x: MatRef<'_, f64>) -> Result<Prediction, Error> {
        self.predict_with(x, &PredictOptions::default())
    }

    /// Posterior at the rows of `x` with the quantities `options` asks for.
    pub fn predict_with(&self, x: MatRef<'_, f64>, options: &PredictOptions) -> Result<Prediction, Error> {
        let z = self.inputs.apply(x)?;
        let par = self.parallelism.faer();
        let (ns, m) = (z.len(), self.y.ncols());
        let mut mean = Mat::zeros(ns, m);
        let mut variance = if options.variance { Mat::zeros(ns, m) } else { Mat::zeros(0, 0) };
        let mut covariance = if options.full_covariance { vec![Mat::zeros(0, 0); m] } else { Vec::new() };
        for c in &self.components {
            let (_, zp) = c.kernel.prepare(&z);
            // A* = L_uu⁻¹ K_u*, m × n*.
            let mut a = cross_covariance(&c.evaluator, &c.inducing, &zp, self.parallelism);
            c.l_uu.solve_lower_in_place(a.as_mut(), par);
            let mut f = Mat::zeros(ns, c.outputs.len());
            matmul(f.as_mut(), Accum::Replace, a.transpose(), c.w.as_ref(), 1.0, par);
            let noise = if options.include_noise { c.kernel.noise_variance() } else { 0.0 };
            let mut b = Mat::zeros(0, 0);
            if options.variance || options.full_covariance {
                b = a.clone();
                c.l_b.solve_lower_in_place(b.as_mut(), par);
            }
            let latent_variance: Vec<f64> = if options.variance {
                let prior = prior_variances(&c.evaluator, &zp);
                (0..ns)
                    .map(|j| {
                        let qa: f64 = a.col(j).iter().map(|v| v * v).sum();
                        let qb: f64 = b.col(j).iter().map(|v| v * v).sum();
                        (prior[j] - qa + qb).max(0.0) + noise
                    })
                    .collect()
            } else {
                Vec::new()
            };
            let latent_covariance = options.full_covariance.then(|| {
                let mut cov = full_covariance(&c.evaluator, &zp, self.parallelism);
                matmul(cov.as_mut(), Accum::Add, a.transpose(), a.as_ref(), -1.0, par);
                matmul(cov.as_mut(), Accum::Add, b.transpose(), b.as_ref(), 1.0, par);
                for i in 0..ns {
                    cov[(i, i)] += noise;
                }
                cov
            });
            for (k, &out) in c.outputs.iter().enumerate() {
                let (mu, s) = (self.outputs.mean[out], self.outputs.scale[out]);
                for i in 0..ns {
                    mean[(i, out)] = f[(i, k)] * s + mu;
                }
                for (i, v) in latent_variance.iter().enumerate() {
                    variance[(i, out)] = v * s * s;
                }
                if let Some(cov) = &latent_covariance {
                    covariance[out] = Mat::from_fn(ns, ns, |i, j| cov[(i, j)] * s * s);
                }
            }
        }
        Ok(Prediction { mean, variance, covariance })
    }
}

impl SparseComponent {
    /// Factors `K_uu` (with jitter escalation, or exactly `fixed_jitter`) and `B`, and returns the
    /// component, the jitter and Titsias' bound.
    fn build(
        kernel: Kernel,
        outputs: Vec<usize>,
        x: &Points,
        y: MatRef<'_, f64>,
        inducing: &Points,
        fixed_jitter: Option<f64>,
        config: &GpConfig,
    ) -> Result<(Self, JitterOutcome, f64), Error> {
        let parallelism = config.parallelism;
        let par = parallelism.faer();
        let (evaluator, xp) = kernel.prepare(x);
        let (_, zp) = kernel.prepare(inducing);
        let (n, mu) = (x.len(), inducing.len());
        let kuu = training_covariance(&evaluator, &zp, 0.0, parallelism);
        let (l_uu, jitter) = match fixed_jitter {
            None => Factor::with_jitter(&kuu, &config.jitter, par)?,
            Some(j) => (Factor::with_fixed_jitter(&kuu, j, par)?, JitterOutcome { added: j, failed_attempts: 0 }),
        };
        let noise = kernel.noise_variance();
        let sigma = noise.sqrt();
        // A = L_uu⁻¹ K_uf / σ.
        let mut a = cross_covariance(&evaluator, &zp, &xp, parallelism);
        l_uu.solve_lower_in_place(a.as_mut(), par);
        for j in 0..n {
            for i in 0..mu {
                a[(i, j)] /= sigma;
            }
        }
        let mut b = Mat::<f64>::identity(mu, mu);
        matmul(b.as_mut(), Accum::Add, a.as_ref(), a.transpose(), 1.0, par);
        // B ⪰ I, so this factorisation only fails on non-finite input.
        let (l_b, _) = Factor::with_jitter(&b, &config.jitter, par)?;
        let mut ay = Mat::zeros(mu, y.ncols());
        matmul(ay.as_mut(), Accum::Replace, a.as_ref(), y, 1.0 / sigma, par);
        let mut c = ay.clone();
        l_b.solve_lower_in_place(c.as_mut(), par);
        let mut w = ay;
        l_b.solve_in_place(w.as_mut(), par);
        // Titsias (2009) Eq. 9 per output column: ln N(y | 0, Q + σ²I) − tr(K − Q) / (2σ²), with
        // ln|Q + σ²I| = n ln σ² + ln|B|, yᵀ(Q + σ²I)⁻¹y = yᵀy/σ² − ‖c‖², tr Q = σ² ‖A‖²_F.
        let trace_k: f64 = prior_variances(&evaluator, &xp).iter().sum();
        let trace_q = noise * (0..n).map(|j| a.col(j).iter().map(|v| v * v).sum::<f64>()).sum::<f64>();
        let log_det_b = l_b.log_determinant();
        let mut elbo = 0.0;
        for k in 0..y.ncols() {
            let yy: f64 = (0..n).map(|i| y[(i, k)] * y[(i, k)]).sum();
            let cc: f64 = c.col(k).iter().map(|v| v * v).sum();
            elbo += -0.5 * n as f64 * (2.0 * std::f64::consts::PI * noise).ln()
                - 0.5 * log_det_b
                - 0.5 * (yy / noise - cc)
                - (trace_k - trace_q) / (2.0 * noise);
        }
        Ok((Self { kernel, outputs, evaluator, inducing: zp, l_uu, l_b, w }, jitter, elbo))
    }
}

/// The serialised form: data, inducing inputs, maps and report.
#[derive(Serialize, Deserialize)]
struct StoredSparseGp {
    inputs: InputStandardiser,
    outputs: OutputNormaliser,
    training_inputs: Vec<Vec<f64>>,
    training_outputs: Vec<Vec<f64>>,
    inducing_inputs: Vec<Vec<f64>>,
    parallelism: Parallelism,
    report: SparseFitReport,
}

fn rows(p: &Points) -> Vec<Vec<f64>> {
    (0..p.len()).map(|i| p.row(i).to_vec()).collect()
}

impl From<SparseGp> for StoredSparseGp {
    fn from(gp: SparseGp) -> Self {
        let training_outputs = (0..gp.y.nrows()).map(|i| (0..gp.y.ncols()).map(|j| gp.y[(i, j)]).collect()).collect();
        Self {
            training_inputs: rows(&gp.x),
            inducing_inputs: rows(&gp.inducing),
            inputs: gp.inputs,
            outputs: gp.outputs,
            training_outputs,
            parallelism: gp.parallelism,
            report: gp.report,
        }
    }
}

impl TryFrom<StoredSparseGp> for SparseGp {
    type Error = Error;

    fn try_from(s: StoredSparseGp) -> Result<Self, Error> {
        let (n, d, m) = (s.training_inputs.len(), s.inputs.mean.len(), s.outputs.mean.len());
        if s.training_outputs.len() != n {
            return Err(Error::RowCountMismatch { input_rows: n, output_rows: s.training_outputs.len() });
        }
        let x = Mat::from_fn(n, d, |i, j| s.training_inputs[i].get(j).copied().unwrap_or(f64::NAN));
        let y = Mat::from_fn(n, m, |i, j| s.training_outputs[i].get(j).copied().unwrap_or(f64::NAN));
        let nu = s.inducing_inputs.len();
        let zm = Mat::from_fn(nu, d, |i, j| s.inducing_inputs[i].get(j).copied().unwrap_or(f64::NAN));
        s.inputs.check(d)?;
        s.outputs.check(m)?;
        let points = validate_training_data(x.as_ref(), y.as_ref())?;
        let inducing = Points::from_rows(zm.as_ref())?;
        if nu == 0 || nu > n {
            return Err(Error::TooManyInducingPoints { requested: nu, available: n });
        }
        let mut served = vec![0usize; m];
        for c in &s.report.components {
            for &j in &c.outputs {
                if j >= m {
                    return Err(Error::InputDimensionMismatch { expected: m, found: j + 1 });
                }
                served[j] += 1;
            }
        }
        if let Some(j) = served.iter().position(|&k| k != 1) {
            return Err(Error::InvalidConfig { field: "report.components.outputs", value: j as f64 });
        }
        let config = GpConfig { parallelism: s.parallelism, ..GpConfig::default() };
        let mut components = Vec::with_capacity(s.report.components.len());
        for c in &s.report.components {
            c.kernel.validate(d)?;
            let yc = Mat::from_fn(n, c.outputs.len(), |i, k| y[(i, c.outputs[k])]);
            let (component, _, _) = SparseComponent::build(
                c.kernel.clone(),
                c.outputs.clone(),
                &points,
                yc.as_ref(),
                &inducing,
                Some(c.jitter.added),
                &config,
            )?;
            components.push(component);
        }
        Ok(Self {
            inputs: s.inputs,
            outputs: s.outputs,
            x: points,
            y,
            inducing,
            components,
            parallelism: s.parallelism,
            report: s.report,
        })
    }
}
