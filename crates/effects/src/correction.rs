//! The effects as the identification sees them: the scaled features are fixed per row, the
//! directions follow the model being identified.

use super::{Direction, IdentifiedEffect, RowTwists};
use errors::Error;
use lie::Vector6;
use measurements::BoundSet;
use poe::LocalPoe;
use poe::identify::PoseCorrection;

/// Every parameter of a list of effects, as one [`PoseCorrection`].
#[derive(Debug)]
pub struct EffectCorrection {
    directions: Vec<Direction>,
    /// `[row][parameter]`.
    features: Vec<Vec<f64>>,
    q: Vec<Vec<f64>>,
    tools: Vec<usize>,
    prior_sigma: Vec<f64>,
}

impl EffectCorrection {
    /// The correction of `effects` on the rows of `data`, every parameter with the prior
    /// standard deviation `prior_sigma` about zero.
    pub fn new(effects: &[IdentifiedEffect], data: &BoundSet<'_>, prior_sigma: f64) -> Result<Self, Error> {
        let directions: Vec<Direction> = effects.iter().flat_map(IdentifiedEffect::directions).collect();
        let features = data
            .iter()
            .map(|(row, tool)| {
                let mut all = Vec::with_capacity(directions.len());
                for effect in effects {
                    all.extend(effect.features(row, tool)?);
                }
                Ok(all)
            })
            .collect::<Result<_, Error>>()?;
        Ok(Self {
            prior_sigma: effects.iter().flat_map(IdentifiedEffect::prior_scale).map(|s| s * prior_sigma).collect(),
            directions,
            features,
            q: data.rows().iter().map(|r| r.q.clone()).collect(),
            tools: data.tools().to_vec(),
        })
    }

    /// Splits the identified parameters back into the effects, in order.
    pub fn distribute(effects: &mut [IdentifiedEffect], theta: &[f64]) {
        let mut offset = 0;
        for effect in effects {
            let count = effect.parameter_count();
            effect.set_theta(&theta[offset..offset + count]);
            offset += count;
        }
    }
}

impl PoseCorrection for EffectCorrection {
    fn parameter_count(&self) -> usize {
        self.directions.len()
    }

    fn twists(&self, model: &LocalPoe, index: usize, out: &mut [Vector6]) {
        let mut twists = RowTwists::new(model, &self.q[index], self.tools[index]);
        for ((o, direction), f) in out.iter_mut().zip(&self.directions).zip(&self.features[index]) {
            // The directions were checked when the effects were built on these rows; a failure
            // here (a joint beyond the model) leaves the parameter without effect.
            *o = twists.twist(*direction).map_or_else(|_| Vector6::zeros(), |t| t * *f);
        }
    }

    fn prior_sigma(&self, parameter: usize) -> f64 {
        self.prior_sigma[parameter]
    }

    fn joint(&self, parameter: usize) -> Option<usize> {
        match self.directions[parameter] {
            Direction::Joint(j) => Some(j),
            // A fixed twist does not follow the kinematics; the arm's growth does, but its
            // derivative (strain 1e-5 to 1e-4 times a link change) is far below the noise.
            // A link's bend follows the kinematics too, but it is not a joint's twist: its
            // derivative in the geometry (a bend of mrad times a link change of mm) is far below
            // the noise, as the growth's.
            Direction::Component(_) | Direction::LinkGrowth | Direction::LinkBend { .. } => None,
        }
    }
}
