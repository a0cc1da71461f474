//! Matérn ν = 5/2 kernel with one length scale per input, Rasmussen & Williams Eq. 4.17, plus white
//! noise.

use serde::{Deserialize, Serialize};

/// ARD Matérn 5/2 kernel `σf² (1 + √5 r + 5r²/3) exp(−√5 r)`, `r² = Σᵢ (xᵢ − x'ᵢ)²/ℓᵢ²`, plus a
/// white-noise term.
///
/// Log-parameter order: `ln σf², ln ℓ₁ … ln ℓ_d, ln σn²`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Matern52Ard {
    /// Signal variance `σf²`.
    pub signal_variance: f64,
    /// One length scale per input dimension.
    pub length_scales: Vec<f64>,
    /// Variance of the white noise added on the diagonal of the training covariance.
    pub noise_variance: f64,
}

const SQRT_5: f64 = 2.236_067_977_499_79;

impl Matern52Ard {
    /// A neutral start for `dim` standardised inputs and normalised outputs.
    pub fn isotropic_start(dim: usize) -> Self {
        Self { signal_variance: 1.0, length_scales: vec![1.0; dim], noise_variance: 0.01 }
    }

    /// `k` and the exponential `e = e^{−√5 r}` from the squared distance `r²` of inputs already
    /// divided by their length scales (R&W Eq. 4.17).
    #[inline]
    pub(crate) fn value_and_exponential(signal_variance: f64, r2: f64) -> (f64, f64) {
        let r = r2.sqrt();
        let e = (-SQRT_5 * r).exp();
        (signal_variance * (1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * e, e)
    }

    /// `k` and the length-scale weight `m`, given `e`, such that `∂k/∂ln ℓᵢ = m (Δᵢ/ℓᵢ)²`.
    ///
    /// `dk/dr = −(5/3) σf² r (1 + √5 r) e^{−√5 r}` and `∂r/∂ln ℓᵢ = −(Δᵢ/ℓᵢ)²/r`, so
    /// `m = (5/3) σf² (1 + √5 r) e^{−√5 r}`: the `r` cancels and the derivative is smooth at
    /// `r = 0`. `∂k/∂ln σf² = k`.
    #[inline]
    pub(crate) fn value_and_weight(signal_variance: f64, r2: f64, e: f64) -> (f64, f64) {
        let r = r2.sqrt();
        let k = signal_variance * (1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * e;
        (k, 5.0 / 3.0 * signal_variance * (1.0 + SQRT_5 * r) * e)
    }
}
