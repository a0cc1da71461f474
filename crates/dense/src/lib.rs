//! The dense numerics the Gaussian process is made of, below any notion of a kernel or a
//! hyperparameter: the Cholesky factorisation by halves, products and triangular solves whose
//! results do not depend on the thread count, and the vectorised loops of the squared exponential
//! (a branch-free exponential, `pulp`'s run-time dispatch, fixed-order partial sums), and
//! k-means' nearest-centre assignment.
//!
//! Invariant: every function gives the same bits whatever the number of threads it is given or
//! runs on (on one machine; a processor without AVX2 + FMA rounds differently in the last bits).
#![deny(missing_docs)]

mod cholesky;
mod exp;
pub mod nearest;
pub mod one_input;
mod products;
pub mod stationary;

pub use cholesky::{FactorOptions, cholesky_lower_in_place};
pub use exp::{LANES, exp_nonpositive, pairwise};
pub use products::{product, solve_lower, solve_upper_transposed};
