//! A Gaussian prior on the kinematic parameters about a given model: the
//! identification becomes a maximum a posteriori fit that keeps what the data determines only
//! weakly at that model (the nominal geometry at its fitted base and tool placement), instead of
//! letting noise and non-geometric effects move it. Unlike `IdentificationOptions`'
//! `prior_translation_m` / `prior_rotation_rad`, which hold every free parameter about the start
//! of each identification, this prior has its own centre, which stays the same through several
//! identifications (the geometry alone, then with effects), and applies only to the blocks it
//! names (the base placement and the tools are usually left free).

use crate::{Block, Error, LocalPoe};

/// The prior: each chosen block's left perturbation from `centre`, `(v, ω)`, is Gaussian with
/// standard deviations `translation_m` and `rotation_rad` per component.
#[derive(Debug, Clone, PartialEq)]
pub struct KinematicPrior {
    /// The prior's mean.
    pub centre: LocalPoe,
    /// Standard deviation of a block's translation, metres.
    pub translation_m: f64,
    /// Standard deviation of a block's rotation, radians.
    pub rotation_rad: f64,
    /// Per block of the layout (joints, then tools), whether the prior applies to it.
    pub blocks: Vec<bool>,
}

impl KinematicPrior {
    /// A prior on the joints' local transforms after the first: the first (which carries the
    /// base placement) and the tools stay free, as in the base-tool fit that places the centre.
    pub fn on_links(centre: LocalPoe, translation_m: f64, rotation_rad: f64) -> Self {
        let layout = centre.layout();
        let blocks = (0..layout.joint_count + layout.tool_count).map(|b| b >= 1 && b < layout.joint_count).collect();
        Self { centre, translation_m, rotation_rad, blocks }
    }

    /// Checks the standard deviations (above 0, `inf` for none) and the block list's length
    /// against `layout`'s.
    pub(super) fn validate(&self, model: &LocalPoe) -> Result<(), Error> {
        for (name, value) in [("prior.translation_m", self.translation_m), ("prior.rotation_rad", self.rotation_rad)] {
            if value.is_nan() || value <= 0.0 {
                return Err(Error::InvalidOption { name, value, expected: "a number above 0 (inf for no prior)" });
            }
        }
        let layout = model.layout();
        if self.centre.layout() != layout || self.blocks.len() != layout.joint_count + layout.tool_count {
            return Err(Error::MaskLength { given: 6 * self.blocks.len(), expected: layout.len() });
        }
        Ok(())
    }

    /// The prior weight `1/σ` of each of the parameters `free` (0 where the prior does not apply).
    pub(super) fn weights(&self, free: &[usize]) -> Vec<f64> {
        free.iter()
            .map(|&index| {
                if !self.blocks[index / 6] {
                    0.0
                } else if index % 6 < 3 {
                    1.0 / self.translation_m
                } else {
                    1.0 / self.rotation_rad
                }
            })
            .collect()
    }

    /// The left perturbation of every block of `model` from the centre, `log(T · T_c⁻¹)`, at the
    /// indices `free`: where a solver's accumulated steps start.
    pub(super) fn deviation(&self, model: &LocalPoe, free: &[usize]) -> Vec<f64> {
        let layout = model.layout();
        let transform = |m: &LocalPoe, block: Block| match block {
            Block::Joint(i) => m.joints()[i].previous_from_joint_zero,
            Block::Tool(t) => m.tools()[t],
        };
        free.iter()
            .map(|&index| {
                let (block, component) = layout.block_of(index);
                let difference = transform(model, block) * transform(&self.centre, block).inverse();
                difference.log().to_vector()[component]
            })
            .collect()
    }
}
