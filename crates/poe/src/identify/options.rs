//! What the identification is told: observations, solver choice, weights and masks.

use crate::{Block, ParameterLayout};
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
/// divided by its sigma, so metres and radians become comparable.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct IdentificationOptions {
    /// The linear solver of each iteration.
    pub solver: Solver,
    /// At most this many iterations.
    pub max_iterations: usize,
    /// Stop when the weighted cost decreases by less than this fraction in one iteration.
    pub tolerance: f64,
    /// Noise of a position residual, metres.
    pub position_sigma_m: f64,
    /// Noise of an orientation residual, radians.
    pub rotation_sigma_rad: f64,
    /// Relative singular-value threshold below which a direction counts as unidentifiable.
    pub rcond: f64,
}

impl Default for IdentificationOptions {
    fn default() -> Self {
        Self {
            solver: Solver::PseudoInverse,
            max_iterations: 50,
            tolerance: 1e-10,
            position_sigma_m: 1e-4,
            rotation_sigma_rad: 1e-4,
            rcond: 1e-9,
        }
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
