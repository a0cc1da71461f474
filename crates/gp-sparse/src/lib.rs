//! The sparse variational Gaussian process for training sets beyond a few thousand rows: `m`
//! inducing inputs, `O(n m²)` time and `O(m² + chunk·m)` memory besides the data (Titsias 2009),
//! built on the exact GP of the `gp` crate (its kernels, covariance blocks, factorisations and,
//! for the first hyperparameters, its fit on a subset).
//!
//! A crate of its own so that a user of the exact GP alone depends on `gp` only.
//!
//! ```
//! use faer::Mat;
//! use gp::{GpConfig, KernelChoice};
//! use gp_sparse::{SparseConfig, SparseGp};
//!
//! // y = sin(3x) on 200 points in [0, 2], 20 inducing inputs.
//! let x = Mat::from_fn(200, 1, |i, _| i as f64 / 100.0);
//! let y = Mat::from_fn(200, 1, |i, _| (3.0 * x[(i, 0)]).sin());
//! let gp = GpConfig { kernel: KernelChoice::SquaredExponentialArd, ..GpConfig::default() };
//! let config = SparseConfig { gp, inducing_points: 20, hyperparameter_subset: 100, ..SparseConfig::default() };
//! let model = SparseGp::fit(x.as_ref(), y.as_ref(), &config)?;
//!
//! let query = Mat::from_fn(1, 1, |_, _| 1.01);
//! let prediction = model.predict(query.as_ref())?;
//! assert!((prediction.mean[(0, 0)] - (3.03f64).sin()).abs() < 1e-2);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![deny(missing_docs)]

mod elbo;
mod error;
mod inducing;
mod sparse;

pub use elbo::sparse_evidence_lower_bound;
pub use error::Error;
pub use inducing::InducingSelection;
pub use sparse::{SparseComponentReport, SparseConfig, SparseFitReport, SparseGp};
