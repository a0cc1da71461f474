//! `--effects auto`'s held-out prediction with the GP stage on top: the diagnosis
//! predicts the error of the geometry and the selected effects on held-out rows (random folds, and
//! arcs of each moving joint's angles); a method with a GP fits a GP on what they leave, which the
//! diagnosis never sees. Here, after the final GP's hyperparameters are chosen, the same folds are
//! used again: in each, a GP with those hyperparameters (and its input standardisation and output
//! normalisation) is conditioned on the residuals that fold's geometry and effects leave on its
//! training rows, and predicts its held-out rows; the held-out position error after it is the
//! prediction. In an arc, where the model fades its series and blends to the geometry fitted
//! alone, the correction blends likewise to the model's fallback GP (`ResidualGp::fallback`)
//! conditioned on what the fold's geometry alone leaves, as the model's does.
//!
//! The hyperparameters are held fixed across the folds, a standard approximation (R&W Section
//! 5.4.2 does the same for leave-one-out): searching them again in every fold would repeat the
//! GP's whole search 5 + 10 × (moving joints) times. With them fixed, every fold is predicted in
//! closed form from one factorisation per kernel ([`gp::ExactGp::held_out_with_fixed_hyperparameters`]).
//!
//! The residuals are the diagnosis's linearised ones, measured minus modelled position (m) and
//! orientation (rad): to first order the GP's outputs in its default tool-point frame, whose `v`
//! part is the position error. The GP's tracker-frame residual mixes the orientation times the
//! lever arm into `v`, and the sparse GP has no closed form: for those, no prediction (`None`).

use diagnose::{FoldResiduals, HeldoutFolds};
use errors::Error;
use faer::Mat;
use model::{GpModel, ResidualFrame, ResidualGp};
use serde::Serialize;

/// The held-out error predicted with the GP on top of the geometry and the selected effects.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PredictedWithGp {
    /// Mean held-out position error on poses like the training poses (the random folds), mm.
    pub on_poses_mm: f64,
    /// Off them (the arcs of each moving joint's angles held out, the mean over the joints as
    /// `off_poses_mm` is), mm; `None` where no joint moves.
    pub off_poses_mm: Option<f64>,
    /// Per moving joint, its arcs' mean held-out position error with the GP (as
    /// `diagnose::ArcCheck::after_mm` is without it).
    pub arcs: Vec<ArcWithGp>,
    /// Where the model has a fallback GP (`model::ResidualGp::fallback`): the arcs' prediction
    /// with it and without it, and whether the fit kept it. The numbers above are the kept
    /// variant's. Absent without one.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fallback_gp: Option<FallbackGpChoice>,
}

/// Whether the fit keeps its fallback GP, from the arcs' prediction with it and without it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FallbackGpChoice {
    /// Off the poses (the arcs), with the fallback GP where a row fades, mm.
    pub off_poses_with_mm: Option<f64>,
    /// The same with the GP alone on the blended pose (no fallback GP), mm.
    pub off_poses_without_mm: Option<f64>,
    /// Whether the fallback GP is kept: it predicts the arcs at least as well.
    pub kept: bool,
}

/// One moving joint's arcs held out, with the GP on top.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ArcWithGp {
    /// The 1-based joint whose arcs are held out.
    pub joint: usize,
    /// Mean held-out position error, mm.
    pub mean_mm: f64,
}

/// The prediction for `gp` (the final GP, `config` its fit's configuration, for the jitter) over
/// the diagnosis's `folds`, rows within `repeat_tolerance` in every joint one configuration
/// ([`model::RepeatGroups`]); `None` where it cannot be made (see the module doc) or there are no
/// folds.
pub(crate) fn predicted_with_gp(
    gp: &ResidualGp,
    folds: &HeldoutFolds,
    config: &gp::GpConfig,
    repeat_tolerance: f64,
) -> Result<Option<PredictedWithGp>, Error> {
    let GpModel::Exact(exact) = &gp.gp else { return Ok(None) };
    if (gp.full_pose && gp.residual_frame != ResidualFrame::ToolPoint) || gp.moved_by.is_some() {
        return Ok(None);
    }
    if folds.random.is_empty() || folds.rows.is_empty() {
        return Ok(None);
    }
    let (n, m) = (folds.rows.len(), exact.output_count());
    let x = gp.inputs_of(&folds.rows, "the diagnosis's rows")?;
    let all: Vec<&FoldResiduals> = folds.random.iter().chain(folds.arcs.iter().flat_map(|(_, f)| f)).collect();
    let targets: Vec<Mat<f64>> =
        all.iter().map(|f| Mat::from_fn(n, m, |i, c| f.residuals.get(i).map_or(0.0, |r| r[c]))).collect();
    let kept_from_gp = with_repeats(folds, &all, repeat_tolerance);
    // Only the position outputs: the position error is what is predicted.
    let predicted = exact
        .held_out_with_fixed_hyperparameters(x.as_ref(), &fold_targets(&kept_from_gp, &targets), &[0, 1, 2], config)
        .map_err(Error::gp)?;
    // Where the model keeps a GP of what the geometry alone leaves (`ResidualGp::fallback`), a
    // faded row's correction blends to it as the model's does: the same folds, conditioned on
    // what each fold's geometry alone leaves, with that GP's hyperparameters.
    let alone = match &gp.fallback {
        Some(GpModel::Exact(fallback)) if all.iter().any(|f| !f.alone.is_empty()) => {
            let targets: Vec<Mat<f64>> =
                all.iter().map(|f| Mat::from_fn(n, m, |i, c| f.alone.get(i).map_or(0.0, |(r, _)| r[c]))).collect();
            let buffered = buffered_arcs(folds, &all, &kept_from_gp);
            Some(
                fallback
                    .held_out_with_fixed_hyperparameters(
                        x.as_ref(),
                        &fold_targets(&buffered, &targets),
                        &[0, 1, 2],
                        config,
                    )
                    .map_err(Error::gp)?,
            )
        }
        _ => None,
    };
    let with = summary(folds, &fold_errors(&all, &predicted, alone.as_deref(), true));
    if alone.is_none() {
        return Ok(Some(with));
    }
    // The fallback GP is kept where the arcs say it predicts the faded rows at least as well as
    // the GP learnt on what the effects leave: which carries better off the effects' angles
    // depends on the data (`docs/results/splits.md`), and the arcs are the folds that hold such rows
    // out.
    let without = summary(folds, &fold_errors(&all, &predicted, alone.as_deref(), false));
    let choice = FallbackGpChoice {
        off_poses_with_mm: with.off_poses_mm,
        off_poses_without_mm: without.off_poses_mm,
        kept: match (with.off_poses_mm, without.off_poses_mm) {
            (Some(a), Some(b)) => a <= b,
            _ => true,
        },
    };
    let chosen = if choice.kept { with } else { without };
    Ok(Some(PredictedWithGp { fallback_gp: Some(choice), ..chosen }))
}

/// Each fold's rows as the GP's held-out rows, each fold's targets beside them.
fn fold_targets<'a>(held_out: &'a [Vec<usize>], targets: &'a [Mat<f64>]) -> Vec<gp::FoldTargets<'a>> {
    held_out.iter().zip(targets).map(|(rows, y)| gp::FoldTargets { held_out: rows, y: y.as_ref() }).collect()
}

/// Each fold's held-out rows and their repeats (the same configuration measured again): those are
/// kept from its fold's GP too, as the fit's leave-group-out error keeps them, since the GP would
/// return the twin's value. They are the first rows' company only: predicted, never counted.
fn with_repeats(folds: &HeldoutFolds, all: &[&FoldResiduals], repeat_tolerance: f64) -> Vec<Vec<usize>> {
    let n = folds.rows.len();
    let repeats = model::RepeatGroups::of(&folds.rows, repeat_tolerance);
    let mut group_of = vec![0; n];
    for (g, rows) in repeats.groups.iter().enumerate() {
        for &i in rows {
            group_of[i] = g;
        }
    }
    all.iter()
        .map(|f| {
            let mut rows = f.held_out.clone();
            let mut taken = vec![false; n];
            rows.iter().for_each(|&i| taken[i] = true);
            for &i in &f.held_out {
                for &j in &repeats.groups[group_of[i]] {
                    if !taken[j] {
                        taken[j] = true;
                        rows.push(j);
                    }
                }
            }
            rows
        })
        .collect()
}

/// The fallback GP's held-out rows: an arc's own rows and, beside them, the rows within one arc's
/// width of it on either side: a GP bridges a narrow arc of the joint it learns, which a model
/// meeting a wider gap or the end of the range cannot (blocked cross-validation with a buffer,
/// Roberts et al., Ecography 40, 2017). The geometry and effects keep their folds; the random
/// folds keep `kept_from_gp`'s rows.
fn buffered_arcs(folds: &HeldoutFolds, all: &[&FoldResiduals], kept_from_gp: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = folds.rows.len();
    let joint_of: Vec<Option<usize>> = std::iter::repeat_n(None, folds.random.len())
        .chain(folds.arcs.iter().flat_map(|(joint, arcs)| std::iter::repeat_n(Some(joint - 1), arcs.len())))
        .collect();
    kept_from_gp
        .iter()
        .zip(all)
        .zip(&joint_of)
        .map(|((rows, f), joint)| {
            let Some(j) = *joint else { return rows.clone() };
            let angles = f.held_out.iter().map(|&i| folds.rows[i].q[j]);
            let (lo, hi) = angles.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), q| (a.min(q), b.max(q)));
            let width = hi - lo;
            let mut taken = vec![false; n];
            rows.iter().for_each(|&i| taken[i] = true);
            let mut rows = rows.clone();
            for (i, row) in folds.rows.iter().enumerate() {
                if !taken[i] && (lo - width..=hi + width).contains(&row.q[j]) {
                    rows.push(i);
                }
            }
            rows
        })
        .collect()
}

/// Per fold, the held-out position errors after the GP (`predicted`, per fold), m: with the
/// fallback GP (`alone`, per fold) where a row fades (`blend`), or with the GP alone on the
/// blended pose, as a model without one does.
fn fold_errors(
    all: &[&FoldResiduals],
    predicted: &[Mat<f64>],
    alone: Option<&[Mat<f64>]>,
    blend: bool,
) -> Vec<Vec<f64>> {
    all.iter()
        .enumerate()
        .map(|(k, f)| {
            let g = &predicted[k];
            f.held_out
                .iter()
                .enumerate()
                .map(|(a, &i)| {
                    let r = f.residuals[i];
                    let w = f.alone.get(i).map_or(1.0, |&(_, w)| w);
                    let correction = |c: usize| match alone {
                        Some(g0) if blend && w < 1.0 => w * g[(a, c)] + (1.0 - w) * g0[k][(a, c)],
                        _ => g[(a, c)],
                    };
                    (0..3).map(|c| (r[c] - correction(c)).powi(2)).sum::<f64>().sqrt()
                })
                .collect()
        })
        .collect()
}

/// The mean of the folds' errors (m), mm.
fn mean_mm(folds: &[Vec<f64>]) -> f64 {
    let count: usize = folds.iter().map(Vec::len).sum();
    folds.iter().flatten().sum::<f64>() / count.max(1) as f64 * 1e3
}

/// The prediction from every fold's errors (`errors`, the random folds first, then each moving
/// joint's arcs), without a fallback GP choice.
fn summary(folds: &HeldoutFolds, errors: &[Vec<f64>]) -> PredictedWithGp {
    let random = folds.random.len();
    let mut start = random;
    let mut per_joint = Vec::with_capacity(folds.arcs.len());
    for (joint, arcs) in &folds.arcs {
        per_joint.push(ArcWithGp { joint: *joint, mean_mm: mean_mm(&errors[start..start + arcs.len()]) });
        start += arcs.len();
    }
    let off_poses_mm =
        (!per_joint.is_empty()).then(|| per_joint.iter().map(|a| a.mean_mm).sum::<f64>() / per_joint.len() as f64);
    PredictedWithGp { on_poses_mm: mean_mm(&errors[..random]), off_poses_mm, arcs: per_joint, fallback_gp: None }
}
