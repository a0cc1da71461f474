//! The paper's covariance function (Jing et al., Eq. 5), which is Bishop's PRML Eq. 6.63:
//! `k(x, x') = θ0 exp(−θ1 ‖x − x'‖² / 2) + θ2 + θ3 xᵀx'`, plus white noise.

use serde::{Deserialize, Serialize};

/// Bishop's "quadratic form" kernel (PRML Eq. 6.63, the paper's Eq. 5) plus a white-noise term.
///
/// All five numbers are on their natural scale and must be strictly positive; the optimiser works
/// on their logarithms in the order `θ0, θ1, θ2, θ3, noise_variance`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct QuadraticKernel {
    /// Amplitude of the exponential (squared-exponential) part.
    pub theta0: f64,
    /// Inverse squared length scale of the exponential part (`θ1 = 1/ℓ²`).
    pub theta1: f64,
    /// Constant (bias) term.
    pub theta2: f64,
    /// Weight of the linear term `xᵀx'`.
    pub theta3: f64,
    /// Variance of the white noise added on the diagonal of the training covariance.
    pub noise_variance: f64,
}

impl Default for QuadraticKernel {
    /// A neutral start on standardised inputs and normalised outputs: unit length scale, small bias,
    /// small linear part, one percent noise.
    fn default() -> Self {
        Self { theta0: 1.0, theta1: 1.0, theta2: 0.1, theta3: 0.1, noise_variance: 0.01 }
    }
}

/// Number of kernel parameters (noise excluded).
pub(crate) const PARAMETERS: usize = 4;

impl QuadraticKernel {
    /// Natural-scale parameters in log-parameter order (noise last).
    pub(crate) fn parameters(&self) -> [f64; PARAMETERS + 1] {
        [self.theta0, self.theta1, self.theta2, self.theta3, self.noise_variance]
    }

    /// Builds the kernel from natural-scale parameters in log-parameter order (noise last).
    pub(crate) fn from_parameters(p: &[f64]) -> Self {
        Self { theta0: p[0], theta1: p[1], theta2: p[2], theta3: p[3], noise_variance: p[4] }
    }

    /// Default search box on standardised inputs and normalised outputs, natural scale.
    pub(crate) fn default_bounds() -> ([f64; PARAMETERS + 1], [f64; PARAMETERS + 1]) {
        // θ1 in [1e-4, 1e2] is a length scale between 0.1 and 100 standard deviations of the input;
        // the noise may go down to 1e-9 so that nearly noiseless data can be interpolated.
        ([1e-3, 1e-4, 1e-6, 1e-6, 1e-9], [1e2, 1e2, 1e2, 1e2, 1e1])
    }
}
