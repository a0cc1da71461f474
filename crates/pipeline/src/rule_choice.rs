//! What the session choice (`sessions.rs`) and the payload choice (`payloads.rs`) share: the
//! training rows refitted without one fold at a time, the fold's rows predicted under each rule an
//! effect may take beyond its span, and the one-standard-error decision between the kind's own
//! rule and the best of the others.

use crate::fit_options::FitOptions;
use effects::{BeyondSpan, EffectSelection, EffectSpec, IdentifiedEffect};
use errors::Error;
use measurements::MeasurementSet;
use model::CalibratedModel;

/// The options of a fold's fit: `poe` with the items `specs` (what `auto` chose, not chosen
/// again), no prior strength, session rule or payload rule chosen inside it, and the plausibility
/// checks passed (the full data passed them).
pub(crate) fn fold_options(options: &FitOptions, specs: &[EffectSpec]) -> FitOptions {
    let mut fold = options.clone().with_effects(EffectSelection::List(specs.to_vec()));
    fold.effects.sessions.choose = false;
    fold.effects.payloads.choose = false;
    fold.nominal_prior.choose = false;
    fold.plausibility.force = true;
    fold
}

/// Why a fold gave no errors: its fit failed, or its rows could not be predicted.
pub(crate) enum FoldFailure {
    /// The fit without the fold.
    Fit(Error),
    /// The prediction of the fold's rows.
    Predict(Error),
}

/// One effect to choose for: its index in the fit's effects and the rules to try, its own first.
pub(crate) struct Target {
    pub(crate) effect: usize,
    pub(crate) rules: Vec<BeyondSpan>,
}

/// The left-out rows' position errors, mm, `[target][rule][row]`: each fold of `folds` (row
/// indices of `data`) left out in turn, the rest fitted by `fit` with `fold_options`, and the
/// fold's rows predicted with one target's rule set by `set` to each of its rules (the other
/// effects as the fold's fit left them).
pub(crate) fn held_out_errors(
    data: &MeasurementSet,
    folds: &[Vec<usize>],
    fold_options: &FitOptions,
    targets: &[Target],
    set: fn(&mut IdentifiedEffect, BeyondSpan),
    fit: impl Fn(&MeasurementSet, &FitOptions) -> Result<CalibratedModel, Error>,
) -> Result<Vec<Vec<Vec<f64>>>, FoldFailure> {
    let mut errors: Vec<Vec<Vec<f64>>> = targets.iter().map(|t| vec![Vec::new(); t.rules.len()]).collect();
    for fold in folds {
        let left_out: std::collections::BTreeSet<usize> = fold.iter().copied().collect();
        let train: Vec<usize> = (0..data.rows.len()).filter(|i| !left_out.contains(i)).collect();
        let test = data.subset(fold);
        let fitted = fit(&data.subset(&train), fold_options).map_err(FoldFailure::Fit)?;
        for (target, errors) in targets.iter().zip(&mut errors) {
            for (&rule, errors) in target.rules.iter().zip(errors.iter_mut()) {
                let mut model = fitted.clone();
                set(&mut model.effects[target.effect], rule);
                let evaluation = model
                    .bind(&test)
                    .and_then(|bound| model::evaluate(&model, &bound))
                    .map_err(FoldFailure::Predict)?;
                errors.extend(evaluation.errors.iter().map(|e| e.position_mm));
            }
        }
    }
    Ok(errors)
}

/// The outcome of [`one_standard_error`].
pub(crate) struct Decision {
    /// The rule kept.
    pub(crate) chosen: BeyondSpan,
    /// Whether it is not the kind's own.
    pub(crate) switched: bool,
    /// The mean left-out error under each rule, in the order given, mm.
    pub(crate) means: Vec<f64>,
    /// The standard error of the paired differences between the best other rule and the own, mm.
    pub(crate) standard_error: f64,
    /// The rows compared.
    pub(crate) rows: usize,
}

/// Keeps `rules[0]`, the kind's own rule, unless the other rule of lowest mean error (`errors[r]`:
/// the same rows under `rules[r]`) is lower by more than one standard error of the rows' paired
/// differences (Breiman's one-standard-error rule, as the nominal prior's strength), so that a
/// difference the rows cannot tell from noise does not change the model.
pub(crate) fn one_standard_error(rules: &[BeyondSpan], errors: &[Vec<f64>]) -> Decision {
    let own = &errors[0];
    let n = own.len().max(1) as f64;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / n;
    let means: Vec<f64> = errors.iter().map(|e| mean(e)).collect();
    let best = (1..rules.len()).min_by(|&a, &b| means[a].total_cmp(&means[b]));
    let Some(best) = best else {
        return Decision { chosen: rules[0], switched: false, means, standard_error: 0.0, rows: own.len() };
    };
    let differences: Vec<f64> = errors[best].iter().zip(own).map(|(o, s)| o - s).collect();
    let gain = mean(&differences);
    let spread = (differences.iter().map(|d| (d - gain).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    let standard_error = spread / n.sqrt();
    let switched = gain < -standard_error;
    let chosen = if switched { rules[best] } else { rules[0] };
    Decision { chosen, switched, means, standard_error, rows: own.len() }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_own_rule_stays_unless_another_is_lower_by_more_than_one_standard_error() {
        let rules = [BeyondSpan::Hold, BeyondSpan::Zero, BeyondSpan::Extend];
        let own = vec![1.0, 2.0, 3.0, 4.0];
        // Extend lower on every row by 0.5 (no spread): switched; zero higher.
        let better: Vec<f64> = own.iter().map(|e| e - 0.5).collect();
        let worse: Vec<f64> = own.iter().map(|e| e + 1.0).collect();
        let decision = one_standard_error(&rules, &[own.clone(), worse.clone(), better]);
        assert_eq!((decision.chosen, decision.switched, decision.rows), (BeyondSpan::Extend, true, 4));
        assert_eq!(decision.means, vec![2.5, 3.5, 2.0]);
        // Lower on average but within one standard error: kept.
        let noisy = vec![0.0, 3.5, 2.0, 4.2];
        let decision = one_standard_error(&rules, &[own.clone(), worse, noisy]);
        assert_eq!((decision.chosen, decision.switched), (BeyondSpan::Hold, false));
        assert!(decision.standard_error > 0.3, "{}", decision.standard_error);
        // One rule alone: nothing to compare.
        assert_eq!(one_standard_error(&rules[..1], &[own]).chosen, BeyondSpan::Hold);
    }
}
