//! Covariance functions, each with a white-noise term and analytic gradients with respect to the
//! logarithms of its parameters.
//!
//! Every parameter is positive and the optimiser works on `ln p`, so `∂k/∂ln p = p ∂k/∂p`. The
//! noise variance is always the last log-parameter; it adds `σn² δᵢⱼ` to the training covariance
//! only (same index, not same location, as scikit-learn's `WhiteKernel`).
//!
//! All kernels are evaluated through one expanded form (`terms.rs`): a stationary term, a
//! constant and a linear term; each public kernel is a choice of which terms it has and which
//! parameters it ties together.

mod composite;
mod matern52;
mod quadratic;
mod shape;
mod squared_exponential;
mod terms;

pub use composite::{AdditiveTerm, CompositeKernel};
pub use matern52::Matern52Ard;
pub use quadratic::QuadraticKernel;
pub use shape::StationaryShape;
pub use squared_exponential::SquaredExponentialArd;
pub(crate) use terms::Terms;
pub use terms::{Evaluator, Expanded, Prepared};

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
    /// Eq. 5 with every term ARD and each optional, see [`CompositeKernel`].
    Composite {
        /// Family of the stationary term.
        shape: StationaryShape,
        /// With a constant term.
        constant: bool,
        /// With an ARD linear term.
        linear: bool,
        /// With a first-order additive term (one one-dimensional kernel per input).
        #[serde(default)]
        additive: bool,
    },
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
    /// Constant + ARD linear + ARD stationary + noise.
    Composite(CompositeKernel),
}

/// A box on the kernel's parameters, natural scale (not log), in log-parameter order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Bounds {
    /// Lower bounds, all > 0.
    pub lower: Vec<f64>,
    /// Upper bounds, each ≥ its lower bound.
    pub upper: Vec<f64>,
}

/// Search box of a signal variance on normalised outputs.
const SIGNAL_BOUNDS: (f64, f64) = (1e-3, 1e2);
/// Length scales from 1/100 to 1000 standard deviations of the input; beyond the upper end the
/// input is irrelevant and the likelihood is flat.
const LENGTH_BOUNDS: (f64, f64) = (1e-2, 1e3);
/// A constant or a slope variance from negligible (1e-6 of the output variance) to 100 times it.
const OFFSET_BOUNDS: (f64, f64) = (1e-6, 1e2);
/// The noise may go down to 1e-9 so that nearly noiseless data can be interpolated.
const NOISE_BOUNDS: (f64, f64) = (1e-9, 1e1);

impl Kernel {
    /// The default starting point of `choice` for `dim` standardised inputs and normalised outputs.
    pub fn start(choice: KernelChoice, dim: usize) -> Self {
        match choice {
            KernelChoice::Quadratic => Self::Quadratic(QuadraticKernel::default()),
            KernelChoice::SquaredExponentialArd => {
                Self::SquaredExponentialArd(SquaredExponentialArd::isotropic_start(dim))
            }
            KernelChoice::Matern52Ard => Self::Matern52Ard(Matern52Ard::isotropic_start(dim)),
            KernelChoice::Composite { shape, constant, linear, additive } => {
                Self::Composite(CompositeKernel::start(shape, dim, constant, linear, additive))
            }
        }
    }

    /// The family of this kernel.
    pub fn choice(&self) -> KernelChoice {
        match self {
            Self::Quadratic(_) => KernelChoice::Quadratic,
            Self::SquaredExponentialArd(_) => KernelChoice::SquaredExponentialArd,
            Self::Matern52Ard(_) => KernelChoice::Matern52Ard,
            Self::Composite(k) => KernelChoice::Composite {
                shape: k.shape,
                constant: k.constant.is_some(),
                linear: k.linear_weights.is_some(),
                additive: k.additive.is_some(),
            },
        }
    }

    /// Input dimension the kernel is tied to (`None` for the isotropic Eq. 5 kernel).
    pub fn input_dim(&self) -> Option<usize> {
        match self {
            Self::Quadratic(_) => None,
            Self::SquaredExponentialArd(k) => Some(k.length_scales.len()),
            Self::Matern52Ard(k) => Some(k.length_scales.len()),
            Self::Composite(k) => Some(k.length_scales.len()),
        }
    }

    /// Number of log-parameters, noise included.
    pub fn parameter_count(&self) -> usize {
        self.parameters().len()
    }

    /// The white-noise variance `σn²`.
    pub fn noise_variance(&self) -> f64 {
        match self {
            Self::Quadratic(k) => k.noise_variance,
            Self::SquaredExponentialArd(k) => k.noise_variance,
            Self::Matern52Ard(k) => k.noise_variance,
            Self::Composite(k) => k.noise_variance,
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
            Self::Composite(k) => {
                let mut p = vec![k.signal_variance];
                p.extend_from_slice(&k.length_scales);
                p.extend(k.constant);
                p.extend(k.linear_weights.iter().flatten());
                if let Some(a) = &k.additive {
                    p.extend_from_slice(&a.variances);
                    p.extend_from_slice(&a.length_scales);
                }
                p.push(k.noise_variance);
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
            Self::Composite(k) => {
                let d = k.length_scales.len();
                let mut rest = &parameters[1 + d..n - 1];
                let mut take = |count: usize| {
                    let (head, tail) = rest.split_at(count);
                    rest = tail;
                    head.to_vec()
                };
                let constant = k.constant.map(|_| take(1)[0]);
                let linear_weights = k.linear_weights.as_ref().map(|w| take(w.len()));
                let additive = k.additive.as_ref().map(|a| AdditiveTerm {
                    variances: take(a.variances.len()),
                    length_scales: take(a.length_scales.len()),
                });
                Self::Composite(CompositeKernel {
                    shape: k.shape,
                    signal_variance: parameters[0],
                    length_scales: parameters[1..1 + d].to_vec(),
                    constant,
                    linear_weights,
                    additive,
                    noise_variance: parameters[n - 1],
                })
            }
        })
    }

    /// Checks that every parameter is finite and positive and that an ARD kernel matches `dim`.
    pub fn validate(&self, dim: usize) -> Result<(), Error> {
        if let Some(expected) = self.input_dim()
            && expected != dim
        {
            return Err(Error::InputDimensionMismatch { expected, found: dim });
        }
        if let Self::Composite(CompositeKernel { linear_weights: Some(w), length_scales, .. }) = self
            && w.len() != length_scales.len()
        {
            return Err(Error::InputDimensionMismatch { expected: length_scales.len(), found: w.len() });
        }
        if let Self::Composite(CompositeKernel { additive: Some(a), length_scales, .. }) = self {
            for found in [a.variances.len(), a.length_scales.len()] {
                if found != length_scales.len() {
                    return Err(Error::InputDimensionMismatch { expected: length_scales.len(), found });
                }
            }
        }
        self.with_parameters(&self.parameters()).map(|_| ())
    }

    /// The default search box for this family, for standardised inputs and normalised outputs.
    pub fn default_bounds(&self) -> Bounds {
        if let Self::Quadratic(_) = self {
            let (lower, upper) = QuadraticKernel::default_bounds();
            return Bounds { lower: lower.to_vec(), upper: upper.to_vec() };
        }
        let d = self.input_dim().unwrap_or(0);
        let mut blocks = vec![(SIGNAL_BOUNDS, 1), (LENGTH_BOUNDS, d)];
        if let Self::Composite(k) = self {
            blocks.push((OFFSET_BOUNDS, usize::from(k.constant.is_some())));
            blocks.push((OFFSET_BOUNDS, k.linear_weights.as_ref().map_or(0, Vec::len)));
            let additive = k.additive.as_ref().map_or(0, |a| a.variances.len());
            blocks.push((OFFSET_BOUNDS, additive));
            blocks.push((LENGTH_BOUNDS, additive));
        }
        blocks.push((NOISE_BOUNDS, 1));
        let expand = |pick: fn((f64, f64)) -> f64| {
            blocks.iter().flat_map(|&(b, count)| std::iter::repeat_n(pick(b), count)).collect::<Vec<f64>>()
        };
        Bounds { lower: expand(|b| b.0), upper: expand(|b| b.1) }
    }

    /// The smaller model this kernel contains without its additive term (`None` when it has
    /// none): the candidate of [`crate::GpConfig::additive_by_bic`].
    pub(crate) fn without_additive(&self) -> Option<Kernel> {
        match self {
            Self::Composite(k) if k.additive.is_some() => {
                Some(Self::Composite(CompositeKernel { additive: None, ..k.clone() }))
            }
            _ => None,
        }
    }

    /// Further deterministic starts for a search from this kernel: the same kernel with its
    /// optional extra terms nearly switched off, so that the search also follows the path of the
    /// smaller model it contains and its optimum cannot end far below that model's.
    ///
    /// Only the additive term has one (its variances at [`AdditiveTerm::OFF_VARIANCE`]): on a
    /// simulated 7-axis campaign (300 poses, payload runs) the search from the default start alone
    /// ended at a log marginal likelihood of 96 for one output, where SE-ARD alone reaches 442.
    pub(crate) fn nested_starts(&self) -> Vec<Kernel> {
        match self {
            Self::Composite(k) if k.additive.is_some() => {
                let mut off = k.clone();
                if let Some(a) = &mut off.additive {
                    a.variances.iter_mut().for_each(|v| *v = AdditiveTerm::OFF_VARIANCE);
                }
                vec![Self::Composite(off)]
            }
            _ => Vec::new(),
        }
    }

    /// The nested start at the smaller model's optimum: this kernel's additive term nearly off
    /// ([`AdditiveTerm::OFF_VARIANCE`], its length scales this kernel's) on every other
    /// hyperparameter of `smaller`, the [`Self::without_additive`] form of this kernel fitted
    /// elsewhere. `None` when this kernel has no additive term or `smaller` is not its form.
    ///
    /// The search from there starts where the smaller model's already ended instead of walking
    /// the same path again from the default start with the term off.
    pub(crate) fn nested_at(&self, smaller: &Kernel) -> Option<Kernel> {
        let (Self::Composite(k), Self::Composite(s)) = (self, smaller) else {
            return None;
        };
        let additive = k.additive.as_ref()?;
        let same_form = s.additive.is_none()
            && s.shape == k.shape
            && s.length_scales.len() == k.length_scales.len()
            && s.constant.is_some() == k.constant.is_some()
            && s.linear_weights.as_ref().map(Vec::len) == k.linear_weights.as_ref().map(Vec::len);
        same_form.then(|| {
            Self::Composite(CompositeKernel {
                additive: Some(AdditiveTerm {
                    variances: vec![AdditiveTerm::OFF_VARIANCE; additive.variances.len()],
                    length_scales: additive.length_scales.clone(),
                }),
                ..s.clone()
            })
        })
    }

    /// The expanded form of this kernel for `dim` inputs.
    pub(crate) fn terms(&self, dim: usize) -> Terms {
        let stationary = |shape, signal_variance, lengths: &[f64], noise_variance| Terms {
            evaluator: Evaluator {
                shape,
                signal_variance,
                constant: 0.0,
                additive_variances: Vec::new(),
                noise_variance,
            },
            inverse_length_scales: lengths.iter().map(|l| 1.0 / l).collect(),
            linear_roots: None,
            additive_inverse_length_scales: None,
        };
        match self {
            Self::Quadratic(k) => Terms {
                evaluator: Evaluator {
                    shape: StationaryShape::SquaredExponential,
                    signal_variance: k.theta0,
                    constant: k.theta2,
                    additive_variances: Vec::new(),
                    noise_variance: k.noise_variance,
                },
                // θ1 = 1/ℓ² for every input, θ3 the weight of every input's slope.
                inverse_length_scales: vec![k.theta1.sqrt(); dim],
                linear_roots: Some(vec![k.theta3.sqrt(); dim]),
                additive_inverse_length_scales: None,
            },
            Self::SquaredExponentialArd(k) => {
                stationary(StationaryShape::SquaredExponential, k.signal_variance, &k.length_scales, k.noise_variance)
            }
            Self::Matern52Ard(k) => {
                stationary(StationaryShape::Matern52, k.signal_variance, &k.length_scales, k.noise_variance)
            }
            Self::Composite(k) => Terms {
                evaluator: Evaluator {
                    shape: k.shape,
                    signal_variance: k.signal_variance,
                    constant: k.constant.unwrap_or(0.0),
                    additive_variances: k.additive.as_ref().map(|a| a.variances.clone()).unwrap_or_default(),
                    noise_variance: k.noise_variance,
                },
                inverse_length_scales: k.length_scales.iter().map(|l| 1.0 / l).collect(),
                linear_roots: k.linear_weights.as_ref().map(|w| w.iter().map(|v| v.sqrt()).collect()),
                additive_inverse_length_scales: k
                    .additive
                    .as_ref()
                    .map(|a| a.length_scales.iter().map(|l| 1.0 / l).collect()),
            },
        }
    }

    /// The evaluator and `points` prepared for it.
    pub fn prepare(&self, points: &Points) -> (Evaluator, Prepared) {
        let terms = self.terms(points.dim());
        let prepared = terms.prepare(points);
        (terms.evaluator, prepared)
    }

    /// The gradient in this kernel's log-parameters from the gradient in the expanded ones (chain
    /// rule through the ties: Eq. 5's one length scale `ℓ = θ1^{−1/2}` and one slope weight).
    pub fn fold_gradient(&self, expanded: &[f64], dim: usize) -> Vec<f64> {
        let layout = Expanded { dim };
        let lengths = (0..dim).map(|i| expanded[layout.length(i)]);
        let mut g = vec![expanded[Expanded::SIGNAL]];
        match self {
            Self::Quadratic(_) => {
                // ln ℓ = −½ ln θ1, so ∂/∂ln θ1 = −½ Σᵢ ∂/∂ln ℓᵢ.
                g.push(-0.5 * lengths.sum::<f64>());
                g.push(expanded[layout.constant()]);
                g.push((0..dim).map(|i| expanded[layout.linear(i)]).sum());
            }
            Self::SquaredExponentialArd(_) | Self::Matern52Ard(_) => g.extend(lengths),
            Self::Composite(k) => {
                g.extend(lengths);
                if k.constant.is_some() {
                    g.push(expanded[layout.constant()]);
                }
                if k.linear_weights.is_some() {
                    g.extend((0..dim).map(|i| expanded[layout.linear(i)]));
                }
                if k.additive.is_some() {
                    g.extend((0..dim).map(|i| expanded[layout.additive_variance(i)]));
                    g.extend((0..dim).map(|i| expanded[layout.additive_length(i)]));
                }
            }
        }
        g.push(expanded[layout.noise()]);
        g
    }

    /// `k(a, b)` without the noise term.
    pub fn value(&self, a: &[f64], b: &[f64]) -> f64 {
        self.terms(a.len()).pair(a, b, None)
    }

    /// `k(a, b)` without noise, and `∂k/∂ln p` for every log-parameter but the noise, written into
    /// `gradient` (length [`Kernel::parameter_count`] − 1).
    pub fn value_and_gradient(&self, a: &[f64], b: &[f64], gradient: &mut [f64]) -> Result<f64, Error> {
        let expected = self.parameter_count() - 1;
        if gradient.len() != expected {
            return Err(Error::ParameterCountMismatch { expected, found: gradient.len() });
        }
        if let Some(dim) = self.input_dim()
            && (a.len() != dim || b.len() != dim)
        {
            return Err(Error::InputDimensionMismatch { expected: dim, found: a.len().min(b.len()) });
        }
        let dim = a.len();
        let mut expanded = vec![0.0; Expanded { dim }.len()];
        let value = self.terms(dim).pair(a, b, Some(&mut expanded));
        let folded = self.fold_gradient(&expanded, dim);
        gradient.copy_from_slice(&folded[..expected]);
        Ok(value)
    }
}

impl Bounds {
    /// Checks `0 < lower ≤ upper < ∞` and the length against `kernel`, and returns the bounds in
    /// log space.
    pub fn to_log(&self, kernel: &Kernel) -> Result<(Vec<f64>, Vec<f64>), Error> {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The nested start at a smaller model's optimum carries every hyperparameter of that model
    /// and this kernel's additive term nearly off, and exists only for the form it nests.
    #[test]
    fn the_nested_start_at_the_smaller_optimum_carries_its_hyperparameters() {
        let larger =
            Kernel::Composite(CompositeKernel::start(StationaryShape::SquaredExponential, 3, true, false, true));
        let Kernel::Composite(mut fitted) = larger.without_additive().expect("smaller form") else {
            unreachable!("the smaller form of a composite kernel is composite");
        };
        fitted.signal_variance = 2.5;
        fitted.length_scales = vec![0.4, 1.7, 3.2];
        fitted.constant = Some(0.03);
        fitted.noise_variance = 0.002;
        let fitted = Kernel::Composite(fitted);
        let Some(Kernel::Composite(nested)) = larger.nested_at(&fitted) else {
            panic!("no nested start");
        };
        let Kernel::Composite(expected_rest) = &fitted else { unreachable!() };
        assert_eq!(CompositeKernel { additive: None, ..nested.clone() }, *expected_rest);
        let additive = nested.additive.expect("additive term");
        assert_eq!(additive.variances, vec![AdditiveTerm::OFF_VARIANCE; 3]);
        assert_eq!(additive.length_scales, vec![0.3; 3]);
        let other_form =
            Kernel::Composite(CompositeKernel::start(StationaryShape::SquaredExponential, 3, false, false, false));
        assert!(larger.nested_at(&other_form).is_none());
        assert!(larger.nested_at(&larger).is_none());
        assert!(fitted.nested_at(&fitted).is_none());
    }
}
