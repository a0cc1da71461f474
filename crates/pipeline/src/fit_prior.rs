//! The prior toward the nominal geometry: how strongly the identification holds
//! the links' local transforms at the nominal model (at its fitted base and tool placement).
//!
//! Never weaker than the posterior with the nominal's manufacturing tolerance as the prior's
//! width: one plain solve gives the scale of the residual, the tolerance is weighed
//! against it (the likelihood's noise is what the geometry leaves, not the tracker's alone), so
//! that directions of the parameter space the training poses determine poorly stay within the
//! tolerance of the nominal even where the data has one configuration cluster and nothing can be
//! held out. Where it has several, stronger candidates are chosen by cross-validation that holds
//! out whole configuration clusters (`clusters.rs`): a fit on one branch cannot
//! say how it does on another, and the held-out clusters say how strongly to hold it.

use crate::clusters::{self, BranchJoint, Cluster, HeightSplit, ScanOptions};
use errors::{Error, OptionOutOfRange, OptionValue, option};
use measurements::MeasurementSet;
use model::geometric::observations;
use poe::LocalPoe;
use poe::identify::{IdentificationOptions, IdentificationReport, Scope, calibrate_placed_with_prior, evaluate};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options of the prior toward the nominal geometry (`nominal_prior` in a fit options file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NominalPriorOptions {
    /// Hold the links at the nominal geometry: at least within its tolerance (the posterior),
    /// more strongly where holding out configuration clusters says so; `false`: never a prior
    /// (the paper's plain least squares).
    pub choose: bool,
    /// The nominal's manufacturing tolerance: the standard deviation of each component of a
    /// link's translation about the nominal, m: the weakest prior the fit takes. 1 mm: machining
    /// and assembly leave an industrial arm's link lengths and axis offsets off by tenths of a
    /// millimetre to a millimetre (the simulated cells' `campaign::Perturbation`, after Nubiola &
    /// Bonev 2013, ABB IRB 1600: 0.97 mm mean error before calibration), so a correction of
    /// several millimetres to a link is the fit absorbing something else.
    pub tolerance_translation_m: f64,
    /// The same for each component of a link's rotation, rad: 1 mrad, axis alignments off by
    /// tenths of a milliradian to a milliradian (same source).
    pub tolerance_rotation_rad: f64,
    /// The candidate standard deviations of a link's translation about the nominal, metres, held
    /// out across configuration clusters; those not below the posterior's (the tolerance over
    /// the residual's scale), and `inf`, are left out: the posterior is the weakest candidate.
    /// The rotation's is the translation's over `length_m`. From 10 mm down to 10 µm (the
    /// nominal geometry itself, placed), half a decade apart.
    pub translations_m: Vec<f64>,
    /// The length that turns a translation σ into a rotation σ (`σ_rot = σ_trans / length_m`): a
    /// rotation that moves a point at this distance as much as the translation. 1 m, the reach
    /// of the arms calibrated here (UR10 1.3 m, IRB 4400 1.96 m, iiwa 0.8 m).
    pub length_m: f64,
    /// A cluster is held out on its own only when it holds at least this share of the rows (its
    /// rows always train otherwise): a fold's error over a handful of poses near a singular angle
    /// says little. 5 %: on the UR10's series B, 17 of 1,495 rows lie just past the wrist's
    /// singular angle, and are no branch of their own.
    pub min_cluster_share: f64,
    /// Angles of a joint over a turn at which the Jacobian's determinant is evaluated to find its
    /// singular angles: 720, half a degree apart (a sign change is located between two of them by
    /// linear interpolation, far closer than `scan_tolerance_rad`).
    pub scan_steps: usize,
    /// Rows, spread over the data, at which a joint's singular angles must agree for the joint to
    /// separate branches: 8 (the shoulder's singular angles move by tens of degrees between any
    /// two poses of a campaign; the elbow's and the wrist's do not move at all).
    pub scan_probes: usize,
    /// How closely they must agree, rad: 0.01 (0.6°; the interpolation error on a 0.5° grid is
    /// below 0.01°).
    pub scan_tolerance_rad: f64,
    /// A prismatic joint (a lifting column, a linear track) splits the rows at its median into two
    /// clusters when its values span at least this, m: 0.1 (a column's stroke is metres and moves
    /// the arm's gravity and lever arms by as much; a track held at one position varies by
    /// micrometres).
    pub min_height_span_m: f64,
    /// Above this many rows the fit has no prior (the report says so): 20,000. The choice costs an extra
    /// fit per candidate and held-out cluster (about 30 on a 6-axis arm with four clusters): on
    /// the 242,000-row, 65.7 MB campaign of `cargo xtask hostile --with-memory` it would take the
    /// fit from under a minute to several and its peak past the 400 MB bound
    /// (`docs/results/nominal-prior.md`). A campaign of
    /// 20,000 poses is dense over the configurations it will be used in, which is where the prior
    /// matters least; the real campaigns this was measured on have 300–3,000 rows.
    pub max_rows: usize,
}

impl Default for NominalPriorOptions {
    fn default() -> Self {
        Self {
            choose: true,
            tolerance_translation_m: 1e-3,
            tolerance_rotation_rad: 1e-3,
            translations_m: vec![f64::INFINITY, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5, 1e-5],
            length_m: 1.0,
            min_cluster_share: 0.05,
            scan_steps: 720,
            scan_probes: 8,
            scan_tolerance_rad: 0.01,
            min_height_span_m: 0.1,
            max_rows: 20_000,
        }
    }
}

impl NominalPriorOptions {
    /// Checks every value once: the field at fault, its value and what is expected.
    pub fn validate(&self) -> Result<(), OptionOutOfRange> {
        let translations = &self.translations_m;
        OptionOutOfRange::check(
            "translations_m",
            OptionValue::Shown(format!("{translations:?}")),
            !translations.is_empty() && translations.iter().all(|t| !t.is_nan() && *t > 0.0),
            "at least one number above 0 (inf for no prior)",
        )?;
        option::above("tolerance_translation_m", self.tolerance_translation_m, 0.0)?;
        option::above("tolerance_rotation_rad", self.tolerance_rotation_rad, 0.0)?;
        option::above("min_height_span_m", self.min_height_span_m, 0.0)?;
        option::above("length_m", self.length_m, 0.0)?;
        let share = self.min_cluster_share;
        OptionOutOfRange::check(
            "min_cluster_share",
            share,
            share > 0.0 && share <= 0.5,
            "a number above 0 and at most 0.5",
        )?;
        option::above("scan_tolerance_rad", self.scan_tolerance_rad, 0.0)?;
        option::count_at_least("scan_steps", self.scan_steps, 8)?;
        option::at_least_one("max_rows", self.max_rows)?;
        option::count_at_least("scan_probes", self.scan_probes, 2)
    }
}

/// One candidate strength and its held-out error across the clusters.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PriorCandidate {
    /// σ of a link's translation, m (`null`: no prior).
    pub translation_m: Option<f64>,
    /// σ of a link's rotation, rad (`null`: no prior).
    pub rotation_rad: Option<f64>,
    /// The RMS position error over the held-out rows (each row held out once, with its
    /// cluster), mm.
    pub heldout_rms_position_mm: f64,
    /// The criterion: the RMS of the weighted residual (position over `position_sigma_m`,
    /// rotation over `rotation_sigma_rad`) over the held-out rows.
    pub heldout_score: f64,
}

/// What the fit chose for the prior toward the nominal geometry, and why.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PriorChoice {
    /// The joints whose singular angles separate branches of the arm.
    pub branch_joints: Vec<BranchJoint>,
    /// The prismatic joints whose median splits the rows into a lower and an upper cluster.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub height_splits: Vec<HeightSplit>,
    /// The data's configuration clusters, largest first.
    pub clusters: Vec<Cluster>,
    /// The nominal's tolerance, translation (m) and rotation (rad).
    pub tolerance: (f64, f64),
    /// How far the plain fit's weighted residual is above the stated noise, `√(χ² / (rows −
    /// rank))`, at least 1 (`null`: no plain fit was made): the posterior's σ is the tolerance
    /// over it.
    pub residual_scale: Option<f64>,
    /// The clusters held out in turn (labels).
    pub held_out: Vec<String>,
    /// Every candidate with its held-out error (empty where nothing was held out); the chosen one
    /// is the first within one standard error of the lowest (`choose`).
    pub candidates: Vec<PriorCandidate>,
    /// The chosen σ of a link's translation, m: the posterior's or a stronger one held out across
    /// the clusters (`null`: no prior, the plain least-squares fit).
    pub translation_m: Option<f64>,
    /// The chosen σ of a link's rotation, rad (`null`: no prior).
    pub rotation_rad: Option<f64>,
    /// Why.
    pub reason: String,
    /// The prior of the fit with effects, where there are effects and a prior: the chosen σ
    /// weighed against the residual the geometry with its effects leaves ([`EffectsPrior`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub with_effects: Option<EffectsPrior>,
}

/// The prior toward the nominal geometry in the fit with effects. The chosen σ is in
/// the units of the stated noise, weighed against the residual the geometry alone leaves
/// (`residual_scale`); with the effects identified that residual is smaller (a compliance the
/// geometry alone left as millimetres is down to the noise), and the same prior width in
/// metres is a σ larger by the ratio of the two scales. Kept as it was, it would hold the
/// geometry that many times (37 on a 7-axis arm with an unmodelled compliance) more tightly
/// than the tolerance says, and the effects would absorb what the geometry could not reach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EffectsPrior {
    /// `√(χ² / (rows − rank))` of the fit with the effects and no prior, at least 1 and at most
    /// the geometry's: effects never hold the geometry more tightly than it is held alone.
    pub residual_scale: f64,
    /// σ of a link's translation, m.
    pub translation_m: f64,
    /// σ of a link's rotation, rad.
    pub rotation_rad: f64,
}

impl PriorChoice {
    /// The chosen standard deviations, translation (m) and rotation (rad); `None`: no prior.
    pub fn chosen(&self) -> Option<(f64, f64)> {
        self.translation_m.zip(self.rotation_rad)
    }

    fn without(
        branch_joints: Vec<BranchJoint>,
        clusters: Vec<Cluster>,
        prior: &NominalPriorOptions,
        reason: String,
    ) -> Self {
        Self {
            branch_joints,
            height_splits: Vec::new(),
            clusters,
            tolerance: (prior.tolerance_translation_m, prior.tolerance_rotation_rad),
            residual_scale: None,
            held_out: Vec::new(),
            candidates: Vec::new(),
            translation_m: None,
            rotation_rad: None,
            reason,
            with_effects: None,
        }
    }

    /// The posterior's widths, translation (m) and rotation (rad): the nominal's tolerance
    /// weighed against the residual the geometry alone leaves, whatever strength was chosen;
    /// `None` where there is no prior (what the geometry's own uncertainty is reported under,
    /// `model::GeometryUncertainty`).
    pub fn posterior(&self) -> Option<(f64, f64)> {
        self.chosen()?;
        let scale = self.residual_scale?;
        Some((self.tolerance.0 / scale, self.tolerance.1 / scale))
    }

    /// [`PriorChoice::posterior`] of the fit with effects: the tolerance weighed against the
    /// residual the geometry with its effects leaves ([`EffectsPrior::residual_scale`]).
    pub fn posterior_with_effects(&self) -> Option<(f64, f64)> {
        self.chosen()?;
        let scale = self.with_effects?.residual_scale;
        Some((self.tolerance.0 / scale, self.tolerance.1 / scale))
    }

    /// The prior of the fit with effects, given the report of that fit without a prior
    /// (`plain`), and records it ([`EffectsPrior`]): the chosen σ times the geometry's residual
    /// scale over the effects' one. `None` where there is no prior.
    pub fn for_effects(&mut self, plain: &IdentificationReport) -> Option<(f64, f64)> {
        self.for_effects_at(residual_scale(plain))
    }

    /// [`PriorChoice::for_effects`] given the plain fit's residual scale (`plain_scale`, at
    /// least 1).
    fn for_effects_at(&mut self, plain_scale: f64) -> Option<(f64, f64)> {
        let (translation_m, rotation_rad) = self.chosen()?;
        let alone = self.residual_scale.unwrap_or(1.0);
        let scale = plain_scale.min(alone);
        let ratio = alone / scale;
        let prior = EffectsPrior {
            residual_scale: scale,
            translation_m: translation_m * ratio,
            rotation_rad: rotation_rad * ratio,
        };
        self.with_effects = Some(prior);
        Some((prior.translation_m, prior.rotation_rad))
    }
}

/// How far a fit's weighted residual is above the stated noise, `√(χ² / (rows − rank))`, at least
/// 1: below the stated noise, the likelihood is the stated noise's.
fn residual_scale(report: &IdentificationReport) -> f64 {
    let dof = report.residual_rows.saturating_sub(report.rank).max(1);
    (report.final_cost / dof as f64).sqrt().max(1.0)
}

impl std::fmt::Display for PriorChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.chosen() {
            Some((t, r)) => write!(
                f,
                "prior toward the nominal geometry: σ {:.3} mm / {:.3} mrad per link ({})",
                t * 1e3,
                r * 1e3,
                self.reason
            ),
            None => write!(f, "prior toward the nominal geometry: none ({})", self.reason),
        }?;
        match self.with_effects {
            Some(prior) => write!(
                f,
                "; with the effects σ {:.3} mm / {:.3} mrad (their residual {:.2} times the stated noise)",
                prior.translation_m * 1e3,
                prior.rotation_rad * 1e3,
                prior.residual_scale
            ),
            None => Ok(()),
        }
    }
}

/// Per row of `data`, the squared weighted residual of a model (position over
/// `position_sigma_m`, rotation over `rotation_sigma_rad`: the identification's criterion) and
/// the squared position error in mm².
fn heldout(model: &LocalPoe, data: &MeasurementSet, options: &IdentificationOptions) -> Result<Vec<(f64, f64)>, Error> {
    observations(data)
        .chunks(1)
        .map(|row| {
            let stats = evaluate(model, row).map_err(Error::kinematics)?;
            let rotation = stats.rms_rotation_rad.map_or(0.0, |r| r / options.rotation_sigma_rad);
            let loss = (stats.rms_position_m / options.position_sigma_m).powi(2) + rotation.powi(2);
            Ok((loss, (stats.rms_position_m * 1e3).powi(2)))
        })
        .collect()
}

/// Chooses the prior's strength for a fit of `scope` on `data`: each candidate of
/// `prior.translations_m` is fitted with each configuration cluster held out in turn and judged on
/// it, every row once. The candidate with the lowest mean held-out criterion is the best; the one
/// chosen is the first listed (the weakest prior, none first) whose mean is within one standard
/// error of the best's (the standard error of the rows' paired differences): Breiman's one
/// standard error rule (Breiman et al. 1984, §3.4.3), so that a difference the held-out rows cannot
/// tell from noise does not change the fit. With fewer than two clusters of `min_cluster_share`,
/// no prior.
pub fn choose(
    nominal: &LocalPoe,
    data: &MeasurementSet,
    identification: &IdentificationOptions,
    prior: &NominalPriorOptions,
) -> Result<PriorChoice, Error> {
    if let Some(reason) = skipped(data, prior) {
        return Ok(PriorChoice::without(Vec::new(), Vec::new(), prior, reason));
    }
    let base = Posterior::new(nominal, data, identification, prior)?;
    if base.branch_joints.is_empty() && base.height_splits.is_empty() {
        return Ok(base.without(one_cluster_reason(nominal), prior));
    }
    let least = (prior.min_cluster_share * data.rows.len() as f64).ceil() as usize;
    let folds: Vec<&Cluster> = base.found.iter().filter(|c| c.n >= least).collect();
    if folds.len() < 2 {
        let reason = format!(
            "one configuration cluster of at least {:.0} % of the rows ({}): nothing to hold out, the posterior",
            100.0 * prior.min_cluster_share,
            base.found.first().map_or("no rows".into(), |c| c.label.clone())
        );
        return Ok(base.without(reason, prior));
    }
    let splits = cluster_splits(&folds, data);
    let sigmas = candidate_sigmas(base.posterior, prior);
    let (usable, rows) = held_out_rows(nominal, &splits, &sigmas, identification);
    if usable.is_empty() {
        let reason =
            "no configuration cluster could be held out (a tool only it carries, or too few rows without it): \
                      the posterior"
                .to_owned();
        return Ok(base.without(reason, prior));
    }
    let held_out: Vec<String> = usable.iter().map(|&s| splits[s].0.clone()).collect();
    Ok(base.held_out_choice(held_out, &sigmas, &rows, prior))
}

/// Why the fit has no prior without looking at the data's clusters: switched off, or too many rows.
fn skipped(data: &MeasurementSet, prior: &NominalPriorOptions) -> Option<String> {
    if !prior.choose {
        return Some("switched off (nominal_prior.choose)".into());
    }
    (data.rows.len() > prior.max_rows).then(|| {
        format!(
            "{} rows, more than nominal_prior.max_rows = {}: the fit as without a prior (the prior costs a plain \
             fit more, and a fit per candidate and cluster)",
            data.rows.len(),
            prior.max_rows
        )
    })
}

/// The candidates held out: the posterior first (the weakest, which the one-standard-error rule
/// prefers), then the stronger of `translations_m`.
fn candidate_sigmas(posterior: (f64, f64), prior: &NominalPriorOptions) -> Vec<Option<(f64, f64)>> {
    let stronger = prior.translations_m.iter().filter(|&&t| t.is_finite() && t < posterior.0);
    std::iter::once(Some(posterior)).chain(stronger.map(|&t| Some((t, t / prior.length_m)))).collect()
}

/// The data's configuration clusters and the posterior of the nominal's tolerance, what every
/// choice reports.
struct Posterior {
    branch_joints: Vec<BranchJoint>,
    height_splits: Vec<HeightSplit>,
    found: Vec<Cluster>,
    /// The residual a plain fit leaves, times the stated noise.
    scale: f64,
    /// The posterior's widths, translation m and rotation rad.
    posterior: (f64, f64),
    /// The tolerance and the scale in words.
    tolerance: String,
}

impl Posterior {
    fn new(
        nominal: &LocalPoe,
        data: &MeasurementSet,
        identification: &IdentificationOptions,
        prior: &NominalPriorOptions,
    ) -> Result<Self, Error> {
        let scan = ScanOptions {
            steps: prior.scan_steps,
            probes: prior.scan_probes,
            tolerance_rad: prior.scan_tolerance_rad,
            min_height_span_m: prior.min_height_span_m,
        };
        let branch_joints = clusters::branch_joints(nominal, &data.rows, scan)?;
        let height_splits = clusters::height_splits(nominal, &data.rows, scan);
        let found = clusters::clusters(&branch_joints, &height_splits, &data.rows);
        // The posterior: the tolerance weighed against the residual a plain fit leaves. Below the
        // stated noise the likelihood is the stated noise's: the prior is never weaker than the
        // tolerance.
        let (_, plain) = calibrate_placed_with_prior(nominal, &observations(data), Scope::Full, None, identification)
            .map_err(Error::kinematics)?;
        let scale = residual_scale(&plain.report);
        let posterior = (prior.tolerance_translation_m / scale, prior.tolerance_rotation_rad / scale);
        let tolerance = format!(
            "the nominal's tolerance {:.3} mm / {:.3} mrad against a residual {scale:.2} times the stated noise",
            prior.tolerance_translation_m * 1e3,
            prior.tolerance_rotation_rad * 1e3
        );
        Ok(Self { branch_joints, height_splits, found, scale, posterior, tolerance })
    }

    /// The choice among the candidates (`sigmas`) by their rows held out in the clusters
    /// `held_out` (per candidate, every row's criterion and squared error): the one-standard-error
    /// rule's.
    fn held_out_choice(
        self,
        held_out: Vec<String>,
        sigmas: &[Option<(f64, f64)>],
        rows: &[Vec<(f64, f64)>],
        prior: &NominalPriorOptions,
    ) -> PriorChoice {
        let (candidates, chosen) = one_standard_error(sigmas, rows);
        let reason = format!(
            "{}; {} configuration clusters held out in turn: held-out RMS {:.4} mm, {:.4} mm at the tolerance",
            self.tolerance,
            held_out.len(),
            candidates[chosen].heldout_rms_position_mm,
            candidates[0].heldout_rms_position_mm
        );
        PriorChoice {
            branch_joints: self.branch_joints,
            height_splits: self.height_splits,
            clusters: self.found,
            tolerance: (prior.tolerance_translation_m, prior.tolerance_rotation_rad),
            residual_scale: Some(self.scale),
            held_out,
            translation_m: candidates[chosen].translation_m,
            rotation_rad: candidates[chosen].rotation_rad,
            candidates,
            reason,
            with_effects: None,
        }
    }

    /// The fit under the posterior, for `reason`: nothing held out chose otherwise.
    fn without(&self, reason: String, prior: &NominalPriorOptions) -> PriorChoice {
        let mut choice = PriorChoice::without(
            self.branch_joints.clone(),
            self.found.clone(),
            prior,
            format!("{}; {reason}", self.tolerance),
        );
        choice.height_splits = self.height_splits.clone();
        choice.residual_scale = Some(self.scale);
        (choice.translation_m, choice.rotation_rad) = (Some(self.posterior.0), Some(self.posterior.1));
        choice
    }
}

/// Why a robot without branch joints or height splits has one configuration cluster.
fn one_cluster_reason(nominal: &LocalPoe) -> String {
    let revolute = nominal.joints().iter().filter(|j| j.kind == poe::JointKind::Revolute).count();
    if revolute == 6 {
        "no joint's singular angles separate branches of the arm: one configuration cluster".to_owned()
    } else if revolute == nominal.joint_count() {
        format!("{} joints, not 6: the branches are not found, one configuration cluster", nominal.joint_count())
    } else {
        format!(
            "{revolute} revolute joints, not 6, and no prismatic joint spans nominal_prior.min_height_span_m: \
             one configuration cluster"
        )
    }
}

/// Each fold trains on every other row; a fold whose rows carry a tool no other row carries
/// cannot be predicted and is not held out. Per fold: its label, its training and its held-out rows.
fn cluster_splits(folds: &[&Cluster], data: &MeasurementSet) -> Vec<(String, MeasurementSet, MeasurementSet)> {
    folds
        .iter()
        .filter_map(|cluster| {
            let held: std::collections::BTreeSet<usize> = cluster.rows.iter().copied().collect();
            let train: Vec<usize> = (0..data.rows.len()).filter(|i| !held.contains(i)).collect();
            let tools_known =
                cluster.rows.iter().all(|&i| train.iter().any(|&t| data.rows[t].tool == data.rows[i].tool));
            tools_known.then(|| (cluster.label.clone(), data.subset(&train), data.subset(&cluster.rows)))
        })
        .collect()
}

/// Every candidate (`sigmas`) fitted on every split's training rows and judged on its held-out
/// rows: the usable splits, and per candidate every held-out row of them (criterion, squared
/// position error mm²), in the same order.
fn held_out_rows(
    nominal: &LocalPoe,
    splits: &[(String, MeasurementSet, MeasurementSet)],
    sigmas: &[Option<(f64, f64)>],
    identification: &IdentificationOptions,
) -> (Vec<usize>, Vec<Vec<(f64, f64)>>) {
    let work: Vec<(usize, usize)> = (0..splits.len()).flat_map(|s| (0..sigmas.len()).map(move |c| (s, c))).collect();
    let results: Vec<Option<Vec<(f64, f64)>>> = work
        .par_iter()
        .map(|&(s, c)| {
            let (_, train, test) = &splits[s];
            let fitted =
                calibrate_placed_with_prior(nominal, &observations(train), Scope::Full, sigmas[c], identification);
            fitted.ok().and_then(|(_, fit)| heldout(&fit.model, test, identification).ok())
        })
        .collect();
    // A fold that some candidate could not fit (too few rows, a refused start) is left out for
    // every candidate, so that all are judged on the same rows.
    let usable: Vec<usize> =
        (0..splits.len()).filter(|&s| (0..sigmas.len()).all(|c| results[s * sigmas.len() + c].is_some())).collect();
    // Every held-out row of every usable fold, per candidate, in the same order.
    let rows: Vec<Vec<(f64, f64)>> = (0..sigmas.len())
        .map(|c| usable.iter().flat_map(|&s| results[s * sigmas.len() + c].clone().unwrap_or_default()).collect())
        .collect();
    (usable, rows)
}

/// The candidates with their held-out scores, and the one chosen: the first whose mean criterion
/// is within one standard error of the best's.
fn one_standard_error(sigmas: &[Option<(f64, f64)>], rows: &[Vec<(f64, f64)>]) -> (Vec<PriorCandidate>, usize) {
    let n = rows[0].len().max(1) as f64;
    let candidates: Vec<PriorCandidate> = sigmas
        .iter()
        .zip(rows)
        .map(|(sigma, rows)| PriorCandidate {
            translation_m: sigma.map(|s| s.0),
            rotation_rad: sigma.map(|s| s.1),
            heldout_rms_position_mm: (rows.iter().map(|r| r.1).sum::<f64>() / n).sqrt(),
            heldout_score: (rows.iter().map(|r| r.0).sum::<f64>() / n).sqrt(),
        })
        .collect();
    let best = candidates.iter().enumerate().fold(0, |best, (c, candidate)| {
        if candidate.heldout_score < candidates[best].heldout_score { c } else { best }
    });
    let within_one_error = |c: usize| {
        let d: Vec<f64> = rows[c].iter().zip(&rows[best]).map(|(a, b)| a.0 - b.0).collect();
        let mean = d.iter().sum::<f64>() / n;
        let variance = d.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        mean <= (variance / n).sqrt()
    };
    let chosen = (0..candidates.len()).find(|&c| within_one_error(c)).unwrap_or(best);
    (candidates, chosen)
}

#[cfg(test)]
mod tests {
    use super::{NominalPriorOptions, PriorChoice};

    #[test]
    fn the_default_options_validate_and_a_bad_value_is_refused_with_its_field_value_and_range() {
        assert_eq!(NominalPriorOptions::default().validate(), Ok(()));
        let cases = [
            (
                NominalPriorOptions { translations_m: vec![], ..Default::default() },
                "translations_m is [], expected at least one number above 0 (inf for no prior)",
            ),
            (
                NominalPriorOptions { translations_m: vec![1e-3, 0.0], ..Default::default() },
                "translations_m is [0.001, 0.0], expected at least one number above 0 (inf for no prior)",
            ),
            (
                NominalPriorOptions { tolerance_translation_m: 0.0, ..Default::default() },
                "tolerance_translation_m is 0, expected a finite number above 0",
            ),
            (
                NominalPriorOptions { tolerance_rotation_rad: f64::INFINITY, ..Default::default() },
                "tolerance_rotation_rad is inf, expected a finite number above 0",
            ),
            (
                NominalPriorOptions { min_height_span_m: -1.0, ..Default::default() },
                "min_height_span_m is -1, expected a finite number above 0",
            ),
            (
                NominalPriorOptions { length_m: f64::NAN, ..Default::default() },
                "length_m is NaN, expected a finite number above 0",
            ),
            (
                NominalPriorOptions { min_cluster_share: 0.6, ..Default::default() },
                "min_cluster_share is 0.6, expected a number above 0 and at most 0.5",
            ),
            (
                NominalPriorOptions { scan_tolerance_rad: 0.0, ..Default::default() },
                "scan_tolerance_rad is 0, expected a finite number above 0",
            ),
            (NominalPriorOptions { scan_steps: 7, ..Default::default() }, "scan_steps is 7, expected at least 8"),
            (NominalPriorOptions { max_rows: 0, ..Default::default() }, "max_rows is 0, expected at least 1"),
            (NominalPriorOptions { scan_probes: 1, ..Default::default() }, "scan_probes is 1, expected at least 2"),
        ];
        for (options, message) in cases {
            let (field, text) = options.validate().unwrap_err().in_file("nominal_prior");
            assert_eq!(text, format!("nominal_prior.{message}"));
            assert!(message.starts_with(field), "{field}: {message}");
        }
        let at_limits = NominalPriorOptions {
            min_cluster_share: 0.5,
            scan_steps: 8,
            scan_probes: 2,
            max_rows: 1,
            ..Default::default()
        };
        assert_eq!(at_limits.validate(), Ok(()));
    }

    fn posterior(scale: f64) -> PriorChoice {
        let prior = NominalPriorOptions::default();
        let mut choice = PriorChoice::without(Vec::new(), Vec::new(), &prior, "test".into());
        choice.residual_scale = Some(scale);
        (choice.translation_m, choice.rotation_rad) = (Some(1e-3 / scale), Some(2e-3 / scale));
        choice
    }

    /// The prior in metres stays what the geometry's was: its σ in noise units grows by the
    /// ratio of the residual scales, back to the tolerance where the effects leave the noise; it
    /// never tightens (a plain fit with effects whose scale is above the geometry's, by the
    /// parameters it spends).
    #[test]
    fn the_effects_prior_is_the_chosen_one_weighed_against_their_residual_and_never_tighter() {
        let near = |(t, r): (f64, f64), (a, b): (f64, f64)| (t - a).abs() < 1e-15 && (r - b).abs() < 1e-15;
        let mut choice = posterior(40.0);
        let at_noise = choice.for_effects_at(1.0).unwrap();
        assert!(near(at_noise, (1e-3, 2e-3)), "{at_noise:?}");
        assert_eq!(choice.with_effects.map(|p| p.residual_scale), Some(1.0));
        let above = posterior(40.0).for_effects_at(4.0).unwrap();
        assert!(near(above, (2.5e-4, 5e-4)), "{above:?}");
        let wider = posterior(4.0).for_effects_at(4.5).unwrap();
        assert!(near(wider, (2.5e-4, 5e-4)), "{wider:?}");
        let prior = NominalPriorOptions::default();
        let mut none = PriorChoice::without(Vec::new(), Vec::new(), &prior, "switched off".into());
        assert_eq!(none.for_effects_at(1.0), None);
        assert!(none.with_effects.is_none());
    }
}
