//! The local product-of-exponentials (POE) kinematic model of a serial robot and its
//! identification (Jing, Tao, Yang, Shimada, Section III-A; Chen, Yang et al. 2001).
//!
//! A joint is a constant local transform `T_{i-1,i}(0) = exp(p̂_i)` followed by a motion about or
//! along that frame's z axis, `exp(ŝ_i q_i)`; the tool hangs from the last joint frame by
//! `T_{n,n+1}(0)`. Every geometric error is a change of the constant transforms, which the
//! identification finds from measured tool poses or positions.
//!
//! Conventions: SI units; twists `(v, ω)`; left perturbations `T ← exp(δ̂) T`, so the
//! identification residual is `y = log(T' T⁻¹)^∨` (paper Section III-A-2).
//!
//! ```
//! use poe::{DhConvention, DhRow, JointKind, LocalPoe};
//! use std::f64::consts::FRAC_PI_2;
//!
//! // A planar two-link arm, standard DH.
//! let row = |a| DhRow { kind: JointKind::Revolute, a, alpha: 0.0, d: 0.0, theta: 0.0 };
//! let arm = LocalPoe::from_dh(&[row(1.0), row(0.5)], DhConvention::Standard);
//! let tool = arm.forward(&[FRAC_PI_2, 0.0], 0).unwrap();
//! assert!((tool.translation() - lie::Vector3::new(0.0, 1.5, 0.0)).norm() < 1e-12);
//! ```
#![deny(missing_docs)]

mod dh;
mod error;
pub mod identify;
mod jacobian;
mod joint;
mod layout;
mod model;

pub use dh::{DhConvention, DhRow};
pub use error::Error;
pub use jacobian::RowKind;
pub use joint::{Joint, JointKind};
pub use layout::{Block, ParameterLayout};
pub use model::{JointAxis, LocalPoe};
