//! What the identification is told: observations, solver choice, weights and masks.

use super::RobustOptions;
use crate::{Block, Error, ParameterLayout};
use lie::{SE3, Vector3};
use serde::{Deserialize, Serialize};

/// What was measured of the tool at one joint configuration, in the reference (tracker) frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Target {
    /// Position and orientation: `reference_from_tool`.
    Pose(SE3),
    /// Position of the tool point only, metres.
    Point(Vector3),
}

/// One measurement for the identification.
#[derive(Debug, Clone, PartialEq)]
pub struct Observation {
    /// Joint values (radians or metres).
    pub q: Vec<f64>,
    /// Which tool was carried.
    pub tool: usize,
    /// What was measured.
    pub target: Target,
    /// The instrument's stated standard deviations of this observation, where it states them
    /// (module `stated_noise`): its residual is weighted by them relative to the other
    /// observations'.
    pub stated_sigma: Option<super::StatedSigma>,
}

/// How each iteration's linear least-squares problem is solved.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Solver {
    /// The paper's update `x = A⁺ Y`, with an SVD pseudo-inverse that drops singular values below
    /// `rcond · σ_max` (the unidentifiable directions).
    #[default]
    PseudoInverse,
    /// Levenberg–Marquardt with Marquardt's diagonal scaling: robust far from the solution.
    LevenbergMarquardt,
}

/// Options of the identification. Weights are the expected measurement noise: each residual is
/// divided by its sigma, so metres and radians become comparable. Every tuning constant of the
/// solvers is a field here; [`IdentificationOptions::validate`] checks them once, before any work.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct IdentificationOptions {
    /// The linear solver of each iteration.
    pub solver: Solver,
    /// At most this many iterations.
    pub max_iterations: usize,
    /// Converged when an accepted step lowers the weighted cost by less than this fraction.
    #[serde(alias = "tolerance")]
    pub cost_tolerance: f64,
    /// Converged when a step is shorter than this, relative to the parameters' deviation from the
    /// start (plus this, so that a start at zero can converge).
    pub step_tolerance: f64,
    /// Converged when every column of the weighted Jacobian is this close to orthogonal to the
    /// residual: `max_j |a_jᵀ y| / (‖a_j‖ ‖y‖) ≤ gradient_tolerance` (MINPACK's `gtol`).
    pub gradient_tolerance: f64,
    /// Halvings of a pseudo-inverse step before the line search gives up.
    pub line_search_halvings: usize,
    /// Levenberg–Marquardt's first damping, relative to the diagonal of the normal matrix.
    pub initial_damping: f64,
    /// Smallest damping Levenberg–Marquardt lowers to.
    pub min_damping: f64,
    /// Largest damping: beyond it no step lowers the cost and the solver stops.
    pub max_damping: f64,
    /// Noise of a position residual, metres.
    pub position_sigma_m: f64,
    /// Noise of an orientation residual, radians.
    pub rotation_sigma_rad: f64,
    /// Relative singular-value threshold: the pseudo-inverse drops directions below
    /// `rcond · σ_max`, and the report counts them as unidentifiable.
    pub rcond: f64,
    /// Levenberg–Marquardt only: prior standard deviation of the local frames' translations about
    /// the start, metres. Directions the data does not excite stay at the start instead of
    /// drifting on noise; `f64::INFINITY` for none.
    pub prior_translation_m: f64,
    /// Levenberg–Marquardt only: prior standard deviation of the local frames' rotations about the
    /// start, radians.
    pub prior_rotation_rad: f64,
    /// The robust loss: Huber weights beyond a generous threshold, gross outliers named and left
    /// out (module `robust`).
    pub robust: RobustOptions,
    /// Observations linearised at a time and folded into the QR triangle of the stacked problem
    /// (`reduced.rs`): memory holds one block of the Jacobian, not all of it. Changes results
    /// only in their rounding.
    pub block_observations: usize,
    /// How observations that state their own σ are weighted (module `stated_noise`).
    pub stated_noise: super::StatedNoise,
}

impl Default for IdentificationOptions {
    fn default() -> Self {
        Self {
            solver: Solver::PseudoInverse,
            max_iterations: 50,
            cost_tolerance: 1e-10,
            // Far below any parameter change that moves a tool point by a micrometre.
            step_tolerance: 1e-12,
            // SciPy's `least_squares` default `gtol`.
            gradient_tolerance: 1e-8,
            // The halvings the paper's iteration always had: a step shrunk 4096 times is noise.
            line_search_halvings: 12,
            // Marquardt's and Nielsen's customary start (Madsen, Nielsen, Tingleff, "Methods for
            // non-linear least squares problems", 2004, §3.2: τ = 1e-3 when the start is good,
            // as after the registration and the base-tool step).
            initial_damping: 1e-3,
            min_damping: 1e-12,
            // Beyond 1e12 times the diagonal the step is below the rounding of the parameters.
            max_damping: 1e12,
            position_sigma_m: 1e-4,
            rotation_sigma_rad: 1e-4,
            rcond: 1e-9,
            // No prior: the plain least-squares solution (callers that want a maximum a
            // posteriori fit set it, as `pipeline` does for non-geometric effects).
            prior_translation_m: f64::INFINITY,
            prior_rotation_rad: f64::INFINITY,
            robust: RobustOptions::default(),
            // 1,024 poses: 6,144 rows of at most ~100 columns, under 5 MB, and each fold's QR
            // (of ~6,200 × 100) long enough that the per-block overhead is negligible.
            block_observations: 1024,
            stated_noise: super::StatedNoise::default(),
        }
    }
}

impl IdentificationOptions {
    /// Checks every field once: tolerances and sigmas positive and finite, damping bounds ordered.
    pub fn validate(&self) -> Result<(), Error> {
        let invalid = |name: &'static str, value: f64, expected: &'static str| {
            Err(Error::InvalidOption { name, value, expected })
        };
        let positive = [
            ("cost_tolerance", self.cost_tolerance),
            ("step_tolerance", self.step_tolerance),
            ("gradient_tolerance", self.gradient_tolerance),
            ("initial_damping", self.initial_damping),
            ("min_damping", self.min_damping),
            ("max_damping", self.max_damping),
            ("position_sigma_m", self.position_sigma_m),
            ("rotation_sigma_rad", self.rotation_sigma_rad),
            ("rcond", self.rcond),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return invalid(name, value, "a finite number above 0");
            }
        }
        for (name, value) in
            [("prior_translation_m", self.prior_translation_m), ("prior_rotation_rad", self.prior_rotation_rad)]
        {
            if value.is_nan() || value <= 0.0 {
                return invalid(name, value, "a number above 0 (inf for no prior)");
            }
        }
        if self.rcond >= 1.0 {
            return invalid("rcond", self.rcond, "below 1");
        }
        if self.max_iterations == 0 {
            return invalid("max_iterations", 0.0, "at least 1");
        }
        if self.block_observations == 0 {
            return invalid("block_observations", 0.0, "at least 1");
        }
        if !(self.min_damping <= self.initial_damping && self.initial_damping <= self.max_damping) {
            return invalid("initial_damping", self.initial_damping, "between min_damping and max_damping");
        }
        let far = self.stated_noise.far_above_median;
        if !(far.is_finite() && far >= 1.0) {
            return invalid("stated_noise.far_above_median", far, "a finite number of at least 1");
        }
        self.robust.validate()
    }
}

/// Which parameters the identification may change (`true`) and which it keeps fixed.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ParameterMask {
    free: Vec<bool>,
}

impl ParameterMask {
    /// Every parameter free: the full local POE identification.
    pub fn all(layout: ParameterLayout) -> Self {
        Self { free: vec![true; layout.len()] }
    }

    /// The paper's base-tool baseline: only the first local transform (which holds the base
    /// placement) and the tools are free.
    pub fn base_tool(layout: ParameterLayout) -> Self {
        let mut mask = Self { free: vec![false; layout.len()] };
        if layout.joint_count > 0 {
            mask.set_block(layout, Block::Joint(0), true);
        }
        for tool in 0..layout.tool_count {
            mask.set_block(layout, Block::Tool(tool), true);
        }
        mask
    }

    /// A mask from one flag per parameter.
    pub fn from_flags(free: Vec<bool>) -> Self {
        Self { free }
    }

    /// Frees or fixes the six parameters of one block.
    pub fn set_block(&mut self, layout: ParameterLayout, block: Block, free: bool) {
        let offset = layout.offset(block);
        self.free[offset..offset + 6].fill(free);
    }

    /// Frees or fixes one parameter.
    pub fn set(&mut self, index: usize, free: bool) {
        self.free[index] = free;
    }

    /// One flag per parameter, `true` where free.
    pub fn flags(&self) -> &[bool] {
        &self.free
    }

    /// Indices of the free parameters, ascending.
    pub fn free_indices(&self) -> Vec<usize> {
        self.free.iter().enumerate().filter(|(_, f)| **f).map(|(i, _)| i).collect()
    }
}
