//! Where each identified parameter sits in the parameter vector.

use serde::{Deserialize, Serialize};

/// The parameter vector of the identification (paper: `x = [δp_1ᵀ … δp_{n+1}ᵀ]ᵀ`), extended to
/// several tools: six numbers `(v, ω)` per joint frame `T_{i-1,i}(0)`, then six per tool transform.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct ParameterLayout {
    /// Number of joints.
    pub joint_count: usize,
    /// Number of tools.
    pub tool_count: usize,
}

/// Which transform a parameter block belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Block {
    /// `T_{i-1,i}(0)` of joint `i` (0-based).
    Joint(usize),
    /// `T_{n,n+1}(0)` of tool `t`.
    Tool(usize),
}

impl ParameterLayout {
    /// Number of parameters, `6 (n + tools)`.
    pub fn len(&self) -> usize {
        6 * (self.joint_count + self.tool_count)
    }

    /// Whether there are no parameters at all.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// First column of a block.
    pub fn offset(&self, block: Block) -> usize {
        match block {
            Block::Joint(i) => 6 * i,
            Block::Tool(t) => 6 * (self.joint_count + t),
        }
    }

    /// The block a parameter index belongs to, and the component (0–5, `(v, ω)` order) in it.
    pub fn block_of(&self, index: usize) -> (Block, usize) {
        let block = index / 6;
        if block < self.joint_count {
            (Block::Joint(block), index % 6)
        } else {
            (Block::Tool(block - self.joint_count), index % 6)
        }
    }
}
