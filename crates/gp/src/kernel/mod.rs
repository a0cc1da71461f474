//! Covariance functions, each with a white-noise term and analytic gradients with respect to the
//! logarithms of its parameters.
//!
//! Every parameter is positive and the optimiser works on `ln p`, so `∂k/∂ln p = p ∂k/∂p`. The
//! noise variance is always the last log-parameter; it adds `σn² δᵢⱼ` to the training covariance
//! only (same index, not same location, as scikit-learn's `WhiteKernel`).

mod matern52;
mod quadratic;
mod squared_exponential;

pub use matern52::Matern52Ard;
pub use quadratic::QuadraticKernel;
pub use squared_exponential::SquaredExponentialArd;

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::points::Points;

/// Which covariance family to fit, without its numbers (a configuration choice).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum KernelChoice {
    /// The paper's Eq. 5 (Bishop PRML Eq. 6.63), see [`QuadraticKernel`].
    #[default]
    Quadratic,
    /// ARD squared exponential, see [`SquaredExponentialArd`].
    SquaredExponentialArd,
    /// ARD Matérn 5/2, see [`Matern52Ard`].
    Matern52Ard,
}

/// A covariance function with its hyperparameters, white noise included.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Kernel {
    /// The paper's Eq. 5.
    Quadratic(QuadraticKernel),
    /// ARD squared exponential.
    SquaredExponentialArd(SquaredExponentialArd),
    /// ARD Matérn 5/2.
    Matern52Ard(Matern52Ard),
}

/// A box on the kernel's parameters, natural scale (not log), in log-parameter order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Lower bounds, all > 0.
    pub lower: Vec<f64>,
    /// Upper bounds, each ≥ its lower bound.
    pub upper: Vec<f64>,
}

impl Kernel {
    /// The default starting point of `choice` for `dim` standardised inputs and normalised outputs.
    pub fn start(choice: KernelChoice, dim: usize) -> Self {
        match choice {
            KernelChoice::Quadratic => Self::Quadratic(QuadraticKernel::default()),
            KernelChoice::SquaredExponentialArd => {
                Self::SquaredExponentialArd(SquaredExponentialArd::isotropic_start(dim))
            }
            KernelChoice::Matern52Ard => Self::Matern52Ard(Matern52Ard::isotropic_start(dim)),
        }
    }

    /// The family of this kernel.
    pub fn choice(&self) -> KernelChoice {
        match self {
            Self::Quadratic(_) => KernelChoice::Quadratic,
            Self::SquaredExponentialArd(_) => KernelChoice::SquaredExponentialArd,
            Self::Matern52Ard(_) => KernelChoice::Matern52Ard,
        }
    }

    /// Input dimension the kernel is tied to (`None` for the isotropic Eq. 5 kernel).
    pub fn input_dim(&self) -> Option<usize> {
        match self {
            Self::Quadratic(_) => None,
            Self::SquaredExponentialArd(k) => Some(k.length_scales.len()),
            Self::Matern52Ard(k) => Some(k.length_scales.len()),
        }
    }

    /// Number of log-parameters, noise included.
    pub fn parameter_count(&self) -> usize {
        match self {
            Self::Quadratic(_) => quadratic::PARAMETERS + 1,
            Self::SquaredExponentialArd(k) => k.length_scales.len() + 2,
            Self::Matern52Ard(k) => k.length_scales.len() + 2,
        }
    }

    /// The white-noise variance `σn²`.
    pub fn noise_variance(&self) -> f64 {
        match self {
            Self::Quadratic(k) => k.noise_variance,
            Self::SquaredExponentialArd(k) => k.noise_variance,
            Self::Matern52Ard(k) => k.noise_variance,
        }
    }

    /// Natural-scale parameters in log-parameter order (noise last).
    pub fn parameters(&self) -> Vec<f64> {
        match self {
            Self::Quadratic(k) => k.parameters().to_vec(),
            Self::SquaredExponentialArd(SquaredExponentialArd { signal_variance, length_scales, noise_variance })
            | Self::Matern52Ard(Matern52Ard { signal_variance, length_scales, noise_variance }) => {
                let mut p = Vec::with_capacity(length_scales.len() + 2);
                p.push(*signal_variance);
                p.extend_from_slice(length_scales);
                p.push(*noise_variance);
                p
            }
        }
    }

    /// `ln` of [`Kernel::parameters`]: the coordinates the optimiser and the gradients use.
    pub fn log_parameters(&self) -> Vec<f64> {
        self.parameters().iter().map(|p| p.ln()).collect()
    }

    /// The same family with parameters `exp(log_parameters)`.
    pub fn with_log_parameters(&self, log_parameters: &[f64]) -> Result<Self, Error> {
        let natural: Vec<f64> = log_parameters.iter().map(|p| p.exp()).collect();
        self.with_parameters(&natural)
    }

    /// The same family with natural-scale `parameters` (log-parameter order, noise last).
    pub fn with_parameters(&self, parameters: &[f64]) -> Result<Self, Error> {
        let expected = self.parameter_count();
        if parameters.len() != expected {
            return Err(Error::ParameterCountMismatch { expected, found: parameters.len() });
        }
        if let Some((index, &value)) = parameters.iter().enumerate().find(|(_, p)| !(p.is_finite() && **p > 0.0)) {
            return Err(Error::InvalidHyperparameter { index, value });
        }
        let n = parameters.len();
        Ok(match self {
            Self::Quadratic(_) => Self::Quadratic(QuadraticKernel::from_parameters(parameters)),
            Self::SquaredExponentialArd(_) => Self::SquaredExponentialArd(SquaredExponentialArd {
                signal_variance: parameters[0],
                length_scales: parameters[1..n - 1].to_vec(),
                noise_variance: parameters[n - 1],
            }),
            Self::Matern52Ard(_) => Self::Matern52Ard(Matern52Ard {
                signal_variance: parameters[0],
                length_scales: parameters[1..n - 1].to_vec(),
                noise_variance: parameters[n - 1],
            }),
        })
    }

    /// Checks that every parameter is finite and positive and that an ARD kernel matches `dim`.
    pub fn validate(&self, dim: usize) -> Result<(), Error> {
        if let Some(expected) = self.input_dim()
            && expected != dim
        {
            return Err(Error::InputDimensionMismatch { expected, found: dim });
        }
        self.with_parameters(&self.parameters()).map(|_| ())
    }

    /// The default search box for this family, for standardised inputs and normalised outputs.
    pub fn default_bounds(&self) -> Bounds {
        match self {
            Self::Quadratic(_) => {
                let (lower, upper) = QuadraticKernel::default_bounds();
                Bounds { lower: lower.to_vec(), upper: upper.to_vec() }
            }
            Self::SquaredExponentialArd(SquaredExponentialArd { length_scales, .. })
            | Self::Matern52Ard(Matern52Ard { length_scales, .. }) => {
                // Length scales from 1/100 to 1000 standard deviations of the input; beyond the
                // upper end the input is irrelevant and the likelihood is flat.
                let d = length_scales.len();
                let mut lower = vec![1e-3];
                lower.extend(std::iter::repeat_n(1e-2, d));
                lower.push(1e-9);
                let mut upper = vec![1e2];
                upper.extend(std::iter::repeat_n(1e3, d));
                upper.push(1e1);
                Bounds { lower, upper }
            }
        }
    }

    /// `k(a, b)` without the noise term.
    pub fn value(&self, a: &[f64], b: &[f64]) -> f64 {
        let (evaluator, scale) = self.evaluator();
        match scale {
            None => evaluator.value(a, b),
            Some(s) => evaluator.value(&scale_point(a, &s), &scale_point(b, &s)),
        }
    }

    /// `k(a, b)` without noise, and `∂k/∂ln p` for every log-parameter but the noise, written into
    /// `gradient` (length [`Kernel::parameter_count`] − 1).
    pub fn value_and_gradient(&self, a: &[f64], b: &[f64], gradient: &mut [f64]) -> Result<f64, Error> {
        let expected = self.parameter_count() - 1;
        if gradient.len() != expected {
            return Err(Error::ParameterCountMismatch { expected, found: gradient.len() });
        }
        let (evaluator, scale) = self.evaluator();
        Ok(match scale {
            None => evaluator.value_and_gradient(a, b, gradient),
            Some(s) => evaluator.value_and_gradient(&scale_point(a, &s), &scale_point(b, &s), gradient),
        })
    }

    /// The evaluator used in the hot loops, and the per-coordinate factor (`1/ℓ`) that inputs must
    /// be multiplied by before it sees them (`None` for Eq. 5, which reads raw inputs).
    pub(crate) fn evaluator(&self) -> (Evaluator, Option<Vec<f64>>) {
        match self {
            Self::Quadratic(k) => (Evaluator::Quadratic(*k), None),
            Self::SquaredExponentialArd(k) => (
                Evaluator::SquaredExponential(SquaredExponentialScaled { signal_variance: k.signal_variance }),
                Some(k.length_scales.iter().map(|l| 1.0 / l).collect()),
            ),
            Self::Matern52Ard(k) => (
                Evaluator::Matern52(Matern52Scaled { signal_variance: k.signal_variance }),
                Some(k.length_scales.iter().map(|l| 1.0 / l).collect()),
            ),
        }
    }

    /// The evaluator and `points` prepared for it (divided by the length scales for ARD kernels).
    pub(crate) fn prepare(&self, points: &Points) -> (Evaluator, Points) {
        let (evaluator, scale) = self.evaluator();
        let prepared = match scale {
            None => points.clone(),
            Some(s) => points.scaled_columns(&s),
        };
        (evaluator, prepared)
    }
}

impl Bounds {
    /// Checks `0 < lower ≤ upper < ∞` and the length against `kernel`, and returns the bounds in
    /// log space.
    pub(crate) fn to_log(&self, kernel: &Kernel) -> Result<(Vec<f64>, Vec<f64>), Error> {
        let expected = kernel.parameter_count();
        for found in [self.lower.len(), self.upper.len()] {
            if found != expected {
                return Err(Error::ParameterCountMismatch { expected, found });
            }
        }
        for (index, (&lower, &upper)) in self.lower.iter().zip(&self.upper).enumerate() {
            if !(lower > 0.0 && lower <= upper && upper.is_finite()) {
                return Err(Error::InvalidBounds { index, lower, upper });
            }
        }
        Ok((self.lower.iter().map(|v| v.ln()).collect(), self.upper.iter().map(|v| v.ln()).collect()))
    }
}

/// A kernel ready for the inner loops: its inputs have been prepared by [`Kernel::prepare`].
#[derive(Debug, Clone, Copy)]
pub(crate) enum Evaluator {
    Quadratic(QuadraticKernel),
    SquaredExponential(SquaredExponentialScaled),
    Matern52(Matern52Scaled),
}

/// The squared exponential on inputs already divided by their length scales.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SquaredExponentialScaled {
    pub(crate) signal_variance: f64,
}

/// The Matérn 5/2 on inputs already divided by their length scales.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Matern52Scaled {
    pub(crate) signal_variance: f64,
}

/// One covariance function on prepared inputs, as a function of the pair's squared distance `r²`
/// and inner product `xᵀx'` (both come from one matrix product, see `gram`), monomorphised into
/// the Gram-matrix loops.
///
/// The likelihood gradient needs every pair's kernel gradient; `value_and_cache` returns with the
/// value the one number (the exponential factor) that makes the gradient free of `exp`.
pub(crate) trait PairKernel: Sync {
    /// Log-parameters differentiated pair by pair (first in the log-parameter order); any further
    /// ones, up to the noise, are ARD length scales.
    const SCALARS: usize;
    /// `k` without noise.
    fn value(&self, r2: f64, dot: f64) -> f64;
    /// `k` without noise and the cached factor for [`PairKernel::gradient_from_cache`].
    fn value_and_cache(&self, r2: f64, dot: f64) -> (f64, f64);
    /// `∂k/∂ln p` for the first [`PairKernel::SCALARS`] log-parameters, written to `scalars`; returns
    /// the length-scale weight `m` with `∂k/∂ln ℓᵢ = m (Δᵢ/ℓᵢ)²` (0 without length scales).
    fn gradient_from_cache(&self, r2: f64, dot: f64, cache: f64, scalars: &mut [f64]) -> f64;
}

impl PairKernel for QuadraticKernel {
    const SCALARS: usize = quadratic::PARAMETERS;
    #[inline]
    fn value(&self, r2: f64, dot: f64) -> f64 {
        self.value_from(r2, dot)
    }
    #[inline]
    fn value_and_cache(&self, r2: f64, dot: f64) -> (f64, f64) {
        self.value_and_exponential(r2, dot)
    }
    #[inline]
    fn gradient_from_cache(&self, r2: f64, dot: f64, cache: f64, scalars: &mut [f64]) -> f64 {
        self.gradient_from_exponential(r2, dot, cache, scalars);
        0.0
    }
}

impl PairKernel for SquaredExponentialScaled {
    const SCALARS: usize = 1;
    #[inline]
    fn value(&self, r2: f64, _dot: f64) -> f64 {
        SquaredExponentialArd::value_scaled(self.signal_variance, r2)
    }
    #[inline]
    fn value_and_cache(&self, r2: f64, dot: f64) -> (f64, f64) {
        let k = self.value(r2, dot);
        (k, k)
    }
    #[inline]
    fn gradient_from_cache(&self, _r2: f64, _dot: f64, cache: f64, scalars: &mut [f64]) -> f64 {
        scalars[0] = cache;
        cache
    }
}

impl PairKernel for Matern52Scaled {
    const SCALARS: usize = 1;
    #[inline]
    fn value(&self, r2: f64, _dot: f64) -> f64 {
        Matern52Ard::value_and_exponential(self.signal_variance, r2).0
    }
    #[inline]
    fn value_and_cache(&self, r2: f64, _dot: f64) -> (f64, f64) {
        Matern52Ard::value_and_exponential(self.signal_variance, r2)
    }
    #[inline]
    fn gradient_from_cache(&self, r2: f64, _dot: f64, cache: f64, scalars: &mut [f64]) -> f64 {
        let (k, weight) = Matern52Ard::value_and_weight(self.signal_variance, r2, cache);
        scalars[0] = k;
        weight
    }
}

/// Runs `$body` with `$k` bound to the concrete [`PairKernel`] inside `$evaluator`, so that the
/// loops in `$body` are compiled once per kernel with no dispatch per pair.
macro_rules! with_pair_kernel {
    ($evaluator:expr, $k:ident => $body:expr) => {
        match $evaluator {
            $crate::kernel::Evaluator::Quadratic($k) => $body,
            $crate::kernel::Evaluator::SquaredExponential($k) => $body,
            $crate::kernel::Evaluator::Matern52($k) => $body,
        }
    };
}
pub(crate) use with_pair_kernel;

/// `‖a − b‖²` and `aᵀb`.
#[inline]
fn distance_and_dot(a: &[f64], b: &[f64]) -> (f64, f64) {
    a.iter().zip(b).fold((0.0, 0.0), |(r2, dot), (x, y)| (r2 + (x - y) * (x - y), dot + x * y))
}

impl Evaluator {
    /// `k(a, b)` without noise, on prepared points.
    #[inline]
    pub(crate) fn value(&self, a: &[f64], b: &[f64]) -> f64 {
        let (r2, dot) = distance_and_dot(a, b);
        with_pair_kernel!(self, k => k.value(r2, dot))
    }

    /// `k(a, b)` without noise and its gradient in the kernel's log-parameters (noise excluded),
    /// on prepared points.
    pub(crate) fn value_and_gradient(&self, a: &[f64], b: &[f64], gradient: &mut [f64]) -> f64 {
        let (r2, dot) = distance_and_dot(a, b);
        with_pair_kernel!(self, k => {
            let (value, cache) = k.value_and_cache(r2, dot);
            let scalars = k.gradient_from_cache(r2, dot, cache, gradient);
            fill_length_scale_gradient(scalars, a, b, gradient, k_scalars(k));
            value
        })
    }
}

fn k_scalars<K: PairKernel>(_: &K) -> usize {
    K::SCALARS
}

/// `∂k/∂ln ℓᵢ = m (Δᵢ/ℓᵢ)²` into `gradient[scalars..]` (prepared points are already divided by ℓ).
fn fill_length_scale_gradient(m: f64, a: &[f64], b: &[f64], gradient: &mut [f64], scalars: usize) {
    for ((g, x), y) in gradient[scalars..].iter_mut().zip(a).zip(b) {
        *g = m * (x - y) * (x - y);
    }
}

#[inline]
pub(crate) fn squared_distance(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn scale_point(a: &[f64], scale: &[f64]) -> Vec<f64> {
    a.iter().zip(scale).map(|(x, s)| x * s).collect()
}
