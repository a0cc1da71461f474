//! The paper's Eq. 5 with every term in its ARD form: a constant, a linear term with one weight per
//! input, a squared exponential or Matérn 5/2 term with one length scale per input, and white
//! noise; optionally a first-order additive term (one one-dimensional stationary kernel per input).

use serde::{Deserialize, Serialize};

use super::StationaryShape;

/// `k(x, x') = σc² + Σᵢ wᵢ xᵢ x'ᵢ + σf² s(r²) + Σᵢ aᵢ s((xᵢ − x'ᵢ)²/bᵢ²) + σn² δ`,
/// `r² = Σᵢ (xᵢ − x'ᵢ)²/ℓᵢ²`.
///
/// Eq. 5 of the paper (Bishop PRML Eq. 6.63) is the special case of one length scale, one linear
/// weight and the squared exponential. The constant, the linear and the additive term are
/// optional; without them this is [`super::SquaredExponentialArd`] or [`super::Matern52Ard`].
///
/// The additive term (Duvenaud, Nickisch, Rasmussen, "Additive Gaussian processes", NIPS 2011,
/// its first order) is a sum of one-dimensional kernels, one per input, each with its own variance
/// `aᵢ` and length scale `bᵢ`. It lets a function that varies quickly along one input — a gear's
/// periodic error along its joint angle — be learnt from the poses that vary that input alone,
/// where the joint ARD term would need poses close in every input at once.
///
/// Log-parameter order: `ln σf², ln ℓ₁ … ln ℓ_d`, then `ln σc²` if there is a constant, then
/// `ln w₁ … ln w_d` if there is a linear term, then `ln a₁ … ln a_d, ln b₁ … ln b_d` if there is an
/// additive term, and `ln σn²` last.
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
    /// The first-order additive term, one one-dimensional kernel per input.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub additive: Option<AdditiveTerm>,
    /// Variance of the white noise added on the diagonal of the training covariance.
    pub noise_variance: f64,
}

impl CompositeKernel {
    /// A neutral start for `dim` standardised inputs and normalised outputs: unit length scales and
    /// signal, small constant and slopes, one percent noise (as the other kernels' starts); the
    /// additive term starts with a tenth of the variance in each input and a short length scale
    /// (0.3 standard deviations), so that its gradient is not flat at the start.
    pub fn start(shape: StationaryShape, dim: usize, constant: bool, linear: bool, additive: bool) -> Self {
        Self {
            shape,
            signal_variance: 1.0,
            length_scales: vec![1.0; dim],
            constant: constant.then_some(0.1),
            linear_weights: linear.then(|| vec![0.1; dim]),
            additive: additive.then(|| AdditiveTerm { variances: vec![0.1; dim], length_scales: vec![0.3; dim] }),
            noise_variance: 0.01,
        }
    }
}

/// `Σᵢ aᵢ s((xᵢ − x'ᵢ)²/bᵢ²)`: one one-dimensional kernel of the composite's shape per input.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AdditiveTerm {
    /// `aᵢ`, the variance each input's own term explains.
    pub variances: Vec<f64>,
    /// `bᵢ`, each input's own length scale.
    pub length_scales: Vec<f64>,
}

impl AdditiveTerm {
    /// The variance of each input's term in the start that nearly switches the term off: 1e-4 of
    /// the normalised output variance, negligible beside the stationary term yet 100 times above
    /// the lower bound, so that the search can still grow it.
    pub const OFF_VARIANCE: f64 = 1e-4;
}
