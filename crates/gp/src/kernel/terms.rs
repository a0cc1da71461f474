//! Every kernel of the crate as one sum of terms, for the inner loops:
//! `σf² s(‖(x − x') ∘ ℓ⁻¹‖²) + σc² + Σᵢ wᵢ xᵢ x'ᵢ + Σᵢ aᵢ s((xᵢ − x'ᵢ)²/bᵢ²)`, and the chain rule
//! from the gradient in this expanded form back to each kernel's own log-parameters.
//!
//! The expanded log-parameters are, always in this order and whether or not the kernel has the
//! term: `ln σf², ln ℓ₁ … ln ℓ_d, ln σc², ln w₁ … ln w_d, ln a₁ … ln a_d, ln b₁ … ln b_d, ln σn²`
//! (`4d + 3` of them).

use super::StationaryShape;
use crate::points::Points;

/// What the Gram-matrix loops need besides the prepared points.
#[derive(Debug, Clone)]
pub struct Evaluator {
    pub(crate) shape: StationaryShape,
    /// `σf²`.
    pub signal_variance: f64,
    /// `σc²`, 0 without a constant term.
    pub constant: f64,
    /// `aᵢ` of the additive term, empty without one.
    pub additive_variances: Vec<f64>,
    pub(crate) noise_variance: f64,
}

impl Evaluator {
    /// `k(x, x)` without noise, given `Σᵢ wᵢ xᵢ²` of the linear term.
    pub(crate) fn prior_variance(&self, linear: f64) -> f64 {
        self.signal_variance + self.constant + linear + self.additive_variances.iter().sum::<f64>()
    }
}

/// Inputs prepared for an [`Evaluator`]: divided by the length scales for the stationary term,
/// multiplied by `√wᵢ` for the linear term (so that it is a plain inner product), and divided by
/// the additive term's own length scales `bᵢ`.
#[derive(Debug, Clone, PartialEq)]
pub struct Prepared {
    pub(crate) stationary: Points,
    /// Inputs times `√wᵢ`, `None` without a linear term.
    pub linear: Option<Points>,
    pub(crate) additive: Option<Points>,
}

impl Prepared {
    /// Number of points.
    pub fn len(&self) -> usize {
        self.stationary.len()
    }

    /// Whether there are no points.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The points in `range`, in order.
    pub fn rows(&self, range: std::ops::Range<usize>) -> Self {
        Self {
            stationary: self.stationary.rows(range.clone()),
            linear: self.linear.as_ref().map(|l| l.rows(range.clone())),
            additive: self.additive.as_ref().map(|a| a.rows(range)),
        }
    }
}

/// The expanded form of a kernel for `dim` inputs.
#[derive(Debug, Clone)]
pub(crate) struct Terms {
    pub(crate) evaluator: Evaluator,
    pub(crate) inverse_length_scales: Vec<f64>,
    /// `√wᵢ`, `None` without a linear term.
    pub(crate) linear_roots: Option<Vec<f64>>,
    /// `1/bᵢ` of the additive term, `None` without one.
    pub(crate) additive_inverse_length_scales: Option<Vec<f64>>,
}

/// Index of each block in the expanded log-parameters for `dim` inputs.
#[derive(Debug, Clone, Copy)]
pub struct Expanded {
    /// Number of inputs.
    pub dim: usize,
}

impl Expanded {
    /// `ln σf²`.
    pub const SIGNAL: usize = 0;
    /// `ln ℓᵢ`.
    pub(crate) fn length(self, i: usize) -> usize {
        1 + i
    }
    /// `ln σc²`.
    pub fn constant(self) -> usize {
        1 + self.dim
    }
    /// `ln wᵢ`.
    pub fn linear(self, i: usize) -> usize {
        2 + self.dim + i
    }
    /// `ln aᵢ`.
    pub fn additive_variance(self, i: usize) -> usize {
        2 + 2 * self.dim + i
    }
    /// `ln bᵢ`.
    pub(crate) fn additive_length(self, i: usize) -> usize {
        2 + 3 * self.dim + i
    }
    /// `ln σn²`.
    pub fn noise(self) -> usize {
        2 + 4 * self.dim
    }
    /// Number of expanded log-parameters, `4d + 3`.
    pub(crate) fn len(self) -> usize {
        3 + 4 * self.dim
    }
}

impl Terms {
    /// The inputs as the loops read them.
    pub(crate) fn prepare(&self, points: &Points) -> Prepared {
        Prepared {
            stationary: points.scaled_columns(&self.inverse_length_scales),
            linear: self.linear_roots.as_ref().map(|r| points.scaled_columns(r)),
            additive: self.additive_inverse_length_scales.as_ref().map(|r| points.scaled_columns(r)),
        }
    }

    /// `k(a, b)` without noise and, if `gradient` is given, `∂k/∂` every expanded log-parameter
    /// (the noise entry is left 0), from raw points.
    pub(crate) fn pair(&self, a: &[f64], b: &[f64], gradient: Option<&mut [f64]>) -> f64 {
        let e = &self.evaluator;
        let r2: f64 = a.iter().zip(b).zip(&self.inverse_length_scales).map(|((x, y), s)| ((x - y) * s).powi(2)).sum();
        let (stationary, weight) = e.shape.value_and_weight(e.signal_variance, r2);
        let linear: Vec<f64> = match &self.linear_roots {
            Some(r) => a.iter().zip(b).zip(r).map(|((x, y), s)| x * s * y * s).collect(),
            None => Vec::new(),
        };
        if let Some(g) = gradient {
            let layout = Expanded { dim: a.len() };
            g.iter_mut().for_each(|v| *v = 0.0);
            g[Expanded::SIGNAL] = stationary;
            for (i, ((x, y), s)) in a.iter().zip(b).zip(&self.inverse_length_scales).enumerate() {
                g[layout.length(i)] = weight * ((x - y) * s).powi(2);
            }
            g[layout.constant()] = e.constant;
            for (i, v) in linear.iter().enumerate() {
                g[layout.linear(i)] = *v;
            }
            if let Some(inverse) = &self.additive_inverse_length_scales {
                for (i, ((x, y), s)) in a.iter().zip(b).zip(inverse).enumerate() {
                    let r2 = ((x - y) * s).powi(2);
                    let (value, weight) = e.shape.value_and_weight(e.additive_variances[i], r2);
                    g[layout.additive_variance(i)] = value;
                    g[layout.additive_length(i)] = weight * r2;
                }
            }
        }
        let additive: f64 = match &self.additive_inverse_length_scales {
            Some(inverse) => a
                .iter()
                .zip(b)
                .zip(inverse)
                .zip(&e.additive_variances)
                .map(|(((x, y), s), v)| e.shape.value(*v, ((x - y) * s).powi(2)))
                .sum(),
            None => 0.0,
        };
        stationary + e.constant + linear.iter().sum::<f64>() + additive
    }
}
