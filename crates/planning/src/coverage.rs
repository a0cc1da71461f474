//! Coverage of each moving joint's range (and of the payloads): the angle-dependent effects
//! (gear periodic error, backlash, compliance) are identified, and held, only on the angles the
//! poses visit (a calibrated model's effects fade outside them), which a D-optimal design for the
//! geometry alone does not care about: it favours the ends of each range.

use crate::design::Design;
use serde::Serialize;

/// One input's bins.
#[derive(Debug, Clone)]
pub struct Axis {
    /// `joint 3` or `payload_kg`.
    pub name: String,
    /// The bin of every candidate.
    pub bin: Vec<usize>,
    /// Number of bins.
    pub bins: usize,
}

impl Axis {
    /// `bins` equal bins over the values' range.
    pub fn new(name: String, values: &[f64], bins: usize) -> Self {
        let low = values.iter().copied().fold(f64::INFINITY, f64::min);
        let high = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let width = (high - low) / bins as f64;
        let bin =
            values.iter().map(|v| if width > 0.0 { (((v - low) / width) as usize).min(bins - 1) } else { 0 }).collect();
        Self { name, bin, bins }
    }

    fn counts(&self, chosen: &[usize]) -> Vec<usize> {
        let mut counts = vec![0; self.bins];
        for &c in chosen {
            counts[self.bin[c]] += 1;
        }
        counts
    }

    fn present(&self) -> Vec<bool> {
        let mut present = vec![false; self.bins];
        for &b in &self.bin {
            present[b] = true;
        }
        present
    }
}

/// How well one input's range is covered.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AxisCoverage {
    /// `joint 3` or `payload_kg`.
    pub input: String,
    /// Bins with at least one chosen pose.
    pub covered: usize,
    /// Bins with at least one candidate.
    pub possible: usize,
}

/// Swaps poses into empty bins (the candidate of the bin with the largest D-gain for the pose of
/// the design whose removal loses least and empties no occupied bin), until every bin that has
/// candidates has a pose or no swap is possible. Returns the swaps made.
pub fn cover(design: &mut Design<'_>, axes: &[Axis]) -> usize {
    let mut swaps = 0;
    let rounds: usize = axes.iter().map(|a| a.bins).sum();
    for _ in 0..rounds {
        let mut swapped = false;
        for axis in axes {
            let present = axis.present();
            for (bin, &present) in present.iter().enumerate() {
                if !present || axis.counts(design.chosen())[bin] > 0 {
                    continue;
                }
                let Some((incoming, _)) = design.best(|c| axis.bin[c] == bin) else { continue };
                let counts: Vec<Vec<usize>> = axes.iter().map(|a| a.counts(design.chosen())).collect();
                // The removal must leave every occupied bin occupied (the incoming pose may refill one).
                let removable = |position: usize| {
                    let c = design.chosen()[position];
                    axes.iter().zip(&counts).all(|(a, n)| n[a.bin[c]] > 1 || a.bin[incoming] == a.bin[c])
                };
                let outgoing = (0..design.chosen().len())
                    .filter(|&p| removable(p))
                    .map(|p| (p, design.loss(design.chosen()[p])))
                    .min_by(|a, b| a.1.total_cmp(&b.1));
                if let Some((position, _)) = outgoing {
                    design.replace(position, incoming);
                    swaps += 1;
                    swapped = true;
                }
            }
        }
        if !swapped {
            break;
        }
    }
    if swaps > 0 {
        design.refresh();
    }
    swaps
}

/// The coverage of every axis by `chosen`.
pub fn coverage(axes: &[Axis], chosen: &[usize]) -> Vec<AxisCoverage> {
    axes.iter()
        .map(|a| {
            let counts = a.counts(chosen);
            AxisCoverage {
                input: a.name.clone(),
                covered: counts.iter().filter(|&&n| n > 0).count(),
                possible: a.present().iter().filter(|&&p| p).count(),
            }
        })
        .collect()
}
