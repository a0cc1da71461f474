//! Gaussian process regression on plain matrices: kernels with analytic gradients,
//! log marginal likelihood, hyperparameter optimisation and prediction.
//!
//! This crate depends on neither `lie` nor `poe`: matrices in, matrices out.
#![deny(missing_docs)]
