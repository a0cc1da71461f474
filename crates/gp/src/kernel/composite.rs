//! The paper's Eq. 5 with every term in its ARD form: a constant, a linear term with one weight per
//! input, a squared exponential or Matérn 5/2 term with one length scale per input, and white
//! noise.

use serde::{Deserialize, Serialize};

use super::StationaryShape;

/// `k(x, x') = σc² + Σᵢ wᵢ xᵢ x'ᵢ + σf² s(r) + σn² δ`, `r² = Σᵢ (xᵢ − x'ᵢ)²/ℓᵢ²`.
///
/// Eq. 5 of the paper (Bishop PRML Eq. 6.63) is the special case of one length scale, one linear
/// weight and the squared exponential. The constant and the linear term are optional; without them
/// this is [`super::SquaredExponentialArd`] or [`super::Matern52Ard`].
///
/// Log-parameter order: `ln σf², ln ℓ₁ … ln ℓ_d`, then `ln σc²` if there is a constant, then
/// `ln w₁ … ln w_d` if there is a linear term, and `ln σn²` last.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CompositeKernel {
    /// Family of the stationary term.
    pub shape: StationaryShape,
    /// Variance `σf²` of the stationary term.
    pub signal_variance: f64,
    /// One length scale per input dimension.
    pub length_scales: Vec<f64>,
    /// Variance `σc²` of the constant term (a random offset of the whole function).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub constant: Option<f64>,
    /// Weights `wᵢ` of the linear term, one per input (the prior variance of the slope in input `i`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub linear_weights: Option<Vec<f64>>,
    /// Variance of the white noise added on the diagonal of the training covariance.
    pub noise_variance: f64,
}

impl CompositeKernel {
    /// A neutral start for `dim` standardised inputs and normalised outputs: unit length scales and
    /// signal, small constant and slopes, one percent noise (as the other kernels' starts).
    pub fn start(shape: StationaryShape, dim: usize, constant: bool, linear: bool) -> Self {
        Self {
            shape,
            signal_variance: 1.0,
            length_scales: vec![1.0; dim],
            constant: constant.then_some(0.1),
            linear_weights: linear.then(|| vec![0.1; dim]),
            noise_variance: 0.01,
        }
    }
}
