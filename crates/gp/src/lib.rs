//! Gaussian process regression on plain matrices: kernels with analytic gradients, the log
//! marginal likelihood, hyperparameter optimisation and prediction; [`blocks`] holds what the
//! inducing-point approximation for large training sets (the `gp-sparse` crate) builds on.
//!
//! This crate depends on no other crate of the workspace: matrices in, matrices out. Inputs are
//! `n × d` faer matrices (one point per row), outputs `n × m` (one output per column, e.g. the six
//! components of a twist, `(v, ω)`).
//!
//! The method is the paper's Section III-B (Jing et al., Eqs. 4–7) with Rasmussen & Williams,
//! *Gaussian Processes for Machine Learning* (2006), for the algorithms: Cholesky-based prediction
//! (Algorithm 2.1), the log marginal likelihood (Eq. 2.30) and its gradient (Eq. 5.9).
//!
//! ```
//! use faer::Mat;
//! use gp::{ExactGp, GpConfig, KernelChoice};
//!
//! // y = sin(3x) on 30 points in [0, 2].
//! let x = Mat::from_fn(30, 1, |i, _| i as f64 / 15.0);
//! let y = Mat::from_fn(30, 1, |i, _| (3.0 * x[(i, 0)]).sin());
//! let config = GpConfig { kernel: KernelChoice::SquaredExponentialArd, ..GpConfig::default() };
//! let model = ExactGp::fit(x.as_ref(), y.as_ref(), &config)?;
//!
//! let query = Mat::from_fn(1, 1, |_, _| 1.01);
//! let prediction = model.predict(query.as_ref())?;
//! assert!((prediction.mean[(0, 0)] - (3.03f64).sin()).abs() < 1e-2);
//! assert!(prediction.variance[(0, 0)] < 1e-3);
//! # Ok::<(), gp::Error>(())
//! ```
#![deny(missing_docs)]

mod additive;
pub mod blocks;
mod cholesky;
mod config;
mod cross_gradient;
mod error;
mod exact;
mod fixed_folds;
mod gram;
mod kernel;
mod lml;
mod loo;
mod optimise;
mod points;
mod predict;
mod scaling;
mod subset;

pub use cholesky::JitterOutcome;
pub use config::{GpConfig, JitterConfig, OptimiserConfig, OutputMode, Parallelism};
pub use dense::FactorOptions;
pub use error::Error;
pub use exact::{AdditiveChoice, ComponentReport, ExactFitReport, ExactGp, IsotropicChoice};
pub use fixed_folds::FoldTargets;
pub use kernel::{
    AdditiveTerm, Bounds, CompositeKernel, Kernel, KernelChoice, Matern52Ard, QuadraticKernel, SquaredExponentialArd,
    StationaryShape,
};
pub use lml::{LmlWorkspace, LogMarginalLikelihood, log_marginal_likelihood};
pub use loo::LeaveOneOut;
pub use optimise::OptimisationReport;
pub use predict::{PredictOptions, Prediction};
pub use scaling::{InputStandardiser, OutputNormaliser};
