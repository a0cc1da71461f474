//! Lie group algebra for rigid motion: SO(3), SE(3) and the tangent space se(3), as concrete
//! `f64` types on nalgebra's fixed-size matrices.
//!
//! # Conventions
//! Stated once here, for the whole crate (and checked by `tests/conventions.rs`).
//!
//! - **Tangent order.** A tangent vector of SE(3) (a [`Twist`]) is ordered `(v, ω)`: translation
//!   first, rotation second, in vectors, in Jacobian rows and columns and in adjoints.
//! - **Perturbation side: left.** A pose is perturbed as `T' = exp(δ^) · T`, and the error between
//!   two poses is `log(T' · T⁻¹)^∨` (the paper's `y_i`): δ is expressed in the frame that `T` maps
//!   into (for `base_from_tool`, the base frame).
//! - **Jacobians.** Consequently the derivative of a map `f` between groups is
//!   `Df(T) = ∂ log(f(exp(δ^) T) · f(T)⁻¹)^∨ / ∂δ` at `δ = 0`, and of a map into a vector space
//!   `∂ f(exp(δ^) T) / ∂δ`. With this convention:
//!   - `∂ exp(ξ) / ∂ξ = J_l(ξ)`, the **left Jacobian**: `exp(ξ + δ) ≈ exp(J_l(ξ) δ) · exp(ξ)`;
//!   - `∂ log(T) / ∂T = J_l⁻¹(log T)`: `log(exp(δ) · T) ≈ log T + J_l⁻¹(log T) δ`;
//!   - the **right Jacobian** serves right perturbations: `exp(ξ + δ) ≈ exp(ξ) · exp(J_r(ξ) δ)`,
//!     with `J_r(ξ) = J_l(−ξ)` and `J_l(ξ) = Ad(exp ξ) · J_r(ξ)`;
//!   - `∂(T · U)/∂T = I`, `∂(T · U)/∂U = Ad(T)`, `∂ T⁻¹/∂T = −Ad(T⁻¹)`;
//!   - for the action on a point, `∂ (T x) / ∂δ = [I, −(T x)^]` (3×6, `(v, ω)` columns).
//!
//!   The same holds for SO(3) with `ω` alone, `Ad(R) = R` and `∂(R x)/∂δ = −(R x)^`.
//! - **Adjoint.** `Ad(T) ξ = (T ξ^ T⁻¹)^∨`, so that `T · exp(ξ) = exp(Ad(T) ξ) · T`; and
//!   `ad(ξ) η = [ξ^, η^]^∨`, with `Ad(exp ξ) = exp(ad ξ)`.
//! - **Names.** A transform named `a_from_b` maps coordinates in frame `b` into frame `a`.
//!
//! ```
//! use lie::{SE3, Twist, Vector3};
//!
//! let xi = Twist::new(Vector3::new(0.1, -0.2, 0.3), Vector3::new(0.4, 0.1, -0.2));
//! let t = xi.exp();
//! assert!((t.log().to_vector() - xi.to_vector()).norm() < 1e-12);
//! // A right perturbation moved to the left through the adjoint.
//! let d = Twist::new(Vector3::new(0.01, 0.0, 0.0), Vector3::new(0.0, 0.02, 0.0));
//! let lhs = t * d.exp();
//! let rhs = SE3::exp(&Twist::from_vector(&(t.adjoint() * d.to_vector()))) * t;
//! assert!((lhs.to_matrix() - rhs.to_matrix()).norm() < 1e-12);
//! ```
#![deny(missing_docs)]

mod coefficients;
mod error;
mod jacobians;
mod se3;
mod so3;
mod twist;

pub use error::Error;
pub use se3::SE3;
pub use so3::{ORTHONORMALITY_TOLERANCE, SO3};
pub use twist::Twist;

/// A 3-vector of `f64`.
pub type Vector3 = nalgebra::Vector3<f64>;
/// A 6-vector of `f64`, a twist in `(v, ω)` order.
pub type Vector6 = nalgebra::Vector6<f64>;
/// A 3×3 matrix of `f64`.
pub type Matrix3 = nalgebra::Matrix3<f64>;
/// A 4×4 matrix of `f64`.
pub type Matrix4 = nalgebra::Matrix4<f64>;
/// A 6×6 matrix of `f64`.
pub type Matrix6 = nalgebra::Matrix6<f64>;
