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

    /// `k` on inputs already divided by their length scales (R&W Eq. 4.17).
    #[inline]
    pub(crate) fn value_scaled(signal_variance: f64, a: &[f64], b: &[f64]) -> f64 {
        let r2 = super::squared_distance(a, b);
        let r = r2.sqrt();
        signal_variance * (1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * (-SQRT_5 * r).exp()
    }

    /// `k` and the exponential `e^{−√5 r}` on inputs already divided by their length scales.
    #[inline]
    pub(crate) fn value_and_exponential(signal_variance: f64, a: &[f64], b: &[f64]) -> (f64, f64) {
        let r2 = super::squared_distance(a, b);
        let r = r2.sqrt();
        let e = (-SQRT_5 * r).exp();
        (signal_variance * (1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * e, e)
    }

    /// Derivatives given `e = e^{−√5 r}`, on inputs already divided by their length scales.
    ///
    /// `dk/dr = −(5/3) σf² r (1 + √5 r) e^{−√5 r}` and `∂r/∂ln ℓᵢ = −(Δᵢ/ℓᵢ)²/r`, so
    /// `∂k/∂ln ℓᵢ = (5/3) σf² (1 + √5 r) e^{−√5 r} (Δᵢ/ℓᵢ)²`: the `r` cancels and the derivative is
    /// smooth at `r = 0`. `∂k/∂ln σf² = k`.
    #[inline]
    pub(crate) fn gradient_from_exponential(signal_variance: f64, a: &[f64], b: &[f64], e: f64, gradient: &mut [f64]) {
        let r2 = super::squared_distance(a, b);
        let r = r2.sqrt();
        gradient[0] = signal_variance * (1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * e;
        let common = 5.0 / 3.0 * signal_variance * (1.0 + SQRT_5 * r) * e;
        for ((g, x), y) in gradient[1..].iter_mut().zip(a).zip(b) {
            let d = x - y;
            *g = common * d * d;
        }
    }
}
