//! Why an identification stopped, stated so that "converged" always names the criterion it met.

use serde::Serialize;
use std::fmt;

/// Why the iterations ended. Only the first three mean the solution was reached.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "criterion", rename_all = "snake_case")]
pub enum Termination {
    /// An accepted step lowered the weighted cost by less than the cost tolerance.
    CostTolerance {
        /// The relative decrease of the last step.
        relative_decrease: f64,
    },
    /// The step became shorter than the step tolerance: an accepted step, or a rejected one (no
    /// step that short lowers the cost: the minimum is within it, MINPACK's `xtol`).
    StepTolerance {
        /// Its norm.
        step_norm: f64,
    },
    /// The residual is orthogonal to every Jacobian column within the gradient tolerance.
    GradientTolerance {
        /// `max_j |a_jᵀ y| / (‖a_j‖ ‖y‖)` at the end.
        gradient_cosine: f64,
    },
    /// The iteration limit was reached first.
    IterationLimit {
        /// The limit.
        iterations: usize,
    },
    /// No step along the pseudo-inverse direction lowered the cost, however short, and the
    /// gradient criterion is not met.
    LineSearchFailed {
        /// `max_j |a_jᵀ y| / (‖a_j‖ ‖y‖)` there.
        gradient_cosine: f64,
    },
    /// Levenberg–Marquardt raised its damping to the limit without finding a lower cost, and the
    /// gradient criterion is not met.
    DampingLimit {
        /// The damping reached.
        damping: f64,
        /// `max_j |a_jᵀ y| / (‖a_j‖ ‖y‖)` there.
        gradient_cosine: f64,
    },
}

impl Termination {
    /// Whether a convergence criterion was met.
    pub fn converged(&self) -> bool {
        matches!(
            self,
            Termination::CostTolerance { .. }
                | Termination::StepTolerance { .. }
                | Termination::GradientTolerance { .. }
        )
    }
}

impl fmt::Display for Termination {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            Termination::CostTolerance { relative_decrease } => {
                write!(f, "converged: the last step lowered the cost by {relative_decrease:.1e} (relative)")
            }
            Termination::StepTolerance { step_norm } => write!(f, "converged: step {step_norm:.1e} below tolerance"),
            Termination::GradientTolerance { gradient_cosine } => {
                write!(f, "converged: gradient cosine {gradient_cosine:.1e} below tolerance")
            }
            Termination::IterationLimit { iterations } => {
                write!(f, "NOT converged: stopped at the iteration limit ({iterations})")
            }
            Termination::LineSearchFailed { gradient_cosine } => write!(
                f,
                "NOT converged: no step along the Gauss–Newton direction lowers the cost (gradient cosine {gradient_cosine:.1e})"
            ),
            Termination::DampingLimit { damping, gradient_cosine } => write!(
                f,
                "NOT converged: damping reached {damping:.0e} without lowering the cost (gradient cosine {gradient_cosine:.1e})"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Termination;

    /// A failed line search is no convergence. Every way to stop says in
    /// words what `converged()` says, and only the three criteria count as convergence.
    #[test]
    fn only_a_met_criterion_is_convergence_and_the_words_say_so() {
        let all = [
            (Termination::CostTolerance { relative_decrease: 1e-12 }, true),
            (Termination::StepTolerance { step_norm: 1e-12 }, true),
            (Termination::GradientTolerance { gradient_cosine: 1e-12 }, true),
            (Termination::IterationLimit { iterations: 50 }, false),
            (Termination::LineSearchFailed { gradient_cosine: 0.3 }, false),
            (Termination::DampingLimit { damping: 1e16, gradient_cosine: 0.3 }, false),
        ];
        for (termination, converged) in all {
            assert_eq!(termination.converged(), converged, "{termination}");
            let words = termination.to_string();
            let prefix = if converged { "converged: " } else { "NOT converged: " };
            assert!(words.starts_with(prefix), "{words}");
        }
    }
}
