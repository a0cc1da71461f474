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

impl Matern52Ard {
    /// A neutral start for `dim` standardised inputs and normalised outputs.
    pub fn isotropic_start(dim: usize) -> Self {
        Self { signal_variance: 1.0, length_scales: vec![1.0; dim], noise_variance: 0.01 }
    }
}
