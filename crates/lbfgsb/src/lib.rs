//! A small bound-constrained L-BFGS: projected two-loop direction on the free variables and a
//! backtracking Armijo search along the projected path (in the spirit of L-BFGS-B, Byrd, Lu,
//! Nocedal & Zhu 1995, without its Cauchy-point subspace step, which matters little for the ≤ 20
//! variables of a kernel).
//!
//! Hand-written rather than taken from a crate: argmin's L-BFGS has no bounds, and the wrappers of
//! the Fortran L-BFGS-B need a Fortran toolchain. The tests check it on bounded quadratics with a
//! known answer and on the Rosenbrock function.
//!
//! ```
//! use lbfgsb::{Objective, Settings, Termination, minimise};
//!
//! /// `(x − 3)² + (y + 1)²`, whose minimum (3, −1) lies outside the box `[0, 2] × [0, 2]`.
//! struct Bowl(Vec<f64>);
//! impl Objective for Bowl {
//!     fn value(&mut self, x: &[f64]) -> Option<f64> {
//!         self.0 = x.to_vec();
//!         Some((x[0] - 3.0).powi(2) + (x[1] + 1.0).powi(2))
//!     }
//!     fn gradient(&mut self) -> Option<Vec<f64>> {
//!         Some(vec![2.0 * (self.0[0] - 3.0), 2.0 * (self.0[1] + 1.0)])
//!     }
//! }
//!
//! let settings =
//!     Settings { memory: 5, max_iterations: 100, gradient_tolerance: 1e-10, function_tolerance: 1e-15 };
//! let found = minimise(&mut Bowl(vec![]), &[1.0, 1.0], &[0.0, 0.0], &[2.0, 2.0], &settings).unwrap();
//! // The constrained minimum is the box's corner nearest (3, −1).
//! assert!((found.x[0] - 2.0).abs() < 1e-9 && found.x[1].abs() < 1e-9);
//! assert_ne!(found.termination, Termination::LineSearchFailed);
//! ```

#![deny(missing_docs)]

use std::collections::VecDeque;

/// Stopping rules and memory.
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// Curvature pairs kept.
    pub memory: usize,
    /// Most iterations.
    pub max_iterations: usize,
    /// On `max |P(x − g) − x|`, scipy's `pgtol`.
    pub gradient_tolerance: f64,
    /// On `(f_k − f_{k+1}) / max(|f_k|, |f_{k+1}|, 1)`, scipy's `factr · ε`.
    pub function_tolerance: f64,
}

/// Why the iteration stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Termination {
    /// The projected gradient met `gradient_tolerance`.
    GradientTolerance,
    /// The relative decrease met `function_tolerance`.
    FunctionTolerance,
    /// `max_iterations` were taken.
    MaxIterations,
    /// No step along the projected path decreased the objective.
    LineSearchFailed,
}

/// The best point found.
#[derive(Debug, Clone)]
pub struct Minimum {
    /// The point.
    pub x: Vec<f64>,
    /// The objective there.
    pub f: f64,
    /// Iterations taken.
    pub iterations: usize,
    /// Objective values computed (every trial point of the line searches).
    pub evaluations: usize,
    /// Gradients computed (accepted points only).
    pub gradients: usize,
    /// Why it stopped.
    pub termination: Termination,
    /// The curvature pairs held at the end, oldest first: a later search near this point can start
    /// from them ([`minimise_with`]).
    pub history: Vec<Pair>,
}

/// One curvature pair: a step `s` and the change `y` of the gradient along it.
#[derive(Debug, Clone)]
pub struct Pair {
    /// The step.
    pub s: Vec<f64>,
    /// The gradient's change along it.
    pub y: Vec<f64>,
}

fn project(x: &mut [f64], lower: &[f64], upper: &[f64]) {
    for ((v, l), u) in x.iter_mut().zip(lower).zip(upper) {
        *v = v.clamp(*l, *u);
    }
}

fn masked_dot(a: &[f64], b: &[f64], free: &[bool]) -> f64 {
    a.iter().zip(b).zip(free).filter(|(_, f)| **f).map(|((x, y), _)| x * y).sum()
}

/// `−H g` on the free variables by the L-BFGS two-loop recursion (Nocedal & Wright Algorithm 7.4),
/// with every inner product restricted to the free set; zero on the others.
fn direction(g: &[f64], free: &[bool], history: &VecDeque<Pair>) -> Vec<f64> {
    let mut q: Vec<f64> = g.iter().zip(free).map(|(v, f)| if *f { *v } else { 0.0 }).collect();
    let usable: Vec<(&Pair, f64)> = history
        .iter()
        .filter_map(|p| {
            let sy = masked_dot(&p.s, &p.y, free);
            (sy > 0.0).then_some((p, 1.0 / sy))
        })
        .collect();
    let mut alphas = Vec::with_capacity(usable.len());
    for (p, rho) in usable.iter().rev() {
        let a = rho * masked_dot(&p.s, &q, free);
        for ((qi, yi), f) in q.iter_mut().zip(&p.y).zip(free) {
            if *f {
                *qi -= a * yi;
            }
        }
        alphas.push(a);
    }
    if let Some((p, rho)) = usable.last() {
        // Initial Hessian γI with γ = sᵀy / yᵀy (Nocedal & Wright Eq. 7.20).
        let yy = masked_dot(&p.y, &p.y, free);
        if yy > 0.0 {
            let gamma = 1.0 / (rho * yy);
            q.iter_mut().for_each(|v| *v *= gamma);
        }
    }
    for ((p, rho), a) in usable.iter().zip(alphas.iter().rev()) {
        let b = rho * masked_dot(&p.y, &q, free);
        for ((qi, si), f) in q.iter_mut().zip(&p.s).zip(free) {
            if *f {
                *qi += (a - b) * si;
            }
        }
    }
    q.iter_mut().for_each(|v| *v = -*v);
    q
}

/// A function to minimise, evaluated in two stages so that a line search that rejects a trial
/// point does not pay for its gradient.
pub trait Objective {
    /// `f(x)`, or `None` where it cannot be evaluated (e.g. a failed factorisation).
    fn value(&mut self, x: &[f64]) -> Option<f64>;
    /// `∇f` at the point of the last `value` call that returned `Some`.
    fn gradient(&mut self) -> Option<Vec<f64>>;
}

/// An objective from a closure that returns value and gradient together.
#[cfg(test)]
pub(crate) struct Joint<F> {
    f: F,
    gradient: Option<Vec<f64>>,
}

#[cfg(test)]
impl<F: FnMut(&[f64]) -> Option<(f64, Vec<f64>)>> Joint<F> {
    pub fn new(f: F) -> Self {
        Self { f, gradient: None }
    }
}

#[cfg(test)]
impl<F: FnMut(&[f64]) -> Option<(f64, Vec<f64>)>> Objective for Joint<F> {
    fn value(&mut self, x: &[f64]) -> Option<f64> {
        let (v, g) = (self.f)(x)?;
        self.gradient = Some(g);
        Some(v)
    }
    fn gradient(&mut self) -> Option<Vec<f64>> {
        self.gradient.take()
    }
}

/// Minimises `objective` over the box `[lower, upper]` from `start`.
///
/// Where the objective cannot be evaluated the line search backtracks. Returns `None` only if the
/// (projected) start itself cannot be evaluated.
pub fn minimise(
    objective: &mut impl Objective,
    start: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &Settings,
) -> Option<Minimum> {
    minimise_with(objective, start, lower, upper, settings, &[])
}

/// [`minimise`] with the memory filled from `pairs` (the newest `settings.memory` of them, those
/// of the right length with positive curvature) instead of empty: the first step is then a
/// quasi-Newton step rather than one down the gradient. Pairs from an earlier search of a similar
/// function (the same likelihood on a subset of the rows, its `y` scaled to the full data) make
/// the search start with that function's curvature.
pub fn minimise_with(
    objective: &mut impl Objective,
    start: &[f64],
    lower: &[f64],
    upper: &[f64],
    settings: &Settings,
    pairs: &[Pair],
) -> Option<Minimum> {
    let n = start.len();
    let mut x = start.to_vec();
    project(&mut x, lower, upper);
    let mut evaluations = 1;
    let mut gradients = 1;
    let mut f = objective.value(&x).filter(|f| f.is_finite())?;
    let mut g = objective.gradient().filter(|g| g.iter().all(|v| v.is_finite()))?;
    let mut history: VecDeque<Pair> = VecDeque::with_capacity(settings.memory);
    for p in pairs.iter().filter(|p| p.s.len() == n && p.y.len() == n) {
        let sy: f64 = p.s.iter().zip(&p.y).map(|(a, b)| a * b).sum();
        let yy: f64 = p.y.iter().map(|v| v * v).sum();
        if sy > f64::EPSILON * yy && sy.is_finite() {
            if history.len() == settings.memory {
                history.pop_front();
            }
            history.push_back(p.clone());
        }
    }
    let mut termination = Termination::MaxIterations;
    let mut iterations = 0;
    while iterations < settings.max_iterations {
        let projected_gradient =
            (0..n).map(|i| ((x[i] - g[i]).clamp(lower[i], upper[i]) - x[i]).abs()).fold(0.0, f64::max);
        if projected_gradient <= settings.gradient_tolerance {
            termination = Termination::GradientTolerance;
            break;
        }
        let free: Vec<bool> =
            (0..n).map(|i| !((x[i] <= lower[i] && g[i] > 0.0) || (x[i] >= upper[i] && g[i] < 0.0))).collect();
        let mut d = direction(&g, &free, &history);
        // Not a descent direction (bad curvature pairs): forget them and go down the gradient.
        if masked_dot(&g, &d, &free).partial_cmp(&0.0) != Some(std::cmp::Ordering::Less) {
            history.clear();
            d = g.iter().zip(&free).map(|(v, f)| if *f { -v } else { 0.0 }).collect();
        }
        let mut step = if history.is_empty() {
            let largest = d.iter().map(|v| v.abs()).fold(0.0, f64::max);
            if largest > 1.0 { 1.0 / largest } else { 1.0 }
        } else {
            1.0
        };
        let mut accepted = None;
        for _ in 0..40 {
            let mut trial: Vec<f64> = x.iter().zip(&d).map(|(xi, di)| xi + step * di).collect();
            project(&mut trial, lower, upper);
            // Armijo on the projected path: f(x(α)) ≤ f(x) + c₁ gᵀ(x(α) − x).
            let decrease: f64 = trial.iter().zip(&x).zip(&g).map(|((t, xi), gi)| gi * (t - xi)).sum();
            if decrease >= 0.0 {
                break;
            }
            evaluations += 1;
            if let Some(ft) = objective.value(&trial)
                && ft.is_finite()
                && ft <= f + 1e-4 * decrease
            {
                gradients += 1;
                match objective.gradient() {
                    Some(gt) if gt.iter().all(|v| v.is_finite()) => accepted = Some((trial, ft, gt)),
                    _ => {}
                }
                if accepted.is_some() {
                    break;
                }
            }
            step *= 0.5;
        }
        let Some((x_new, f_new, g_new)) = accepted else {
            // As L-BFGS-B does: a failed search along the quasi-Newton direction is retried once
            // down the projected gradient with the memory cleared (stale curvature pairs can point
            // the direction where no step decreases f); only a failed steepest-descent search ends
            // the minimisation. Bounded: the memory refills only through accepted steps.
            if !history.is_empty() {
                history.clear();
                continue;
            }
            termination = Termination::LineSearchFailed;
            break;
        };
        iterations += 1;
        let s: Vec<f64> = x_new.iter().zip(&x).map(|(a, b)| a - b).collect();
        let y: Vec<f64> = g_new.iter().zip(&g).map(|(a, b)| a - b).collect();
        let sy: f64 = s.iter().zip(&y).map(|(a, b)| a * b).sum();
        let yy: f64 = y.iter().map(|v| v * v).sum();
        // Keep a pair only with positive curvature, so the implicit inverse Hessian stays positive.
        if sy > f64::EPSILON * yy {
            if history.len() == settings.memory {
                history.pop_front();
            }
            history.push_back(Pair { s, y });
        }
        let relative = (f - f_new) / f.abs().max(f_new.abs()).max(1.0);
        x = x_new;
        f = f_new;
        g = g_new;
        if relative <= settings.function_tolerance {
            termination = Termination::FunctionTolerance;
            break;
        }
    }
    Some(Minimum { x, f, iterations, evaluations, gradients, termination, history: history.into() })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings() -> Settings {
        Settings { memory: 8, max_iterations: 500, gradient_tolerance: 1e-9, function_tolerance: 0.0 }
    }

    /// Curvature pairs from a search of the same function make a second search from a nearby
    /// start converge in fewer iterations than an empty memory does, to the same minimum.
    #[test]
    fn seeded_memory_converges_in_fewer_iterations() {
        let c = [1.0, 30.0, 3.0, 0.2, 8.0];
        let f = |x: &[f64]| {
            let v = (0..5).map(|i| c[i] * (x[i] - 0.1 * i as f64).powi(2)).sum();
            let g = (0..5).map(|i| 2.0 * c[i] * (x[i] - 0.1 * i as f64)).collect();
            Some((v, g))
        };
        let (lower, upper) = ([-10.0; 5], [10.0; 5]);
        let tight = Settings { memory: 10, max_iterations: 500, gradient_tolerance: 1e-10, function_tolerance: 0.0 };
        let first = minimise(&mut Joint::new(f), &[3.0, -2.0, 1.0, 4.0, -1.0], &lower, &upper, &tight).expect("first");
        let start = [0.5, 0.3, -0.4, 1.0, 0.9];
        let cold = minimise(&mut Joint::new(f), &start, &lower, &upper, &tight).expect("cold");
        let warm = minimise_with(&mut Joint::new(f), &start, &lower, &upper, &tight, &first.history).expect("warm");
        assert!(!first.history.is_empty());
        assert!(warm.iterations < cold.iterations, "seeded {} vs empty {}", warm.iterations, cold.iterations);
        for i in 0..5 {
            assert!((warm.x[i] - 0.1 * i as f64).abs() < 1e-6, "{:?}", warm.x);
        }
    }

    #[test]
    fn bounded_quadratic_stops_on_the_active_bound() {
        // f = Σ cᵢ (xᵢ − tᵢ)², target outside the box in coordinates 0 and 2.
        let c = [1.0, 10.0, 3.0, 0.5];
        let t = [2.0, -0.3, -5.0, 0.7];
        let (lower, upper) = ([-1.0; 4], [1.0; 4]);
        let f = |x: &[f64]| {
            let v = (0..4).map(|i| c[i] * (x[i] - t[i]).powi(2)).sum();
            let g = (0..4).map(|i| 2.0 * c[i] * (x[i] - t[i])).collect();
            Some((v, g))
        };
        let m =
            minimise(&mut Joint::new(f), &[0.0, 0.9, 0.5, -0.9], &lower, &upper, &settings()).expect("start evaluates");
        let expected = [1.0, -0.3, -1.0, 0.7];
        for (a, b) in m.x.iter().zip(expected) {
            assert!((a - b).abs() < 1e-7, "{:?}", m);
        }
        assert!(matches!(m.termination, Termination::GradientTolerance | Termination::FunctionTolerance), "{m:?}");
    }

    #[test]
    fn rosenbrock_converges_to_its_minimum_inside_the_box() {
        let f = |x: &[f64]| {
            let (a, b) = (x[0], x[1]);
            let v = (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2);
            let g = vec![-2.0 * (1.0 - a) - 400.0 * a * (b - a * a), 200.0 * (b - a * a)];
            Some((v, g))
        };
        let m = minimise(&mut Joint::new(f), &[-1.2, 1.0], &[-2.0, -2.0], &[2.0, 2.0], &settings())
            .expect("start evaluates");
        assert!((m.x[0] - 1.0).abs() < 1e-5 && (m.x[1] - 1.0).abs() < 1e-5, "{m:?}");
    }

    #[test]
    fn rosenbrock_with_the_minimum_cut_off_stops_on_the_constrained_minimum() {
        // With x₀ ≤ 0.5 the minimum is at x₀ = 0.5, x₁ = 0.25 (the valley floor b = a²).
        let f = |x: &[f64]| {
            let (a, b) = (x[0], x[1]);
            let v = (1.0 - a).powi(2) + 100.0 * (b - a * a).powi(2);
            let g = vec![-2.0 * (1.0 - a) - 400.0 * a * (b - a * a), 200.0 * (b - a * a)];
            Some((v, g))
        };
        let m = minimise(&mut Joint::new(f), &[-1.2, 1.0], &[-2.0, -2.0], &[0.5, 2.0], &settings())
            .expect("start evaluates");
        assert!((m.x[0] - 0.5).abs() < 1e-8 && (m.x[1] - 0.25).abs() < 1e-5, "{m:?}");
    }

    /// A quadratic that refuses every trial point off the steepest-descent ray of the last
    /// accepted point: the quasi-Newton direction always fails there.
    struct SteepestOnly {
        at: Vec<f64>,
        gradient_at: Vec<f64>,
        pending: Option<(Vec<f64>, Vec<f64>)>,
    }

    impl SteepestOnly {
        fn f(x: &[f64]) -> (f64, Vec<f64>) {
            let c = [1.0, 4.0, 9.0];
            ((0..3).map(|i| c[i] * (x[i] - 0.5).powi(2)).sum(), (0..3).map(|i| 2.0 * c[i] * (x[i] - 0.5)).collect())
        }
    }

    impl Objective for SteepestOnly {
        fn value(&mut self, x: &[f64]) -> Option<f64> {
            if !self.at.is_empty() {
                let d: Vec<f64> = x.iter().zip(&self.at).map(|(a, b)| a - b).collect();
                let cos = -d.iter().zip(&self.gradient_at).map(|(a, b)| a * b).sum::<f64>()
                    / (d.iter().map(|v| v * v).sum::<f64>().sqrt()
                        * self.gradient_at.iter().map(|v| v * v).sum::<f64>().sqrt());
                if cos < 1.0 - 1e-9 {
                    return None;
                }
            }
            let (v, g) = Self::f(x);
            self.pending = Some((x.to_vec(), g));
            Some(v)
        }
        fn gradient(&mut self) -> Option<Vec<f64>> {
            let (x, g) = self.pending.take()?;
            self.at = x;
            self.gradient_at = g.clone();
            Some(g)
        }
    }

    #[test]
    fn a_failed_quasi_newton_search_is_retried_down_the_gradient() {
        let mut objective = SteepestOnly { at: Vec::new(), gradient_at: Vec::new(), pending: None };
        let settings = Settings { memory: 8, max_iterations: 500, gradient_tolerance: 1e-8, function_tolerance: 0.0 };
        let m =
            minimise(&mut objective, &[-1.0, 2.0, 1.5], &[-10.0; 3], &[10.0; 3], &settings).expect("start evaluates");
        assert!(matches!(m.termination, Termination::GradientTolerance), "{m:?}");
        assert!(m.x.iter().all(|v| (v - 0.5).abs() < 1e-6), "{m:?}");
        assert!(m.iterations > 2, "the search took more than one step: {m:?}");
    }

    #[test]
    fn unevaluable_region_is_backtracked_out_of() {
        // f undefined for x > 0.5; minimum of (x − 0.4)² inside the defined part.
        let f = |x: &[f64]| (x[0] <= 0.5).then(|| ((x[0] - 0.4).powi(2), vec![2.0 * (x[0] - 0.4)]));
        let m = minimise(&mut Joint::new(f), &[-3.0], &[-10.0], &[10.0], &settings()).expect("start evaluates");
        assert!((m.x[0] - 0.4).abs() < 1e-6, "{m:?}");
    }
}
