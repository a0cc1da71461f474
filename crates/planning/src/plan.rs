//! `calib plan`: the poses worth measuring, chosen from candidates.
//!
//! D-optimal for the identification ([`crate::information`], [`crate::design`]): greedy, then
//! Fedorov exchanges, then exchanges that lower the expected held-out error with the error the
//! geometry cannot model in it ([`crate::bias`]), then every moving joint's range (and the payloads) covered
//! ([`crate::coverage`]); put in the order to measure them (tool and payload changes grouped,
//! the shortest joint move next); reported with the predicted error at the chosen count and at a
//! few others, so that the user sees where more poses stop paying.

use crate::ErrorKind;
use crate::bias::{BiasModel, Unmodelled};
use crate::coverage::{Axis, AxisCoverage, cover, coverage};
use crate::design::{Criterion, Design};
use crate::information::{Candidate, CandidateRows, RowWeights, candidate_rows};
use crate::unmodelled_setting::{UnmodelledFrom, UnmodelledGiven, UnmodelledSetting, per_axis_from_mean};
use errors::{Error, OptionOutOfRange, option};
use model::CalibratedModel;
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// Everything `plan` is tuned by.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PlanOptions {
    /// What the design maximises ([`Criterion`]).
    pub criterion: Criterion,
    /// Tracker position noise per axis, mm: 0.05, a Leica AT960's MPE (15 µm + 6 µm/m) at 3–5 m
    /// rounded up. It scales the predicted errors; set it to the residual a fit leaves (its
    /// held-out error / √3) for absolute numbers.
    pub position_noise_mm: f64,
    /// Tracker orientation noise per axis, mrad (full-pose measurements): 0.05, the T-Mac's
    /// order of accuracy; it sets the weight of a rotation row against a position row.
    pub rotation_noise_mrad: f64,
    /// Directions of the scaled information with an eigenvalue below this fraction of the
    /// largest are redundant (a local POE model's redundant directions sit at rounding, ~1e-16;
    /// 1e-10 keeps every direction a design can determine).
    pub rank_tolerance: f64,
    /// The ridge `ρ = prior_fraction · tr(mean candidate information) / r` that makes `log det`
    /// finite before the poses determine every direction; 1e-6 changes the criterion of a
    /// determined design by far less than an exchange's tolerance.
    pub prior_fraction: f64,
    /// Passes of Fedorov exchanges after the greedy choice (each pass visits every pose; most
    /// gain is in the first: Atkinson, Donev & Tobias, *Optimum Experimental Designs*, §12.5).
    /// One: on 100 of 10,000 UR10 candidates a second pass changed the predicted error by < 1 %
    /// and doubled the time.
    pub exchange_passes: usize,
    /// Smallest rise of `log det M` an exchange must bring.
    pub exchange_tolerance: f64,
    /// Bins over each moving joint's range (and the payloads) that the poses must cover where
    /// candidates are: 8, so that no gap wider than 1/8 of a range is left for the angle-dependent
    /// effects, which a calibrated model fades outside the angles they were fitted on. Fewer when fewer
    /// poses are asked for.
    pub coverage_bins: usize,
    /// A joint whose candidates span less than this (rad or m) does not move and needs no
    /// coverage.
    pub min_joint_span: f64,
    /// RMS per axis of the position error the geometry cannot model (compliance, gear errors),
    /// mm: 0.2. After `poe` the UR10 of Landgraf et al. keeps 0.44 mm (3-D mean) on series C,
    /// 0.41 on B and 0.37 on D, about 0.2–0.25 per axis. The design is then exchanged to lower
    /// the expected held-out error with that error in it ([`crate::bias`]), and the report
    /// predicts it. 0: tracker noise alone (the plain criterion). `calib plan --model` sets it
    /// from the model's held-out error where the options do not ([`PlanOptions::set_unmodelled_from`]).
    pub unmodelled_mm: f64,
    /// The same for the orientation, mrad: 0.2, the position's at the 1 m lever of an arm's
    /// reach.
    pub unmodelled_mrad: f64,
    /// Correlation length of the unmodelled error over the joints (chordal distance of the
    /// angles, rad; metres for a prismatic joint): 0.2. Measured: the correlation of `poe`'s
    /// residuals between two poses of the UR10 (series B, C, D; docs/results/cell-check.md)
    /// is 0.3–0.5 at 0.1–0.2 rad apart and 0.1–0.3 at 0.3 rad.
    pub unmodelled_length_rad: f64,
    /// Candidates (evenly strided) over which the expected error is averaged: 1000.
    pub unmodelled_test_points: usize,
    /// Candidates (evenly strided over those not chosen) tried in each position of an exchange
    /// for the unmodelled error: 500, at most `unmodelled_evaluations / poses`.
    pub unmodelled_trials: usize,
    /// Trials in one pass of those exchanges, over all positions: 30,000. Each is a rank-2k
    /// update (`O(r² k)`, `r` ≈ 30–40 directions for a 6-axis arm's full pose, [`crate::bias`]);
    /// this kept 100 of 10,000 candidates within seconds when each trial was still a
    /// refactorisation (`cargo xtask cell-check --only timing`), and 30 or 50 poses at 500
    /// trials each.
    pub unmodelled_evaluations: usize,
    /// Passes of those exchanges: 2 (a third changed no pose on the UR10 series).
    pub unmodelled_passes: usize,
}

impl Default for PlanOptions {
    fn default() -> Self {
        Self {
            criterion: Criterion::default(),
            position_noise_mm: 0.05,
            rotation_noise_mrad: 0.05,
            rank_tolerance: 1e-10,
            prior_fraction: 1e-6,
            exchange_passes: 1,
            exchange_tolerance: 1e-6,
            coverage_bins: 8,
            min_joint_span: 1e-3,
            unmodelled_mm: 0.2,
            unmodelled_mrad: 0.2,
            unmodelled_length_rad: 0.2,
            unmodelled_test_points: 1000,
            unmodelled_trials: 500,
            unmodelled_evaluations: 30_000,
            unmodelled_passes: 2,
        }
    }
}

impl PlanOptions {
    /// Options from the RON text of a file (`calib plan --options`): every field optional,
    /// unknown ones refused, each value validated; errors name the file, line and column.
    pub fn parse(text: &str, file: &str) -> Result<Self, Error> {
        let options: PlanOptions = ron::from_str(text).map_err(|e| Error::ron(file, &e))?;
        options.validate()?;
        Ok(options)
    }

    /// Refuses values out of range.
    pub fn validate(&self) -> Result<(), Error> {
        let positive = [
            ("position_noise_mm", self.position_noise_mm),
            ("rotation_noise_mrad", self.rotation_noise_mrad),
            ("rank_tolerance", self.rank_tolerance),
            ("prior_fraction", self.prior_fraction),
            ("min_joint_span", self.min_joint_span),
            ("unmodelled_length_rad", self.unmodelled_length_rad),
        ];
        for (field, value) in positive {
            option::positive(field, value)?;
        }
        for (field, value) in [("unmodelled_mm", self.unmodelled_mm), ("unmodelled_mrad", self.unmodelled_mrad)] {
            option::non_negative(field, value)?;
        }
        for (field, value) in [
            ("unmodelled_test_points", self.unmodelled_test_points),
            ("unmodelled_trials", self.unmodelled_trials),
            ("unmodelled_evaluations", self.unmodelled_evaluations),
        ] {
            option::at_least_one(field, value)?;
        }
        let bins = self.coverage_bins;
        OptionOutOfRange::check("coverage_bins", bins as f64, bins <= 1000, "at most 1000")?;
        option::non_negative("exchange_tolerance", self.exchange_tolerance)?;
        Ok(())
    }
}

/// What a design of some size predicts.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Checkpoint {
    /// Poses.
    pub poses: usize,
    /// Whether this is the chosen design (after exchanges and coverage); the others are the greedy
    /// design's prefix or continuation.
    pub chosen: bool,
    /// `log det M / r`: the information per determined direction, log units of the noise.
    pub log_det_per_direction: f64,
    /// RMS over the candidates of the position error the parameters' uncertainty leaves, mm.
    pub parameter_error_mm: f64,
    /// Its largest value over the candidates, mm.
    pub max_parameter_error_mm: f64,
    /// Predicted held-out RMS position error: the noise and the parameters' part, mm.
    pub predicted_error_mm: f64,
    /// The same with the unmodelled error of `PlanOptions::unmodelled_mm` in it: what the fit
    /// on these poses is expected to leave where the robot is used, mm (absent with
    /// `unmodelled_mm` 0, or where it is not finite).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_with_unmodelled_mm: Option<f64>,
    /// RMS over the candidates of the orientation error the parameters leave, mrad (full pose).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub parameter_rotation_error_mrad: Option<f64>,
}

/// What `calib plan` found (`--json`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlanReport {
    /// Candidates.
    pub candidates: usize,
    /// Poses chosen.
    pub poses: usize,
    /// Whether full poses are planned for (else positions).
    pub full_pose: bool,
    /// Parameters of the model and the directions of them the candidates determine.
    pub parameters: usize,
    /// See `parameters`.
    pub directions: usize,
    /// The noise the errors are predicted for, mm per axis.
    pub position_noise_mm: f64,
    /// The unmodelled error the errors with it are predicted for, mm per axis
    /// ([`PlanOptions::unmodelled_mm`]; 0: none).
    pub unmodelled_mm: f64,
    /// Where `unmodelled_mm` came from ([`UnmodelledFrom`]; [`plan()`] says the options,
    /// `calib plan` whether they are the defaults or a model's held-out error).
    pub unmodelled_from: UnmodelledFrom,
    /// The unmodelled orientation error, mrad per axis ([`PlanOptions::unmodelled_mrad`]; full
    /// pose only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unmodelled_mrad: Option<f64>,
    /// Where it came from.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unmodelled_mrad_from: Option<UnmodelledFrom>,
    /// Exchanges made after the greedy choice.
    pub exchanges: usize,
    /// Exchanges made for the unmodelled error ([`PlanOptions::unmodelled_mm`]).
    pub unmodelled_exchanges: usize,
    /// Swaps made for coverage.
    pub coverage_swaps: usize,
    /// Coverage of every moving joint (and the payloads) by the chosen poses.
    pub coverage: Vec<AxisCoverage>,
    /// The predicted errors at the chosen count and a few others.
    pub checkpoints: Vec<Checkpoint>,
}

impl PlanReport {
    /// Says where the unmodelled errors came from ([`PlanOptions::set_unmodelled_from`]).
    pub fn set_unmodelled_from(&mut self, setting: UnmodelledSetting) {
        self.unmodelled_from = setting.position;
        if self.unmodelled_mrad.is_some() {
            self.unmodelled_mrad_from = Some(setting.rotation);
        }
    }

    /// The report as lines of text.
    pub fn lines(&self) -> Vec<String> {
        let mut lines = vec![format!(
            "chose {} of {} candidates ({} poses): {} of {} parameter directions determined; {} exchanges, {} for \
             the unmodelled error, {} swaps for coverage",
            self.poses,
            self.candidates,
            if self.full_pose { "full" } else { "position-only" },
            self.directions,
            self.parameters,
            self.exchanges,
            self.unmodelled_exchanges,
            self.coverage_swaps
        )];
        for c in &self.coverage {
            lines.push(format!("  {}: {} of {} bins covered", c.input, c.covered, c.possible));
        }
        if self.unmodelled_mm > 0.0 {
            lines.push(format!("  unmodelled error {:.3} mm per axis ({})", self.unmodelled_mm, self.unmodelled_from));
            if let (Some(mrad), Some(from)) = (self.unmodelled_mrad, self.unmodelled_mrad_from) {
                let lever = if matches!(from, UnmodelledFrom::Model { .. }) { "; mm at the 1 m lever" } else { "" };
                lines.push(format!("  unmodelled orientation error {mrad:.3} mrad per axis ({from}{lever})"));
            }
        }
        lines.push(format!(
            "  predicted error (tracker noise {:.3} mm per axis{}; rms over the candidates):",
            self.position_noise_mm,
            if self.unmodelled_mm > 0.0 {
                format!(", unmodelled error {:.3} mm per axis", self.unmodelled_mm)
            } else {
                String::new()
            }
        ));
        for c in &self.checkpoints {
            lines.push(format!(
                "  {:>6} poses{}: from the parameters {:.4} mm (max {:.4}){}, held-out {:.4} mm{}",
                c.poses,
                if c.chosen { " (chosen)" } else { "          " },
                c.parameter_error_mm,
                c.max_parameter_error_mm,
                c.parameter_rotation_error_mrad.map_or(String::new(), |r| format!(", {r:.4} mrad")),
                c.predicted_error_mm,
                c.predicted_with_unmodelled_mm
                    .map_or(String::new(), |u| format!(", {u:.4} mm with the unmodelled error"))
            ));
        }
        lines
    }
}

/// The chosen poses in measuring order (indices into the candidates) and the report.
#[derive(Debug, Clone)]
pub struct Plan {
    /// Candidate indices, in the order to measure them.
    pub order: Vec<usize>,
    /// The report.
    pub report: PlanReport,
}

fn checkpoint(
    design: &Design<'_>,
    unmodelled: Option<&Unmodelled<'_>>,
    directions: usize,
    chosen: bool,
    options: &PlanOptions,
    full_pose: bool,
) -> Checkpoint {
    let (mean, max) = design.predicted_variance(3);
    let sigma = options.position_noise_mm;
    Checkpoint {
        poses: design.chosen().len(),
        chosen,
        log_det_per_direction: design.log_det() / directions as f64,
        parameter_error_mm: sigma * mean.sqrt(),
        max_parameter_error_mm: sigma * max.sqrt(),
        predicted_error_mm: sigma * (3.0 + mean).sqrt(),
        predicted_with_unmodelled_mm: unmodelled
            .map(|u| sigma * u.expected(design.chosen()).max(0.0).sqrt())
            .filter(|e| e.is_finite()),
        parameter_rotation_error_mrad: if full_pose {
            design.predicted_rotation_variance().map(|(m, _)| options.rotation_noise_mrad * m.sqrt())
        } else {
            None
        },
    }
}

/// Chooses `poses` of `candidates` for identifying `model`.
pub fn plan(
    model: &LocalPoe,
    candidates: &[Candidate],
    poses: usize,
    full_pose: bool,
    options: &PlanOptions,
) -> Result<Plan, Error> {
    options.validate()?;
    if poses == 0 || candidates.len() < poses {
        return Err(Error::new(ErrorKind::TooFewCandidates { candidates: candidates.len(), poses }));
    }
    let weights = RowWeights {
        position_m: options.position_noise_mm * 1e-3,
        rotation_rad: full_pose.then_some(options.rotation_noise_mrad * 1e-3),
        rank_tolerance: options.rank_tolerance,
    };
    let rows = candidate_rows(model, candidates, &weights)?;
    if rows.is_empty() {
        return Err(Error::new(ErrorKind::NoIdentifiableDirection { candidates: candidates.len() }));
    }
    let mean_trace = rows.a.iter().map(|v| v * v).sum::<f64>() / candidates.len() as f64;
    let prior = options.prior_fraction * mean_trace / rows.r as f64;
    let kinds: Vec<poe::JointKind> = model.joints().iter().map(|j| j.kind).collect();
    let unmodelled = (options.unmodelled_mm > 0.0)
        .then(|| Unmodelled::new(&rows, candidates, &kinds, prior, bias_model(options, poses)));
    let mut design = Design::new(&rows, prior, options.criterion);
    let targets: Vec<usize> = [poses / 4, poses / 2].into_iter().filter(|&n| n > 0 && n < poses).collect();
    let mut checkpoints = Vec::new();
    design.greedy(poses, |d| {
        if targets.contains(&d.chosen().len()) {
            checkpoints.push(checkpoint(d, unmodelled.as_ref(), rows.r, false, options, full_pose));
        }
    });
    let exchanges = design.exchange(options.exchange_passes, options.exchange_tolerance);
    let unmodelled_exchanges = match &unmodelled {
        Some(unmodelled) => exchange_for_unmodelled(&mut design, unmodelled, &rows, prior, options.criterion),
        None => 0,
    };
    let axes = axes(candidates, options.coverage_bins.min(poses), options.min_joint_span);
    let coverage_swaps = cover(&mut design, &axes);
    checkpoints.push(checkpoint(&design, unmodelled.as_ref(), rows.r, true, options, full_pose));
    let chosen = design.chosen().to_vec();
    let more = (2 * poses).min(candidates.len());
    if more > poses {
        design.greedy(more, |_| {});
        design.refresh();
        checkpoints.push(checkpoint(&design, unmodelled.as_ref(), rows.r, false, options, full_pose));
    }
    let report = PlanReport {
        candidates: candidates.len(),
        poses,
        full_pose,
        parameters: rows.p,
        directions: rows.r,
        position_noise_mm: options.position_noise_mm,
        unmodelled_mm: options.unmodelled_mm,
        unmodelled_from: UnmodelledFrom::Options,
        unmodelled_mrad: full_pose.then_some(options.unmodelled_mrad),
        unmodelled_mrad_from: full_pose.then_some(UnmodelledFrom::Options),
        exchanges,
        unmodelled_exchanges,
        coverage_swaps,
        coverage: coverage(&axes, &chosen),
        checkpoints,
    };
    Ok(Plan { order: measuring_order(candidates, &chosen), report })
}

/// The model of the error the geometry leaves, in the units the criterion weighs it in.
fn bias_model(options: &PlanOptions, poses: usize) -> BiasModel {
    BiasModel {
        position_ratio: (options.unmodelled_mm / options.position_noise_mm).powi(2),
        rotation_ratio: (options.unmodelled_mrad / options.rotation_noise_mrad).powi(2),
        length: options.unmodelled_length_rad,
        test_points: options.unmodelled_test_points,
        trials: options.unmodelled_trials.min(options.unmodelled_evaluations / poses).max(1),
        passes: options.unmodelled_passes,
    }
}

/// Exchanges of the chosen poses that lower the expected error with the unmodelled part; the
/// design is remade from the new choice when any was made. Returns how many were made.
fn exchange_for_unmodelled<'a>(
    design: &mut Design<'a>,
    unmodelled: &Unmodelled<'_>,
    rows: &'a CandidateRows,
    prior: f64,
    criterion: Criterion,
) -> usize {
    let mut chosen = design.chosen().to_vec();
    let made = unmodelled.exchange(&mut chosen);
    if made > 0 {
        *design = Design::of(rows, prior, criterion, &chosen);
    }
    made
}

/// The bins of every moving joint and of the payload where it varies.
fn axes(candidates: &[Candidate], bins: usize, min_span: f64) -> Vec<Axis> {
    let joints = candidates.first().map_or(0, |c| c.q.len());
    let mut axes = Vec::new();
    let span = |v: &[f64]| {
        v.iter().copied().fold(f64::NEG_INFINITY, f64::max) - v.iter().copied().fold(f64::INFINITY, f64::min)
    };
    for j in 0..joints {
        let values: Vec<f64> = candidates.iter().map(|c| c.q[j]).collect();
        if span(&values) >= min_span && bins > 0 {
            axes.push(Axis::new(format!("joint {}", j + 1), &values, bins));
        }
    }
    let payloads: Vec<f64> = candidates.iter().map(|c| c.payload_kg).collect();
    if span(&payloads) > 0.0 && bins > 0 {
        axes.push(Axis::new("payload_kg".into(), &payloads, bins));
    }
    axes
}

/// The order to measure `chosen` in: groups of one tool and payload (a manual change each) in
/// the order they first appear among the candidates, and inside a group the nearest pose next
/// (largest joint move, as the joints move together), from the first of the group.
pub fn measuring_order(candidates: &[Candidate], chosen: &[usize]) -> Vec<usize> {
    let mut sorted = chosen.to_vec();
    sorted.sort_unstable();
    let key = |c: usize| (candidates[c].tool, candidates[c].payload_kg.to_bits());
    let mut groups: Vec<(usize, u64)> = Vec::new();
    for &c in &sorted {
        if !groups.contains(&key(c)) {
            groups.push(key(c));
        }
    }
    let distance = |a: usize, b: usize| {
        candidates[a].q.iter().zip(&candidates[b].q).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
    };
    let mut order = Vec::with_capacity(chosen.len());
    for group in groups {
        let mut left: Vec<usize> = sorted.iter().copied().filter(|&c| key(c) == group).collect();
        let mut current = match order.last() {
            Some(&last) => {
                left.iter().copied().min_by(|&a, &b| distance(last, a).total_cmp(&distance(last, b))).unwrap_or(left[0])
            }
            None => left[0],
        };
        while !left.is_empty() {
            left.retain(|&c| c != current);
            order.push(current);
            if let Some(next) =
                left.iter().copied().min_by(|&a, &b| distance(current, a).total_cmp(&distance(current, b)))
            {
                current = next;
            }
        }
    }
    order
}

impl PlanOptions {
    /// Sets the unmodelled errors the options do not `given` from `model`'s held-out error
    /// where it keeps one ([`per_axis_from_mean`]), and says where each came from. A model
    /// without a held-out estimate (written before it was kept, or a sparse GP's) leaves the
    /// defaults.
    pub fn set_unmodelled_from(
        &mut self,
        model: Option<&CalibratedModel>,
        given: UnmodelledGiven,
    ) -> UnmodelledSetting {
        let fallback = |set: bool| if set { UnmodelledFrom::Options } else { UnmodelledFrom::Default };
        let mut setting = UnmodelledSetting { position: fallback(given.position), rotation: fallback(given.rotation) };
        let Some((model, heldout)) = model.and_then(|m| m.heldout.map(|h| (m, h))) else { return setting };
        let from = UnmodelledFrom::Model {
            heldout_mm: heldout.mean_position_error_mm,
            heldout_source: heldout.source,
            method: model.method,
            beyond_geometry: !model.effects.is_empty() || model.residual_gp.is_some(),
        };
        let sigma = per_axis_from_mean(heldout.mean_position_error_mm);
        if !given.position {
            self.unmodelled_mm = sigma;
            setting.position = from;
        }
        if !given.rotation {
            // mm per axis at the 1 m lever, in mrad.
            self.unmodelled_mrad = sigma;
            setting.rotation = from;
        }
        setting
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use poe::{DhConvention, DhRow, JointKind};
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn arm() -> LocalPoe {
        // The UR10's DH table (SPEC).
        let row = |a, alpha, d| DhRow { kind: JointKind::Revolute, a, alpha, d, theta: 0.0 };
        let h = std::f64::consts::FRAC_PI_2;
        LocalPoe::from_dh(
            &[
                row(0.0, h, 0.1273),
                row(-0.612, 0.0, 0.0),
                row(-0.5723, 0.0, 0.0),
                row(0.0, h, 0.163941),
                row(0.0, -h, 0.1157),
                row(0.0, 0.0, 0.0922),
            ],
            DhConvention::Standard,
        )
    }

    fn candidates(count: usize, seed: u64) -> Vec<Candidate> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..count)
            .map(|_| Candidate { q: (0..6).map(|_| rng.random_range(-3.0..3.0)).collect(), tool: 0, payload_kg: 0.0 })
            .collect()
    }

    fn log_det_of(model: &LocalPoe, all: &[Candidate], chosen: &[usize], full_pose: bool) -> f64 {
        let options = PlanOptions::default();
        let weights = RowWeights {
            position_m: 5e-5,
            rotation_rad: full_pose.then_some(5e-5),
            rank_tolerance: options.rank_tolerance,
        };
        let rows = candidate_rows(model, all, &weights).unwrap();
        let prior =
            options.prior_fraction * rows.a.iter().map(|v| v * v).sum::<f64>() / all.len() as f64 / rows.r as f64;
        let mut design = Design::new(&rows, prior, Criterion::D);
        for &c in chosen {
            design.add(c);
        }
        design.refresh();
        design.log_det()
    }

    #[test]
    fn planned_poses_beat_random_ones_on_log_det() {
        let model = arm();
        let all = candidates(600, 1);
        let plan = plan(&model, &all, 20, false, &PlanOptions::default()).unwrap();
        let planned = log_det_of(&model, &all, &plan.order, false);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..10 {
            let mut random: Vec<usize> = Vec::new();
            while random.len() < 20 {
                let c = rng.random_range(0..all.len());
                if !random.contains(&c) {
                    random.push(c);
                }
            }
            let other = log_det_of(&model, &all, &random, false);
            assert!(planned > other, "planned {planned} random {other}");
        }
    }

    #[test]
    fn the_chosen_poses_cover_every_moving_joint() {
        let model = arm();
        let all = candidates(400, 3);
        let plan = plan(&model, &all, 24, true, &PlanOptions::default()).unwrap();
        assert_eq!(plan.order.len(), 24);
        for c in &plan.report.coverage {
            assert_eq!(c.covered, c.possible, "{c:?}");
        }
        let mut sorted = plan.order.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 24, "a pose chosen twice");
        // More poses predict a smaller error.
        let errors: Vec<f64> = plan.report.checkpoints.iter().map(|c| c.parameter_error_mm).collect();
        assert!(errors.windows(2).all(|w| w[1] < w[0]), "{errors:?}");
    }

    #[test]
    fn more_poses_than_candidates_are_refused_with_the_counts() {
        let err = plan(&arm(), &candidates(5, 4), 6, false, &PlanOptions::default()).unwrap_err();
        assert!(
            matches!(err.kind::<ErrorKind>(), Some(ErrorKind::TooFewCandidates { candidates: 5, poses: 6 })),
            "{err}"
        );
    }

    #[test]
    fn the_measuring_order_groups_payloads_and_moves_little() {
        let all: Vec<Candidate> = [(0.0, 0.0), (3.0, 5.0), (0.1, 0.0), (2.9, 5.0), (1.0, 0.0)]
            .iter()
            .map(|&(q, m)| Candidate { q: vec![q; 6], tool: 0, payload_kg: m })
            .collect();
        assert_eq!(measuring_order(&all, &[3, 4, 0, 1, 2]), vec![0, 2, 4, 3, 1]);
    }
}
