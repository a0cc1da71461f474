//! The exact GP's building blocks that an approximation of it reuses (the sparse GP of the
//! `gp-sparse` crate): points prepared for a kernel, covariance blocks and the contraction of
//! their gradient, Cholesky factors with jitter, and the checks and seeded subsets every fit
//! shares. Fitting and predicting with the exact GP needs none of it.

pub use crate::cholesky::Factor;
pub use crate::cross_gradient::contract_cross;
pub use crate::exact::{check_served, validate_training_data};
pub use crate::gram::{cross_covariance, full_covariance, prior_variances, training_covariance};
pub use crate::kernel::{Evaluator, Expanded, Prepared};
pub use crate::lml::check_finite_outputs;
pub use crate::points::Points;
pub use crate::subset::random_indices;
