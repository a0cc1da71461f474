//! Step 2 of the paper (Section III-B): a Gaussian process on the pose error the geometric model
//! leaves, with the joint values (and the payload) as inputs, placed before the POE model
//! (Eq. 9): `T = G(q, m) · T_POE(q)`.

use errors::Error;
use faer::Mat;
use lie::{SE3, Twist, Vector3, Vector6};
use measurements::{BoundSet, Measurement, MeasurementSet};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::str::FromStr;

/// Where the error twist of Eq. 8 is expressed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ResidualFrame {
    /// At the tool point: `ε = log(P⁻¹ T' T⁻¹ P)^∨` with `P` the translation to the modelled tool
    /// point, and `G = P exp(ĝ) P⁻¹`. The same twist as Eq. 8 seen from the tool, so that its `v`
    /// part is the position error and does not carry the orientation error times the lever arm
    /// to the tracker (metres): each GP output then sees one physical error.
    #[default]
    ToolPoint,
    /// In the tracker frame, exactly the paper's Eq. 8: `ε = log(T' T⁻¹)^∨`, `G = exp(ĝ)`.
    Tracker,
}

/// Which Gaussian process the GP stage fits (`calib fit --gp`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum GpChoice {
    /// The exact GP: `O(n³)` time, `O(n²)` memory.
    Exact,
    /// The sparse variational GP (VFE) with inducing inputs: `O(n m²)` time, `O(n m)` memory.
    Sparse,
    /// Exact up to [`ResidualGpOptions::sparse_above_rows`] training rows, sparse beyond.
    #[default]
    Auto,
}

impl GpChoice {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Self::Exact => "exact",
            Self::Sparse => "sparse",
            Self::Auto => "auto",
        }
    }
}

impl fmt::Display for GpChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A `--gp` value that is not `exact`, `sparse` or `auto`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownGpChoice {
    /// The name given.
    pub name: String,
}

impl fmt::Display for UnknownGpChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown GP '{}': expected one of exact, sparse, auto", self.name)
    }
}

impl std::error::Error for UnknownGpChoice {}

impl FromStr for GpChoice {
    type Err = UnknownGpChoice;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        [Self::Exact, Self::Sparse, Self::Auto]
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| UnknownGpChoice { name: s.to_owned() })
    }
}

/// Options of the GP stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct ResidualGpOptions {
    /// The exact Gaussian process (and the kernel, outputs, scaling and optimiser of both). Read
    /// from an options file field by field onto this stage's default, so that `gp: (optimiser:
    /// (max_iterations: 100))` changes that one field and keeps the stage's kernel and search.
    #[serde(deserialize_with = "onto_default_gp")]
    pub gp: gp::GpConfig,
    /// Exact, sparse, or chosen by the number of training rows.
    pub method: GpChoice,
    /// With [`GpChoice::Auto`], the sparse GP above this many training rows.
    pub sparse_above_rows: usize,
    /// The sparse GP (its `gp` field is replaced by [`ResidualGpOptions::gp`], but for the
    /// outputs and the kernel, which [`ResidualGpOptions::sparse_outputs`] and
    /// [`ResidualGpOptions::sparse_kernel`] set).
    pub sparse: gp_sparse::SparseConfig,
    /// One kernel for all outputs or one each, in the sparse GP.
    pub sparse_outputs: gp::OutputMode,
    /// The covariance family of the sparse GP.
    pub sparse_kernel: gp::KernelChoice,
    /// Where the error twist is expressed.
    pub residual_frame: ResidualFrame,
    /// For full-pose data, the three rotation outputs share one kernel, searched once on all rows
    /// from the position output kernel that explains them best ([`gp::GpConfig::follower_groups`]),
    /// instead of three searches of their own; the position outputs are fitted as `gp` says.
    pub rotation_follows_position: bool,
    /// Where the GP knows little of a row, its correction fades out and the model falls back to
    /// the geometry: with `s` the share of the GP's prior variance of the position
    /// outputs that its posterior keeps at the row, measured from what it keeps at its training
    /// rows ([`GpFadeRule`]: 0 at a typical training row, 1 where the training rows say nothing
    /// of it), the correction applies in full while `s` is at most this value and fades linearly
    /// to none at `s = 1`. `None`: never fades (the GP's posterior mean everywhere, as before).
    /// Within `[0, 1)`.
    pub fade_above_variance_ratio: Option<f64>,
    /// The sparse GP's training share of the fade ([`GpFadeRule::training_share`]) is the median
    /// over at most this many of its training rows, every k-th in the file's order: the
    /// posterior variance at a row costs two `m × m` triangular solves, so at 100,000 rows the
    /// median of all of them took longer than the sparse GP's own search. The exact GP's comes
    /// from its leave-one-out over every row, which the fit computes anyway. At least 1.
    pub fade_share_rows: usize,
    /// Measured signals taken as inputs beside the joints and the payload (`calib fit --inputs`):
    /// columns of the measurement file by name (after `--columns`), in this order. The
    /// GP standardises every input, so each is used in the unit it was measured in.
    pub inputs: Vec<String>,
    /// The fallback GP's ([`ResidualGp::fallback`]) full-data searches after its warm-start
    /// subset take at most this many iterations ([`gp::OptimiserConfig::refine_max_iterations`];
    /// `None`: as the GP's own). The fallback serves only the rows an effect's span fades to the
    /// geometry alone, where the hyperparameters' last few nats on all rows change little.
    pub fallback_refine_iterations: Option<usize>,
}

impl Default for ResidualGpOptions {
    fn default() -> Self {
        // What each default was measured against is in docs/results/gp-defaults.md; here the
        // reasons.
        Self {
            gp: exact_gp_defaults(),
            method: GpChoice::default(),
            // One exact evaluation with its gradient costs n³ flops (64 GFLOP at n = 4000: a
            // search takes minutes); the sparse GP with 500 inducing points takes seconds there
            // and stays within a few percent of the exact error.
            sparse_above_rows: 4000,
            sparse: gp_sparse::SparseConfig::default(),
            // A kernel per output: shared hyperparameters lose accuracy where the outputs' errors
            // vary on different scales.
            sparse_outputs: gp::OutputMode::Independent,
            // SE-ARD, not the exact GP's additive kernel: at the sizes the sparse GP serves the
            // additive term gained nothing held out, and its d one-dimensional kernels cost d
            // more exponentials for each of the n·m entries of every bound evaluation.
            sparse_kernel: gp::KernelChoice::SquaredExponentialArd,
            residual_frame: ResidualFrame::default(),
            // Off: a shared rotation kernel is cheaper but cost held-out rotation accuracy on the
            // UR10; accuracy first.
            rotation_follows_position: false,
            // One half: where the posterior keeps more than half of the prior variance a training
            // pose leaves, the prediction is more the prior's extrapolation than the data's.
            fade_above_variance_ratio: Some(0.5),
            // The median of 2,000 rows is within about 3 % of the rows' spread of the median of
            // all of them (its standard error, 1.25 σ / √2000), far inside the rule's margin:
            // the share fades the correction only from half-way between it and 1.
            fade_share_rows: 2000,
            inputs: Vec::new(),
            // The subset's optimum as it is (no iteration on all rows): the fallback serves only
            // the rows an effect's span fades, where its held-out error matched the full search's.
            fallback_refine_iterations: Some(0),
        }
    }
}

/// The exact GP's defaults (the reasons for each below).
fn exact_gp_defaults() -> gp::GpConfig {
    // ARD squared exponential plus a first-order additive term (one one-dimensional squared
    // exponential per input) rather than the paper's Eq. 5 kernel: the additive term learns a
    // joint's periodic gear error from the poses that move that joint, which the joint ARD
    // term cannot. The default start and the kernel's nested start (additive term nearly
    // off), searched on a 500-row warm-start subset; no random restarts, which never reached
    // the best likelihood on bench-gp's sets.
    //
    // The search stops when an iteration raises the log marginal likelihood by less than
    // 1e-5 of itself (≈ 0.005 nats here, far below the ~1 nat that separates models) and
    // keeps 20 curvature pairs (the kernel's parameter count on six joints: nearly full
    // BFGS). The full-data search after the subset starts near its optimum, where an
    // iteration gains hundredths of a nat for an `n³` factorisation: it stops at 1e-4.
    let optimiser = gp::OptimiserConfig {
        restarts: 0,
        warm_start_rows: 500,
        memory: 20,
        function_tolerance: 1e-5,
        refine_function_tolerance: Some(1e-4),
        ..gp::OptimiserConfig::default()
    };
    gp::GpConfig {
        kernel: gp::KernelChoice::Composite {
            shape: gp::StationaryShape::SquaredExponential,
            constant: false,
            linear: false,
            additive: true,
        },
        optimiser,
        // The additive term only where the data pay for it: per output, the kernel with
        // and without it are both searched (on the warm-start subset when there is one,
        // then only the chosen one on all rows) and the additive term is kept when it
        // raises the log marginal likelihood by more than the Schwarz penalty ½ · 2d · ln N.
        // No threshold of ours: BIC's own.
        additive_by_bic: true,
        // The paper's isotropic Eq. 5 kernel beside it, per output, kept where its
        // closed-form leave-one-out log predictive probability is higher: on a few hundred
        // poses the ARD length scales, fitted by marginal likelihood, can overfit. Decided
        // on the warm-start subset's optimum where there is one, so the isotropic kernel
        // is searched on all rows only where it wins there.
        isotropic_by_loo: true,
        ..gp::GpConfig::default()
    }
}

impl ResidualGpOptions {
    /// The fade's options: the first outside its range, with its value and what is expected.
    pub fn validate_fade(&self) -> Result<(), errors::OptionOutOfRange> {
        if let Some(r) = self.fade_above_variance_ratio {
            let accepted = (0.0..1.0).contains(&r);
            errors::OptionOutOfRange::check("fade_above_variance_ratio", r, accepted, "a number in [0, 1) or None")?;
        }
        errors::option::at_least_one("fade_share_rows", self.fade_share_rows)
    }

    /// The GP's inputs, refused as [`measurements::InputNames`] refuses a list of names (not a
    /// range): the field and the message.
    pub fn validate_inputs(&self) -> Result<(), (&'static str, String)> {
        measurements::InputNames::new(self.inputs.clone(), "residual_gp.inputs")
            .map(|_| ())
            .map_err(|e| ("inputs", format!("residual_gp.inputs: {}", e.dyn_kind())))
    }
}

/// A field given in an options file, or `None` when it was left out.
fn given<'de, D: serde::Deserializer<'de>, T: Deserialize<'de>>(deserializer: D) -> Result<Option<T>, D::Error> {
    T::deserialize(deserializer).map(Some)
}

/// The fields of [`gp::OptimiserConfig`] an options file may set.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct OptimiserPatch {
    #[serde(default, deserialize_with = "given")]
    restarts: Option<usize>,
    #[serde(default, deserialize_with = "given")]
    seed: Option<u64>,
    #[serde(default, deserialize_with = "given")]
    max_iterations: Option<usize>,
    #[serde(default, deserialize_with = "given")]
    memory: Option<usize>,
    #[serde(default, deserialize_with = "given")]
    gradient_tolerance: Option<f64>,
    #[serde(default, deserialize_with = "given")]
    function_tolerance: Option<f64>,
    #[serde(default, deserialize_with = "given")]
    warm_start_rows: Option<usize>,
    #[serde(default, deserialize_with = "given")]
    warm_start_curvature: Option<bool>,
    #[serde(default, deserialize_with = "given")]
    refine_function_tolerance: Option<Option<f64>>,
    #[serde(default, deserialize_with = "given")]
    refine_max_iterations: Option<Option<usize>>,
    #[serde(default, deserialize_with = "given")]
    kernel_cache_bytes: Option<usize>,
}

/// The fields of [`gp::GpConfig`] an options file may set.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GpPatch {
    #[serde(default, deserialize_with = "given")]
    kernel: Option<gp::KernelChoice>,
    #[serde(default, deserialize_with = "given")]
    bounds: Option<Option<gp::Bounds>>,
    #[serde(default, deserialize_with = "given")]
    outputs: Option<gp::OutputMode>,
    #[serde(default, deserialize_with = "given")]
    standardise_inputs: Option<bool>,
    #[serde(default, deserialize_with = "given")]
    normalise_outputs: Option<bool>,
    #[serde(default, deserialize_with = "given")]
    optimiser: Option<OptimiserPatch>,
    #[serde(default, deserialize_with = "given")]
    jitter: Option<gp::JitterConfig>,
    #[serde(default, deserialize_with = "given")]
    parallelism: Option<gp::Parallelism>,
    #[serde(default, deserialize_with = "given")]
    additive_by_bic: Option<bool>,
    #[serde(default, deserialize_with = "given")]
    isotropic_by_loo: Option<bool>,
    #[serde(default, deserialize_with = "given")]
    follower_groups: Option<Vec<Vec<usize>>>,
}

/// `gp` as an options file gives it, laid over [`ResidualGpOptions::default`]'s: derived
/// `#[serde(default)]` would fill the fields left out from [`gp::GpConfig::default`] (the
/// library's kernel, three restarts, no warm start) and silently change the fit.
fn onto_default_gp<'de, D: serde::Deserializer<'de>>(deserializer: D) -> Result<gp::GpConfig, D::Error> {
    let patch = GpPatch::deserialize(deserializer)?;
    let mut gp = ResidualGpOptions::default().gp;
    let GpPatch {
        kernel,
        bounds,
        outputs,
        standardise_inputs,
        normalise_outputs,
        optimiser,
        jitter,
        parallelism,
        additive_by_bic,
        isotropic_by_loo,
        follower_groups,
    } = patch;
    gp.kernel = kernel.unwrap_or(gp.kernel);
    gp.bounds = bounds.unwrap_or(gp.bounds);
    gp.outputs = outputs.unwrap_or(gp.outputs);
    gp.standardise_inputs = standardise_inputs.unwrap_or(gp.standardise_inputs);
    gp.normalise_outputs = normalise_outputs.unwrap_or(gp.normalise_outputs);
    gp.jitter = jitter.unwrap_or(gp.jitter);
    gp.parallelism = parallelism.unwrap_or(gp.parallelism);
    gp.additive_by_bic = additive_by_bic.unwrap_or(gp.additive_by_bic);
    gp.isotropic_by_loo = isotropic_by_loo.unwrap_or(gp.isotropic_by_loo);
    gp.follower_groups = follower_groups.unwrap_or(gp.follower_groups);
    if let Some(o) = optimiser {
        let OptimiserPatch {
            restarts,
            seed,
            max_iterations,
            memory,
            gradient_tolerance,
            function_tolerance,
            warm_start_rows,
            warm_start_curvature,
            refine_function_tolerance,
            refine_max_iterations,
            kernel_cache_bytes,
        } = o;
        let d = &mut gp.optimiser;
        d.restarts = restarts.unwrap_or(d.restarts);
        d.seed = seed.unwrap_or(d.seed);
        d.max_iterations = max_iterations.unwrap_or(d.max_iterations);
        d.memory = memory.unwrap_or(d.memory);
        d.gradient_tolerance = gradient_tolerance.unwrap_or(d.gradient_tolerance);
        d.function_tolerance = function_tolerance.unwrap_or(d.function_tolerance);
        d.warm_start_rows = warm_start_rows.unwrap_or(d.warm_start_rows);
        d.warm_start_curvature = warm_start_curvature.unwrap_or(d.warm_start_curvature);
        d.refine_function_tolerance = refine_function_tolerance.unwrap_or(d.refine_function_tolerance);
        d.refine_max_iterations = refine_max_iterations.unwrap_or(d.refine_max_iterations);
        d.kernel_cache_bytes = kernel_cache_bytes.unwrap_or(d.kernel_cache_bytes);
    }
    Ok(gp)
}

impl ResidualGpOptions {
    /// The GP that `rows` training rows get.
    pub fn choice_for(&self, rows: usize) -> GpChoice {
        match self.method {
            GpChoice::Auto if rows > self.sparse_above_rows => GpChoice::Sparse,
            GpChoice::Auto => GpChoice::Exact,
            other => other,
        }
    }
}

/// The fitted GP of the stage: exact or sparse.
///
/// Stored untagged, so that model files written before the sparse GP existed (an exact GP in the
/// `gp` field) still read.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(untagged)]
pub enum GpModel {
    /// The sparse variational GP.
    Sparse(gp_sparse::SparseGp),
    /// The exact GP.
    Exact(gp::ExactGp),
}

impl GpModel {
    /// Number of inputs.
    pub fn input_dim(&self) -> usize {
        match self {
            Self::Exact(g) => g.input_dim(),
            Self::Sparse(g) => g.input_dim(),
        }
    }

    /// Number of outputs.
    pub fn output_count(&self) -> usize {
        match self {
            Self::Exact(g) => g.output_count(),
            Self::Sparse(g) => g.output_count(),
        }
    }

    /// Every kernel of the GP (one per group of outputs).
    pub fn kernels(&self) -> Vec<&gp::Kernel> {
        match self {
            Self::Exact(g) => g.report().components.iter().map(|c| &c.kernel).collect(),
            Self::Sparse(g) => g.report().components.iter().map(|c| &c.kernel).collect(),
        }
    }

    /// The mean of each input over the training rows (the GP's input standardisation).
    pub fn input_mean(&self) -> &[f64] {
        match self {
            Self::Exact(g) => &g.input_standardiser().mean,
            Self::Sparse(g) => &g.input_standardiser().mean,
        }
    }

    /// Which one it is.
    pub fn choice(&self) -> GpChoice {
        match self {
            Self::Exact(_) => GpChoice::Exact,
            Self::Sparse(_) => GpChoice::Sparse,
        }
    }

    /// Posterior mean and variance at the rows of `x`.
    pub fn predict(&self, x: faer::MatRef<'_, f64>) -> Result<gp::Prediction, gp::Error> {
        match self {
            Self::Exact(g) => g.predict(x),
            Self::Sparse(g) => g.predict(x),
        }
    }
}

/// What the GP's fit reported.
#[derive(Debug, Clone, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GpFitReport {
    /// The exact GP's report.
    Exact(gp::ExactFitReport),
    /// The sparse GP's report.
    Sparse(gp_sparse::SparseFitReport),
}

impl GpFitReport {
    /// The output columns whose kernel's hyperparameter search stopped on its iteration limit or a
    /// failed line search rather than on a tolerance, with the iterations it ran. For the sparse GP
    /// that is the exact search on its subset: the bound's search that refines it runs a fixed
    /// budget ([`gp_sparse::SparseConfig::bound_iterations`]) and its outcome stays in the report.
    pub fn unconverged(&self) -> Vec<(Vec<usize>, usize)> {
        let exact = |c: &gp::ComponentReport| match &c.optimisation {
            Some(o) if !o.converged => Some((c.outputs.clone(), o.iterations)),
            _ => None,
        };
        match self {
            Self::Exact(r) => r.components.iter().filter_map(exact).collect(),
            Self::Sparse(r) => r.components.iter().filter_map(|c| c.subset_fit.as_ref().and_then(exact)).collect(),
        }
    }
}

/// A fitted residual GP, stored in the model file.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ResidualGp {
    /// Whether the payload is an input (method `poe-gp-load`, Eq. 12).
    pub with_payload: bool,
    /// Six outputs (a twist) for full-pose data, three (the position error) otherwise.
    pub full_pose: bool,
    /// Where the error twist is expressed.
    pub residual_frame: ResidualFrame,
    /// The GP: inputs `(q_1 … q_n[, m])`, outputs the error components.
    pub gp: GpModel,
    /// `model_frame_from_fit_frame`: where the reference frame moved since the GP was fitted
    /// (`calib register`, crate `cell`). The GP's outputs are in the frame it was fitted in and
    /// are carried into the model's by this transform's adjoint (its rotation alone for the
    /// tool-point frame and position-only outputs), which is exact. Absent: not moved.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moved_by: Option<SE3>,
    /// Per model tool, the point (in that tool's frame, m) about which a tool-point correction
    /// applies: where `calib register` carried a tool (`tool = reference · D`), the reference
    /// tool's point `D⁻¹ · 0`, so that the registered model predicts `G P_ref · D`, as the
    /// registration fitted it, and the GP's orientation correction reaches the new point through
    /// its lever arm. Empty, or `None` for a tool: the tool's own point. Absent in older files.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub tool_points: Vec<Option<Vector3>>,
    /// The GP of what the geometry fitted alone ([`crate::CalibratedModel::fallback_kinematics`])
    /// leaves on the same training rows, its hyperparameters searched on those residuals
    /// ([`ResidualGp::fit_fallback`]): where the effects fade out and the pose blends to
    /// the geometry alone, the correction blends to this GP's, so that off the effects' angles the
    /// model is the GP-corrected geometry (what `poe-gp` without effects would give) rather than
    /// the geometry with a GP learnt on what the effects left. Absent without effects, for the
    /// sparse GP, where `--effects auto`'s arcs predicted the faded rows better without it, and in
    /// older files (there the GP applies to the blended pose).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<GpModel>,
    /// Where the GP's correction fades ([`ResidualGpOptions::fade_above_variance_ratio`]), as
    /// fitted. Absent in older files and where the options turn it off: it never fades there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fade: Option<GpFadeRule>,
    /// The measured signals the GP takes after the joints and the payload, by column name
    /// ([`ResidualGpOptions::inputs`]; their spans are in the model's
    /// [`crate::TrainingRange::inputs`]). Absent in older files and where it takes none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<String>,
}

/// Where a GP's correction fades: from the share `r` of its prior variance (of the position
/// outputs, pooled) its posterior keeps at a row, measured from what it keeps at its own training
/// rows, `s = (r − t) / (1 − t)` (0 at a typical training row, 1 where the training rows say
/// nothing), the correction applies in full while `s` is at most [`GpFadeRule::above`] and
/// fades linearly to none at `s = 1`. From the training rows' share, not from 0: a GP whose
/// signal is weak beside its noise keeps much of its prior variance even at its training rows
/// (UR10 B, what the effects leave: more than half at 478 of 747 interleaved held-out rows), and
/// there its small mean is the data's, not an extrapolation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GpFadeRule {
    /// [`ResidualGpOptions::fade_above_variance_ratio`].
    pub above: f64,
    /// The median share `t` of the GP's prior variance its posterior keeps at its training rows,
    /// each left out of it.
    pub training_share: f64,
    /// The same for the [`ResidualGp::fallback`] GP, where there is one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback_training_share: Option<f64>,
}

impl GpFadeRule {
    /// The training share of the GP (`fallback`: of the fallback GP; the GP's where a file
    /// lacks it).
    pub fn training_share_of(&self, fallback: bool) -> f64 {
        if fallback { self.fallback_training_share.unwrap_or(self.training_share) } else { self.training_share }
    }

    /// The weight of the correction at a row where the posterior keeps the share `ratio` of the
    /// prior variance, for a GP whose training rows keep `training_share`.
    pub fn weight(&self, ratio: f64, training_share: f64) -> f64 {
        let t = training_share.clamp(0.0, 1.0);
        let s = if t < 1.0 { ((ratio - t) / (1.0 - t)).max(0.0) } else { 0.0 };
        gp_weight(Some(self.above), s)
    }
}

/// The rule that fades the correction where the posterior keeps more than `above` of the prior
/// variance, with the training rows' median share; none where the options turn it off.
fn fade_rule(
    gp: &GpModel,
    x: &Mat<f64>,
    loo: Option<&gp::LeaveOneOut>,
    options: &ResidualGpOptions,
) -> Result<Option<GpFadeRule>, Error> {
    Ok(match options.fade_above_variance_ratio {
        Some(above) => Some(GpFadeRule {
            above,
            training_share: timings::phase("fade share", || median_share(gp, x, loo, options.fade_share_rows))?,
            fallback_training_share: None,
        }),
        None => None,
    })
}

/// The median over the training rows `x` of the share of its prior variance `gp`'s posterior
/// keeps at a row it has not seen there: for the exact GP, each row left out of it (R&W
/// Eq. 5.12, the noise taken off: a row's own noisy value would count as knowledge of its
/// neighbours, and a held-out pose between two training poses has none); for the sparse GP, which
/// has no closed form, at the row itself, over at most `sparse_rows` of them (every k-th).
/// `loo`: the exact GP's leave-one-out where the caller has it already.
fn median_share(gp: &GpModel, x: &Mat<f64>, loo: Option<&gp::LeaveOneOut>, sparse_rows: usize) -> Result<f64, Error> {
    if let GpModel::Sparse(_) = gp
        && x.nrows() > sparse_rows
    {
        let step = x.nrows().div_ceil(sparse_rows.max(1));
        let rows: Vec<usize> = (0..x.nrows()).step_by(step).collect();
        let every_kth = Mat::from_fn(rows.len(), x.ncols(), |i, j| x[(rows[i], j)]);
        return median_share(gp, &every_kth, None, sparse_rows);
    }
    let mut prediction = match gp {
        GpModel::Sparse(_) => gp.predict(x.as_ref()).map_err(Error::gp)?,
        // The leave-one-out variances stand for the posterior's at the training rows, so only the
        // prior variance is needed beside them (a posterior variance would cost a solve with
        // every row as a right-hand side).
        GpModel::Exact(exact) => gp::Prediction {
            mean: Mat::zeros(0, 0),
            variance: Mat::zeros(x.nrows(), exact.output_count()),
            covariance: Vec::new(),
            prior_variance: exact.prior_variance(x.as_ref()).map_err(Error::gp)?,
        },
    };
    if let GpModel::Exact(exact) = gp {
        let computed;
        let loo = match loo {
            Some(loo) => loo,
            None => {
                computed = exact.leave_one_out().map_err(Error::gp)?;
                &computed
            }
        };
        let scale = &exact.output_normaliser().scale;
        for component in &exact.report().components {
            let noise = component.kernel.noise_variance();
            for &out in &component.outputs {
                for i in 0..x.nrows() {
                    prediction.variance[(i, out)] = loo.variance[(i, out)] - noise * scale[out] * scale[out];
                }
            }
        }
    }
    let mut shares: Vec<f64> = (0..x.nrows()).map(|i| kept_share(&prediction, i)).collect();
    shares.sort_by(f64::total_cmp);
    Ok(shares.get(shares.len() / 2).copied().unwrap_or(0.0))
}

/// How far the GP's correction applies at a row: 1 in full, 0 not at all (the geometry), from the
/// share `r` of its prior variance the posterior keeps there.
pub fn gp_weight(fade_above: Option<f64>, ratio: f64) -> f64 {
    match fade_above {
        Some(r0) if ratio > r0 => ((1.0 - ratio) / (1.0 - r0)).clamp(0.0, 1.0),
        _ => 1.0,
    }
}

/// The share of the prior variance of the position outputs (the first three) the posterior keeps
/// at row `i`, pooled over them; 0 where the prior has none.
fn kept_share(prediction: &gp::Prediction, i: usize) -> f64 {
    let outputs = prediction.variance.ncols().min(3);
    let kept: f64 = (0..outputs).map(|c| prediction.variance[(i, c)].max(0.0)).sum();
    let prior: f64 = (0..outputs).map(|c| prediction.prior_variance[(i, c)]).sum();
    if prior > 0.0 { (kept / prior).min(1.0) } else { 0.0 }
}

/// What the GP stage reports.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualGpReport {
    /// The GP's own report (hyperparameters, log marginal likelihood or bound, jitter).
    pub gp: GpFitReport,
    /// The training error of the model had the GP not seen each row: every row corrected by the
    /// GP's closed-form leave-one-out prediction (R&W Eqs. 5.10–5.12; hyperparameters and the
    /// geometry as fitted on all rows). A GP interpolates its training poses, so the training
    /// error after it says little; this says what it does on a pose it has not seen. `None` for
    /// the sparse GP, which has no closed form.
    pub leave_one_out: Option<crate::ErrorSummary>,
    /// Where rows repeat a configuration ([`crate::RepeatGroups`]), the same with each repeated
    /// configuration left out whole (closed form by blocks, [`gp::ExactGp::leave_groups_out`]):
    /// leaving one row out keeps its twin, whose value the GP then returns, so
    /// [`ResidualGpReport::leave_one_out`] flatters the model there. Absent without repeats and for
    /// the sparse GP.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub leave_group_out: Option<crate::ErrorSummary>,
    /// Rows that repeat another row's configuration (0: none), and in how many configurations.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub repeated_rows: usize,
    /// The configurations measured more than once.
    #[serde(default, skip_serializing_if = "is_zero")]
    pub repeated_configurations: usize,
    /// The measured signals the GP took beside the joints (`--inputs`), each with its unit and
    /// the span it was fitted on; absent where it took none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub inputs: Vec<crate::InputSpan>,
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

/// A row's correction `G` to put before its model pose, and the standard deviation of each error
/// component `(v, ω)` (m, rad).
pub type Correction = (SE3, [f64; 6]);

/// The exact GP of the stage on inputs `x` and residuals `y`: `options.gp`, with the rotation
/// outputs following the position outputs' kernel for full-pose data where the options ask.
fn exact_fit(x: &Mat<f64>, y: &Mat<f64>, full_pose: bool, options: &ResidualGpOptions) -> Result<gp::ExactGp, Error> {
    let mut config = options.gp.clone();
    if full_pose && options.rotation_follows_position && config.follower_groups.is_empty() {
        config.follower_groups = vec![vec![3, 4, 5]];
    }
    gp::ExactGp::fit(x.as_ref(), y.as_ref(), &config).map_err(Error::gp)
}

/// The GP's inputs of `rows`: the joints, the payload where `with_payload`, then the measured
/// signals `signals` by name; a row without one of them is refused at its line of `source`
/// ([`measurements::ErrorKind::MissingInput`]: rows a caller made without it; a file without the column was
/// refused by its reader).
fn inputs(rows: &[Measurement], with_payload: bool, signals: &[String], source: &str) -> Result<Mat<f64>, Error> {
    let n = rows.first().map_or(0, |r| r.q.len());
    let p = n + usize::from(with_payload);
    let mut x = Mat::from_fn(rows.len(), p + signals.len(), |i, c| {
        if c < n {
            rows[i].q[c]
        } else if c < p {
            rows[i].payload_kg
        } else {
            0.0
        }
    });
    for (i, row) in rows.iter().enumerate() {
        for (k, name) in signals.iter().enumerate() {
            let Some(value) = row.inputs.value(k, name) else {
                let kind = measurements::ErrorKind::MissingInput { name: name.clone() };
                return Err(Error::at_line(source.to_owned(), row.line, 1, kind));
            };
            x[(i, p + k)] = value;
        }
    }
    Ok(x)
}

/// The error of one row against the model's pose, as the GP's output vector.
fn error_vector(model_pose: &SE3, row: &Measurement, frame: ResidualFrame) -> Vector6 {
    match row.orientation {
        None => {
            let d = row.position - model_pose.translation();
            Vector6::new(d.x, d.y, d.z, 0.0, 0.0, 0.0)
        }
        Some(rotation) => {
            let measured = SE3::new(rotation, row.position);
            let error = measured * model_pose.inverse();
            match frame {
                ResidualFrame::Tracker => error.log().to_vector(),
                ResidualFrame::ToolPoint => {
                    let p = SE3::from_translation(model_pose.translation());
                    (p.inverse() * error * p).log().to_vector()
                }
            }
        }
    }
}

/// What the GP learns: its inputs `(q_1 … q_n[, m])` and the error the geometric model leaves
/// (Eq. 8), one row per measurement.
#[derive(Debug, Clone)]
pub struct ResidualSet {
    /// `n × (joints [+ 1])`: joint values, then the payload (kg) when it is an input.
    pub inputs: Mat<f64>,
    /// `n × 3` (position only: the position error, m) or `n × 6` (full pose: the error twist).
    pub outputs: Mat<f64>,
}

impl ResidualSet {
    /// The error that the model poses `poses` (one per row) leave on `data`, expressed in `frame`.
    pub fn new(poses: &[SE3], data: &MeasurementSet, with_payload: bool, frame: ResidualFrame) -> Self {
        Self::with_inputs(poses, data, with_payload, &[], frame).expect("no measured signal to miss")
    }

    /// [`ResidualSet::new`] with the measured signals `signals` as inputs after the joints and
    /// the payload; a row without one is refused at its line.
    pub fn with_inputs(
        poses: &[SE3],
        data: &MeasurementSet,
        with_payload: bool,
        signals: &[String],
        frame: ResidualFrame,
    ) -> Result<Self, Error> {
        let outputs = if data.full_pose { 6 } else { 3 };
        let mut y = Mat::<f64>::zeros(data.rows.len(), outputs);
        for (i, (row, pose)) in data.rows.iter().zip(poses).enumerate() {
            let e = error_vector(pose, row, frame);
            for c in 0..outputs {
                y[(i, c)] = e[c];
            }
        }
        Ok(Self { inputs: inputs(&data.rows, with_payload, signals, &data.source)?, outputs: y })
    }
}

impl ResidualGp {
    /// Fits the GP to the error that the model poses `poses` (one per row) leave on `data`;
    /// `repeats` groups the rows of `data` that repeat a configuration, for the leave-group-out
    /// error.
    pub fn fit(
        poses: &[SE3],
        data: &MeasurementSet,
        with_payload: bool,
        options: &ResidualGpOptions,
        repeats: &crate::RepeatGroups,
    ) -> Result<(Self, ResidualGpReport), Error> {
        let ResidualSet { inputs: x, outputs: y } =
            ResidualSet::with_inputs(poses, data, with_payload, &options.inputs, options.residual_frame)?;
        let (gp, report, loo, leave_group_out) = match options.choice_for(x.nrows()) {
            GpChoice::Sparse => {
                let inducing_points = options.sparse.inducing_points.min(x.nrows());
                let gp = gp::GpConfig {
                    outputs: options.sparse_outputs,
                    kernel: options.sparse_kernel,
                    ..options.gp.clone()
                };
                let config = gp_sparse::SparseConfig { gp, inducing_points, ..options.sparse.clone() };
                let model = timings::phase("search", || gp_sparse::SparseGp::fit(x.as_ref(), y.as_ref(), &config))
                    .map_err(Error::gp)?;
                let report = GpFitReport::Sparse(model.report().clone());
                (GpModel::Sparse(model), report, None, None)
            }
            GpChoice::Exact | GpChoice::Auto => {
                let model = timings::phase("search", || exact_fit(&x, &y, data.full_pose, options))?;
                let report = GpFitReport::Exact(model.report().clone());
                let loo = timings::phase("leave-one-out", || model.leave_one_out()).map_err(Error::gp)?;
                let grouped = if repeats.any() {
                    let grouped = timings::phase("leave-group-out", || model.leave_groups_out(&repeats.groups));
                    Some(grouped.map_err(Error::gp)?.mean)
                } else {
                    None
                };
                (GpModel::Exact(model), report, Some(loo), grouped)
            }
        };
        let fade = fade_rule(&gp, &x, loo.as_ref(), options)?;
        let residual_gp = Self {
            with_payload,
            full_pose: data.full_pose,
            residual_frame: options.residual_frame,
            gp,
            moved_by: None,
            tool_points: Vec::new(),
            fallback: None,
            fade,
            inputs: options.inputs.clone(),
        };
        let report = residual_gp.fit_report(report, (loo, leave_group_out), poses, data, options, repeats);
        Ok((residual_gp, report))
    }

    /// The fit's report: the GP's own, and the held-out errors its leave-one-out and
    /// leave-group-out means give the model's poses, with the repeats and the inputs' ranges.
    fn fit_report(
        &self,
        gp: GpFitReport,
        (loo, leave_group_out): (Option<gp::LeaveOneOut>, Option<Mat<f64>>),
        poses: &[SE3],
        data: &MeasurementSet,
        options: &ResidualGpOptions,
        repeats: &crate::RepeatGroups,
    ) -> ResidualGpReport {
        let summary = |mean: Mat<f64>| self.error_summary(poses, data, &mean);
        ResidualGpReport {
            gp,
            leave_one_out: loo.map(|loo| summary(loo.mean)),
            leave_group_out: leave_group_out.map(&summary),
            repeated_rows: repeats.repeated_rows(),
            repeated_configurations: repeats.groups.iter().filter(|g| g.len() > 1).count(),
            inputs: crate::TrainingRange::of(&data.rows)
                .map(|range| range.inputs.into_iter().filter(|i| options.inputs.contains(&i.name)).collect())
                .unwrap_or_default(),
        }
    }

    /// The errors left on `data` when each pose is corrected by the GP's `mean` at its row.
    fn error_summary(&self, poses: &[SE3], data: &MeasurementSet, mean: &Mat<f64>) -> crate::ErrorSummary {
        let errors: Vec<crate::PoseError> = poses
            .iter()
            .zip(&data.rows)
            .enumerate()
            .map(|(i, (pose, row))| {
                let g = Vector6::from_fn(|c, _| if c < mean.ncols() { mean[(i, c)] } else { 0.0 });
                let error = crate::pose_error(&(self.correction(pose, &g) * *pose), row);
                if data.full_pose { error } else { crate::PoseError { rotation_mrad: None, ..error } }
            })
            .collect();
        crate::ErrorSummary::from_errors(&errors)
    }

    /// The GP's inputs for `rows`: `(q_1 … q_n[, m], s_1 … s_k)`, the payload where the GP
    /// takes it and then its measured signals ([`ResidualGp::inputs`]), as its fit and its
    /// prediction build them; a row without a signal is refused at its line of `source`.
    pub fn inputs_of(&self, rows: &[Measurement], source: &str) -> Result<Mat<f64>, Error> {
        inputs(rows, self.with_payload, &self.inputs, source)
    }

    /// `G` for the GP's output `g` at a model pose: a translation for position-only data, else the
    /// twist's exponential, at the tool point or in the tracker frame as the residuals were taken.
    fn correction(&self, pose: &SE3, g: &Vector6) -> SE3 {
        self.correction_about(pose, g, None)
    }

    /// [`ResidualGp::correction`] with the tool point taken at `point` of the pose's frame.
    fn correction_about(&self, pose: &SE3, g: &Vector6, point: Option<Vector3>) -> SE3 {
        if !self.full_pose {
            return SE3::from_translation(Vector3::new(g[0], g[1], g[2]));
        }
        let exp = Twist::from_vector(g).exp();
        match self.residual_frame {
            ResidualFrame::Tracker => exp,
            ResidualFrame::ToolPoint => {
                let p = SE3::from_translation(point.map_or_else(|| pose.translation(), |u| pose.transform_point(&u)));
                p * exp * p.inverse()
            }
        }
    }

    /// The GP's output `g` and its deviations carried from the frame it was fitted in to the
    /// model's ([`ResidualGp::moved_by`]): `X exp(ĝ) X⁻¹ = exp((Ad_X g)^)` in the tracker frame;
    /// at the tool point, `X P = P' R` with `P'` the translation to the moved point, so only the
    /// rotation acts. Deviations as those of independent components, `σ'² = Σ_k A_ck² σ_k²`.
    fn carried(&self, moved: &SE3, g: &Vector6, std: &[f64; 6]) -> (Vector6, [f64; 6]) {
        let adjoint = match (self.full_pose, self.residual_frame) {
            (true, ResidualFrame::Tracker) => moved.adjoint(),
            _ => SE3::new(moved.rotation(), Vector3::zeros()).adjoint(),
        };
        let carried = adjoint * g;
        let deviations =
            std::array::from_fn(|c| (0..6).map(|k| (adjoint[(c, k)] * std[k]).powi(2)).sum::<f64>().sqrt());
        (carried, deviations)
    }

    /// The correction of every row: `G(q, m)` to put before the model pose, and the GP's standard
    /// deviation of each error component `(v, ω)` (m, rad; zeros where not modelled). Each row's
    /// model tool in `data` picks its tool point ([`ResidualGp::tool_points`]).
    pub fn predict(&self, data: &BoundSet<'_>, model_poses: &[SE3]) -> Result<Vec<Correction>, Error> {
        self.predict_with(&self.gp, false, data, model_poses)
    }

    /// [`ResidualGp::predict`] with the [`ResidualGp::fallback`] GP at the poses of the geometry
    /// fitted alone; `None` where the model has none.
    pub fn predict_fallback(&self, data: &BoundSet<'_>, alone_poses: &[SE3]) -> Option<Result<Vec<Correction>, Error>> {
        self.fallback.as_ref().map(|gp| self.predict_with(gp, true, data, alone_poses))
    }

    /// Fits [`ResidualGp::fallback`]: an exact GP, searched as this one was, on the error that
    /// `alone_poses` (the geometry fitted alone, one per row of `data`, the rows this GP was
    /// fitted on) leave: the GP `poe-gp` without effects fits. Its own search, not this GP's
    /// hyperparameters: those were chosen on what the effects left, little more than noise, and
    /// held, the fallback GP learnt almost nothing (a simulated joint-3 error beside a faded
    /// joint-2 series: 0.2634 mm off the effects' angles with them against 0.2633 without the
    /// fallback GP and 0.1807 for `poe-gp`). Nothing for the sparse GP.
    pub fn fit_fallback(
        &mut self,
        alone_poses: &[SE3],
        data: &MeasurementSet,
        options: &ResidualGpOptions,
    ) -> Result<(), Error> {
        if !matches!(self.gp, GpModel::Exact(_)) {
            return Ok(());
        }
        let ResidualSet { inputs: x, outputs: y } =
            ResidualSet::with_inputs(alone_poses, data, self.with_payload, &self.inputs, self.residual_frame)?;
        let mut options = options.clone();
        options.gp.optimiser.refine_max_iterations =
            options.fallback_refine_iterations.or(options.gp.optimiser.refine_max_iterations);
        let fallback = GpModel::Exact(timings::phase("search", || exact_fit(&x, &y, data.full_pose, &options))?);
        if let Some(fade) = &mut self.fade {
            fade.fallback_training_share =
                Some(timings::phase("fade share", || median_share(&fallback, &x, None, options.fade_share_rows))?);
        }
        self.fallback = Some(fallback);
        Ok(())
    }

    /// How far the GP's correction applies at each row of `rows` ([`gp_weight`]), and the share
    /// of its prior variance the posterior keeps there: of the GP, and with a
    /// [`ResidualGp::fallback`] the smaller of the two weights.
    pub fn weights(&self, rows: &[Measurement]) -> Result<Vec<(f64, f64)>, Error> {
        let x = inputs(rows, self.with_payload, &self.inputs, "the rows")?;
        let mut out = vec![(1.0, 0.0); rows.len()];
        for (gp, fallback) in std::iter::once((&self.gp, false)).chain(self.fallback.iter().map(|f| (f, true))) {
            let prediction = gp.predict(x.as_ref()).map_err(Error::gp)?;
            for (i, slot) in out.iter_mut().enumerate() {
                let share = kept_share(&prediction, i);
                let w = self.fade.map_or(1.0, |fade| fade.weight(share, fade.training_share_of(fallback)));
                if w < slot.0 || (w == slot.0 && share > slot.1) {
                    *slot = (w, share);
                }
            }
        }
        Ok(out)
    }

    fn predict_with(
        &self,
        gp: &GpModel,
        fallback: bool,
        data: &BoundSet<'_>,
        model_poses: &[SE3],
    ) -> Result<Vec<Correction>, Error> {
        let tools = data.tools();
        let x = inputs(data.rows(), self.with_payload, &self.inputs, &data.set().source)?;
        let prediction = gp.predict(x.as_ref()).map_err(Error::gp)?;
        let outputs = prediction.mean.ncols();
        Ok(model_poses
            .iter()
            .enumerate()
            .map(|(i, pose)| {
                // Where the GP knows little, its correction fades (weight w); what it no longer
                // corrects joins its σ: E[(f − w m)²] = σ² + ((1 − w) m)².
                let share = kept_share(&prediction, i);
                let w = self.fade.map_or(1.0, |fade| fade.weight(share, fade.training_share_of(fallback)));
                let mut g = Vector6::zeros();
                let mut std = [0.0; 6];
                for c in 0..outputs {
                    let (m, v) = (prediction.mean[(i, c)], prediction.variance[(i, c)].max(0.0));
                    g[c] = w * m;
                    std[c] = (v + ((1.0 - w) * m).powi(2)).sqrt();
                }
                if let Some(moved) = self.moved_by {
                    (g, std) = self.carried(&moved, &g, &std);
                }
                let point = tools.get(i).and_then(|&t| self.tool_points.get(t).copied().flatten());
                (self.correction_about(pose, &g, point), std)
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::gp_weight;

    #[test]
    fn the_gp_weight_is_whole_up_to_the_ratio_and_falls_linearly_to_none_where_the_data_say_nothing() {
        assert_eq!(gp_weight(None, 1.0), 1.0);
        assert_eq!(gp_weight(Some(0.5), 0.0), 1.0);
        assert_eq!(gp_weight(Some(0.5), 0.5), 1.0);
        assert!((gp_weight(Some(0.5), 0.75) - 0.5).abs() < 1e-15);
        assert_eq!(gp_weight(Some(0.5), 1.0), 0.0);
        assert!((gp_weight(Some(0.0), 0.25) - 0.75).abs() < 1e-15);
    }
}
