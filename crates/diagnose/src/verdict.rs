//! The verdict: name an effect only when it explains most of what can be explained.
//!
//! "What can be explained" is measured by a cross-validated GP on the joint angles (module
//! `structure`): fitted to the geometric model's held-out residual, and to what the selected
//! effects leave. A named effect must account for at least `min_explained_fraction` of the largest
//! reduction of the mean held-out error that the effects, the GP, or the effects and then the GP
//! achieve; otherwise the residual holds
//! something the candidates do not model (a coupling between joints, an effect outside the list)
//! and the honest verdict is `unknown`, with the inputs the GP found the structure in.

use super::candidates::Effect;
use super::statistics::{mean, signed_rank_z};
use super::structure::{GpInput, Structure};
use serde::{Deserialize, Serialize};

/// When to say `unknown`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct VerdictOptions {
    /// The GP must lower the mean held-out error by at least this fraction for the residual to
    /// count as structured (10 %: below that, a GP's gain on a few hundred poses is within what
    /// the choice of its hyperparameters moves it by).
    pub structure_min_gain: f64,
    /// The share of the explainable reduction of the mean held-out error a named effect must
    /// achieve: "most", i.e. more than half.
    pub min_explained_fraction: f64,
    /// `none` means the geometric model is at the noise floor: with nothing selected and a
    /// held-out error above this multiple of the floor the verdict is `unknown` even when the GP
    /// finds no structure (an error too rough for a GP on a few hundred poses, or noise larger
    /// than the floor says). 1.5: with a few hundred poses the mean error scatters by a few per
    /// cent, so 50 % above the floor is not noise.
    pub none_max_floor_ratio: f64,
}

impl Default for VerdictOptions {
    fn default() -> Self {
        Self { structure_min_gain: 0.1, min_explained_fraction: 0.5, none_max_floor_ratio: 1.5 }
    }
}

/// The SPEC's `verdict`: the effect that explains the residual and the joints it involves.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Verdict {
    /// The effect.
    pub effect: Effect,
    /// 1-based joints, ascending; empty where none. For `unknown`, the joints whose angles the
    /// GP found the unexplained structure in.
    pub joints: Vec<usize>,
}

/// What a cross-validated GP finds in one residual.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpCheck {
    /// Cross-validated mean position error once the GP's prediction is removed, mm.
    pub heldout_after_gp_mm: f64,
    /// Signed-rank statistic of the GP's per-pose gain.
    pub z: f64,
    /// Relative drop of the mean held-out error.
    pub gain: f64,
    /// Whether the gain is significant and at least `structure_min_gain`.
    pub significant: bool,
    /// Each input's length scale in its standard deviations (short = the structure lies there).
    pub length_scales: Vec<InputScale>,
}

/// The length scale of one GP input.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InputScale {
    /// The input.
    pub input: GpInput,
    /// Length scale, standard deviations of the input.
    pub length_scale: f64,
}

impl GpCheck {
    /// The check of `structure` against the residual errors `before` (m).
    pub(crate) fn new(before: &[f64], structure: &Structure, critical_z: f64, options: &VerdictOptions) -> Self {
        let z = signed_rank_z(before, &structure.errors);
        let gain = 1.0 - structure.mean_error() / mean(before).max(f64::MIN_POSITIVE);
        Self {
            heldout_after_gp_mm: structure.mean_error() * 1e3,
            z,
            gain,
            significant: z > critical_z && gain >= options.structure_min_gain,
            length_scales: structure
                .inputs
                .iter()
                .zip(&structure.length_scales)
                .map(|(input, &length_scale)| InputScale { input: input.clone(), length_scale })
                .collect(),
        }
    }
}

/// The numbers the verdict is decided on (held-out position errors per pose, m).
pub(crate) struct Evidence<'a> {
    /// The geometric model.
    pub before: &'a [f64],
    /// With every selected effect.
    pub selected: &'a [f64],
    /// The GP on the geometric model's residual, if it ran.
    pub gp_before: Option<(&'a [f64], bool)>,
    /// The GP on what the selected effects leave, if it ran.
    pub gp_after: Option<&'a [f64]>,
    /// The noise floor (mean position error of a perfect model), m.
    pub floor: f64,
}

/// The decision and its reason.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Decision {
    /// Whether the verdict is `unknown` (otherwise the first selected effect, or `none`).
    pub unknown: bool,
    /// The share of the explainable reduction of the mean held-out error the selected effects
    /// achieve (`None` when nothing is selected or no GP ran).
    pub explained_fraction: Option<f64>,
}

/// Decides between naming the selected effects, `none` and `unknown`.
pub(crate) fn decide(evidence: &Evidence<'_>, any_selected: bool, options: &VerdictOptions) -> Decision {
    let before = mean(evidence.before);
    let explained = before - mean(evidence.selected);
    let by_gp_before = evidence.gp_before.map_or(0.0, |(e, _)| before - mean(e));
    let by_gp_after = evidence.gp_after.map_or(0.0, |e| before - mean(e));
    let explainable = explained.max(by_gp_before).max(by_gp_after);
    if !any_selected {
        let structured = evidence.gp_before.is_some_and(|(_, significant)| significant);
        let above_floor = before > options.none_max_floor_ratio * evidence.floor;
        return Decision { unknown: structured || above_floor, explained_fraction: None };
    }
    if evidence.gp_before.is_none() && evidence.gp_after.is_none() {
        return Decision { unknown: false, explained_fraction: None };
    }
    let fraction = if explainable > 0.0 { explained / explainable } else { 1.0 };
    Decision { unknown: fraction < options.min_explained_fraction, explained_fraction: Some(fraction) }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_effect_that_explains_most_of_what_a_gp_explains_is_named() {
        let before = [1.0; 10];
        let selected = [0.3; 10];
        let gp = [0.4; 10];
        let after = [0.25; 10];
        let evidence = Evidence {
            before: &before,
            selected: &selected,
            gp_before: Some((&gp, true)),
            gp_after: Some(&after),
            floor: 0.2,
        };
        let d = decide(&evidence, true, &VerdictOptions::default());
        assert!(!d.unknown);
        // (1 − 0.3) / (1 − 0.25)
        assert!((d.explained_fraction.unwrap() - 0.7 / 0.75).abs() < 1e-12);
    }

    #[test]
    fn an_effect_that_explains_a_small_part_of_the_structure_is_unknown() {
        // A coupling: the best candidate takes 1 → 0.9, a GP 1 → 0.4.
        let before = [1.0; 10];
        let selected = [0.9; 10];
        let gp = [0.4; 10];
        let evidence =
            Evidence { before: &before, selected: &selected, gp_before: Some((&gp, true)), gp_after: None, floor: 0.2 };
        let d = decide(&evidence, true, &VerdictOptions::default());
        assert!(d.unknown);
        assert!((d.explained_fraction.unwrap() - 0.1 / 0.6).abs() < 1e-12);
    }

    #[test]
    fn nothing_selected_is_unknown_only_when_the_gp_finds_significant_structure() {
        let before = [1.0; 10];
        let gp = [0.5; 10];
        for significant in [true, false] {
            let evidence = Evidence {
                before: &before,
                selected: &before,
                gp_before: Some((&gp, significant)),
                gp_after: None,
                floor: 0.9,
            };
            assert_eq!(decide(&evidence, false, &VerdictOptions::default()).unknown, significant);
        }
        let evidence = Evidence { before: &before, selected: &before, gp_before: None, gp_after: None, floor: 0.9 };
        assert!(!decide(&evidence, false, &VerdictOptions::default()).unknown);
    }

    #[test]
    fn an_error_far_above_the_floor_that_nothing_explains_is_unknown_not_none() {
        let before = [1.0; 10];
        let gp = [1.05; 10];
        for (floor, unknown) in [(0.9, false), (0.5, true)] {
            let evidence =
                Evidence { before: &before, selected: &before, gp_before: Some((&gp, false)), gp_after: None, floor };
            assert_eq!(decide(&evidence, false, &VerdictOptions::default()).unknown, unknown, "floor {floor}");
        }
    }
}
