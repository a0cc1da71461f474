//! The stationary part of a covariance function as a function of `r²`, the squared distance of
//! two inputs already divided by their length scales.

use serde::{Deserialize, Serialize};

/// The family of the stationary (distance-based) term.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum StationaryShape {
    /// `exp(−r²/2)` (R&W Eq. 5.2): infinitely smooth.
    #[default]
    SquaredExponential,
    /// `(1 + √5 r + 5r²/3) exp(−√5 r)` (R&W Eq. 4.17): twice differentiable, rougher than the
    /// squared exponential, so it follows sharper features.
    Matern52,
}

const SQRT_5: f64 = 2.236_067_977_499_79;

impl StationaryShape {
    /// `σf² s(r²)`.
    #[inline]
    pub(crate) fn value(self, signal_variance: f64, r2: f64) -> f64 {
        match self {
            Self::SquaredExponential => signal_variance * (-0.5 * r2).exp(),
            Self::Matern52 => {
                let r = r2.sqrt();
                signal_variance * (1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * (-SQRT_5 * r).exp()
            }
        }
    }

    /// `σf² s(r²)` and the length-scale weight `m` such that `∂k/∂ln ℓᵢ = m (Δᵢ/ℓᵢ)²`.
    ///
    /// Squared exponential: `m = k`. Matérn 5/2: `dk/dr = −(5/3) σf² r (1 + √5 r) e^{−√5 r}` and
    /// `∂r/∂ln ℓᵢ = −(Δᵢ/ℓᵢ)²/r`, so `m = (5/3) σf² (1 + √5 r) e^{−√5 r}`: the `r` cancels and the
    /// derivative is smooth at `r = 0`.
    #[inline]
    pub(crate) fn value_and_weight(self, signal_variance: f64, r2: f64) -> (f64, f64) {
        match self {
            Self::SquaredExponential => {
                let k = signal_variance * (-0.5 * r2).exp();
                (k, k)
            }
            Self::Matern52 => {
                let r = r2.sqrt();
                let e = signal_variance * (-SQRT_5 * r).exp();
                ((1.0 + SQRT_5 * r + 5.0 / 3.0 * r2) * e, 5.0 / 3.0 * (1.0 + SQRT_5 * r) * e)
            }
        }
    }
}
