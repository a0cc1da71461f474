//! `calib diagnose`: where the geometric model still misses, which unmodelled effect explains it,
//! and how far the error shrinks once that effect is modelled — all on held-out rows.
//!
//! 1. *Where*: the local POE model is fitted to every row; K-fold cross-validation of one
//!    linearised step from that solution, regularised by a prior so that a fold cannot move
//!    along directions its rows do not determine (module `pool`), gives each row's held-out
//!    residual, broken down by component, payload, moving joint, reach, height, temperature and
//!    time (module `regions`).
//! 2. *Which*: each candidate effect becomes extra columns of the same linear problem (module
//!    `candidates`); a periodic error of a joint's own angle is a Fourier series whose order each
//!    fold chooses on its own training rows. Greedy forward selection keeps an effect only when a
//!    signed-rank test of its per-pose gain is significant (module `selection`).
//! 3. *Is that all*: a cross-validated GP on the joint angles measures what any smooth model
//!    could explain; an effect is named only when it explains most of that, otherwise the verdict
//!    is `unknown` with the joints the GP found the structure in (modules `structure`, `verdict`).
//! 4. *How far*: held-out error before and after, against a noise floor from repeated poses, the
//!    user, or the instrument class (module `noise`), overall and per region.
//!
//! ```
//! # let fixture = |name: &str| std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(name);
//! let robot = robot::RobotDescription::read(&fixture("irb4400.ron"))?;
//! let config = campaign::GeneratorConfig { sample_count: 150, seed: 1, ..Default::default() };
//! let (_, data) = campaign::simulate_campaign(
//!     &robot, &campaign::paper_effects(), &campaign::Perturbation::default(), &campaign::Remount::default(), &config, true,
//! )?;
//! let diagnosis = diagnose::diagnose(&robot, &data, &diagnose::DiagnoseOptions::default())?;
//! println!("{:?}: {:.3} mm -> {:.3} mm", diagnosis.verdict.effect, diagnosis.heldout_before_mm, diagnosis.heldout_after_mm);
//! assert!(diagnosis.heldout_after_selected_mm <= diagnosis.heldout_before_mm);
//! # Ok::<(), errors::Error>(())
//! ```
#![deny(missing_docs)]

mod arcs;
mod candidates;
mod design;
mod error_kind;
mod fold_residuals;
mod learnt_side;
mod noise;
mod outliers;
mod pool;
mod regions;
mod report;
mod selection;
mod statistics;
mod structure;
mod verdict;

pub use arcs::ArcCheck;
pub use candidates::Effect;
pub use error_kind::ErrorKind;
pub use fold_residuals::{FoldResiduals, HeldoutFolds};
pub use noise::{NoiseFloor, NoiseSource};
pub use outliers::{GrossOutliers, OutlierOptions};
pub use pool::PriorOptions;
pub use regions::{PoseDiagnosis, Region};
pub use report::{CandidateScore, DominantHarmonic, ErrorPlot, OrderScore, SelectedEffect, SeriesShape};
pub use selection::SelectionOptions;
pub use structure::{GpInput, StructureOptions};
pub use verdict::{GpCheck, InputScale, Verdict, VerdictOptions};

use design::{Design, Weights};
use effects::IdentifiedEffect;
use errors::{Error, OptionOutOfRange, option};
use lie::Vector3;
use measurements::{BoundSet, MeasurementSet};
use model::geometric::{fit_geometry, observations};
use poe::LocalPoe;
use poe::identify::{IdentificationOptions, Scope};
use pool::Pool;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use robot::RobotDescription;
use selection::{Selection, Term};
use serde::{Deserialize, Serialize};

/// How to diagnose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DiagnoseOptions {
    /// Number of cross-validation folds.
    pub folds: usize,
    /// Seed of the fold assignment.
    pub seed: u64,
    /// The measurement noise per axis, mm, if known; otherwise from repeated poses, or the
    /// instrument default `tracker`.
    pub noise_mm: Option<f64>,
    /// The instrument class assumed when neither `noise_mm` nor repeated poses give the noise.
    pub tracker: loadsim::TrackerNoiseModel,
    /// A joint counts as moving when its angles span more than this, rad. 0.05 rad (3°): well
    /// above the few mrad a joint held still jitters by, and over a few degrees a function of the
    /// angle is a straight line the kinematic model already holds.
    pub moving_min_range_rad: f64,
    /// Arcs each moving joint's angles are cut into for the prediction off the training poses
    /// (module `arcs`). 10, the usual choice of k-fold cross-validation beside 5 (Hastie,
    /// Tibshirani and Friedman, ESL §7.10): each fold's geometry is fitted on nine tenths of the
    /// joint's range. Where the series fade, the fitted model is the geometry fitted on all of it,
    /// and fewer arcs take away more of the range and over-predict; more arcs approach the
    /// geometry's error at the training poses and under-predict (the comparison of 5, 10 and 15 on
    /// simulated gaps and the UR10: `docs/results/off-training.md`).
    pub arc_folds: usize,
    /// The prior that keeps each fold's fit from moving where its rows see nothing.
    pub prior: PriorOptions,
    /// How strict the selection is.
    pub selection: SelectionOptions,
    /// The GP that measures what could be explained.
    pub structure: StructureOptions,
    /// When to say `unknown`.
    pub verdict: VerdictOptions,
    /// When gross outliers stop the attribution (module `outliers`).
    pub outliers: OutlierOptions,
    /// When the temperature and the time vary enough to offer thermal growth and drift.
    pub candidates: effects::CandidateOptions,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            folds: 5,
            seed: 0,
            noise_mm: None,
            tracker: loadsim::TrackerNoiseModel::default(),
            moving_min_range_rad: 0.05,
            arc_folds: 10,
            prior: PriorOptions::default(),
            selection: SelectionOptions::default(),
            structure: StructureOptions::default(),
            verdict: VerdictOptions::default(),
            outliers: OutlierOptions::default(),
            candidates: effects::CandidateOptions::default(),
        }
    }
}

impl DiagnoseOptions {
    /// Refuses values that would make the diagnosis meaningless, naming the option.
    pub fn validate(&self) -> Result<(), Error> {
        let positive: [(&'static str, f64); 10] = [
            ("prior.placement", self.prior.placement),
            ("prior.series_rad", self.prior.series_rad),
            ("noise_mm", self.noise_mm.unwrap_or(1.0)),
            ("prior.kinematic_m", self.prior.kinematic_m),
            ("prior.kinematic_rad", self.prior.kinematic_rad),
            ("prior.effect_m", self.prior.effect_m),
            ("selection.significance", self.selection.significance),
            ("structure.short_length_scale", self.structure.short_length_scale),
            ("moving_min_range_rad", self.moving_min_range_rad + f64::MIN_POSITIVE),
            ("structure.max_training_rows", self.structure.max_training_rows as f64),
        ];
        for (field, value) in positive {
            option::positive(field, value)?;
        }
        let fractions: [(&'static str, f64); 5] = [
            ("outliers.max_left_out_fraction", self.outliers.max_left_out_fraction),
            ("selection.significance", self.selection.significance),
            ("selection.min_relative_gain", self.selection.min_relative_gain),
            ("verdict.structure_min_gain", self.verdict.structure_min_gain),
            ("verdict.min_explained_fraction", self.verdict.min_explained_fraction),
        ];
        for (field, value) in fractions {
            OptionOutOfRange::check(field, value, (0.0..1.0).contains(&value), "a number in [0, 1)")?;
        }
        let at_least_zero: [(&'static str, f64); 2] = [
            ("candidates.thermal_min_span_k", self.candidates.thermal_min_span_k),
            ("candidates.drift_min_offset_s", self.candidates.drift_min_offset_s),
        ];
        for (field, value) in at_least_zero {
            option::non_negative(field, value)?;
        }
        let weight = self.selection.arc_order_weight;
        OptionOutOfRange::check(
            "selection.arc_order_weight",
            weight,
            (0.0..=1.0).contains(&weight),
            "a number in [0, 1]",
        )?;
        OptionOutOfRange::check("arc_folds", self.arc_folds as f64, self.arc_folds >= 2, "at least 2")?;
        // Inner cross-validation inside a fold needs two folds left.
        OptionOutOfRange::check("folds", self.folds as f64, self.folds >= 3, "at least 3")?;
        let orders = &self.selection.series_orders;
        let accepted = !orders.is_empty() && !orders.contains(&0);
        OptionOutOfRange::check("selection.series_orders", 0.0, accepted, "orders of at least 1, and at least one")?;
        Ok(())
    }
}

/// The diagnosis of one data set: the SPEC's JSON object as it serialises.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The robot's name.
    pub robot: String,
    /// Number of poses.
    pub n: usize,
    /// Whether the data has orientations.
    pub full_pose: bool,
    /// 1-based joints whose angles span more than `moving_min_range_rad`.
    pub moving_joints: Vec<usize>,
    /// 1-based prismatic joints (reported in mm, where revolute ones are in degrees).
    #[serde(default)]
    pub prismatic_joints: Vec<usize>,
    /// The verdict.
    pub verdict: Verdict,
    /// Cross-validated mean position error of the geometric model, mm.
    pub heldout_before_mm: f64,
    /// The same with the verdict's effect alone, mm (`heldout_before_mm` for `none` and `unknown`).
    pub heldout_after_mm: f64,
    /// The same with every selected effect, mm.
    pub heldout_after_selected_mm: f64,
    /// The share of the explainable reduction of the mean held-out error that the selected effects
    /// achieve (module `verdict`), where a GP ran and something was selected.
    pub explained_fraction: Option<f64>,
    /// Every candidate tried alone on top of the geometric model, best first.
    pub candidates: Vec<CandidateScore>,
    /// The effects kept, in the order they were selected.
    pub selected: Vec<SelectedEffect>,
    /// The critical signed-rank z a candidate had to pass.
    pub critical_z: f64,
    /// What a GP on the geometric model's held-out residual explains.
    pub explainable: Option<GpCheck>,
    /// What a GP on the residual the selected effects leave still explains.
    pub remaining: Option<GpCheck>,
    /// The noise floor.
    pub noise: NoiseFloor,
    /// The held-out error by region.
    pub regions: Vec<Region>,
    /// Folds that see gaps: per moving joint, the held-out error when contiguous arcs of its
    /// angles (and the ends of its range) are left out (module `arcs`).
    #[serde(default)]
    pub arcs: Vec<ArcCheck>,
    /// The mean of `arcs`' held-out errors of the geometric model, mm: the prediction for poses
    /// off the training poses (past the ends of a joint's angles, in gaps, in other
    /// configurations), where `heldout_before_mm` is for poses like them.
    #[serde(default)]
    pub off_poses_before_mm: Option<f64>,
    /// The same with the selected effects, faded where they were not fitted.
    #[serde(default)]
    pub off_poses_after_mm: Option<f64>,
    /// The rows named as gross outliers and left out of everything above (`n` does not count
    /// them), checked before anything is attributed (module `outliers`).
    #[serde(default)]
    pub gross_outliers: GrossOutliers,
    /// Every pose (not in the JSON).
    #[serde(skip)]
    pub poses: Vec<PoseDiagnosis>,
    /// The random folds and the arcs fold by fold, for a stage fitted on top of the selected
    /// effects (not in the JSON).
    #[serde(skip)]
    pub folds: HeldoutFolds,
}

/// Assigns each of `n` rows to one of `folds` folds, shuffled by `seed`, sizes differing by one.
pub(crate) fn fold_assignment(n: usize, folds: usize, seed: u64) -> Vec<usize> {
    let mut order: Vec<usize> = (0..n).collect();
    order.shuffle(&mut rand_chacha::ChaCha8Rng::seed_from_u64(seed));
    let mut fold = vec![0; n];
    for (position, &row) in order.iter().enumerate() {
        fold[row] = position % folds;
    }
    fold
}

/// 0-based joints whose angles span more than `min_range` rad.
fn moving_joints(data: &MeasurementSet, min_range: f64) -> Vec<usize> {
    (0..data.joint_count)
        .filter(|&j| {
            let (low, high) =
                data.rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| (a.min(r.q[j]), b.max(r.q[j])));
            high - low > min_range
        })
        .collect()
}

/// The candidates as terms over pool columns, and the blocks of columns the pool is built from.
fn terms_of(candidates: &[candidates::Candidate], kinematic: usize) -> (Vec<Term>, Vec<pool::Block<'_>>) {
    let mut terms: Vec<Term> = Vec::new();
    let mut blocks: Vec<pool::Block<'_>> = Vec::new();
    let mut next = kinematic;
    for c in candidates {
        let columns: Vec<usize> = (next..next + c.columns.len()).collect();
        next += c.columns.len();
        blocks.push((&c.columns, c.prior_sd));
        // A series takes the orders whose harmonics are all among its columns.
        let orders =
            c.orders.as_ref().map(|o| o.iter().copied().filter(|&h| 2 * h as usize <= columns.len()).collect());
        terms.push(Term {
            effect: c.effect,
            joints: c.joints.clone(),
            columns,
            per_fold: None,
            orders,
            model: c.model.clone(),
        });
    }
    (terms, blocks)
}

/// What a selected series looks like, fitted on every row with every selected effect at the
/// order its cross-validation curve prefers: its RMS over the data and its strongest periods.
///
/// The coefficients themselves do not say which periods matter: over part of a turn, many
/// combinations of harmonics cancel on the data. So the fitted joint error is sampled on 720
/// points of the joint's range in the data, its mean removed, Hann-windowed, and projected onto
/// `cos hq, sin hq` (a windowed periodogram; Harris, *Proc. IEEE* 66, 1978) for the orders whose
/// period fits in the range (a longer one cannot be told from a slope); the local maxima of the
/// amplitude, largest first, are reported.
fn series_shapes(
    pool: &Pool,
    terms: &[Term],
    selection: &Selection,
    data: &MeasurementSet,
) -> Result<Vec<Option<SeriesShape>>, Error> {
    let width = |s: &selection::Step| s.scored.order.map_or(terms[s.term].columns.len(), |h| 2 * h as usize);
    let mut columns = pool.kinematic_columns();
    let mut starts = Vec::new();
    for step in &selection.steps {
        starts.push(columns.len());
        columns.extend_from_slice(&terms[step.term].columns[..width(step)]);
    }
    let beta = pool.solve(&[], &columns)?;
    let mut out = Vec::new();
    for (step, start) in selection.steps.iter().zip(starts) {
        let Some(order) = step.scored.order else {
            out.push(None);
            continue;
        };
        let IdentifiedEffect::GearPeriodic(gear) = &terms[step.term].model else {
            out.push(None);
            continue;
        };
        // The parameters multiply the features `cos hq / scale`, `sin hq / scale`.
        let coefficient = |l: usize| beta[start + l] / gear.scale.get(l).copied().unwrap_or(1.0);
        let series = |q: f64| -> f64 {
            (1..=order as usize)
                .map(|h| {
                    let (sin, cos) = (h as f64 * q).sin_cos();
                    coefficient(2 * (h - 1)) * cos + coefficient(2 * (h - 1) + 1) * sin
                })
                .sum()
        };
        out.push(Some(series_shape(&series, data, gear.joint, order)));
    }
    Ok(out)
}

/// Points of the joint's range a series is sampled on for its periodogram.
const SHAPE_SAMPLES: usize = 720;

/// The shape of the joint error `series` of `joint` (0-based) up to `order`: its RMS over the
/// rows, and the local maxima of its windowed periodogram over the joint's range in the data.
fn series_shape(series: &dyn Fn(f64) -> f64, data: &MeasurementSet, joint: usize, order: u32) -> SeriesShape {
    const REPORTED: usize = 3;
    let at_rows: Vec<f64> = data.rows.iter().map(|r| series(r.q[joint])).collect();
    let row_mean = statistics::mean(&at_rows);
    let rms = (at_rows.iter().map(|v| (v - row_mean).powi(2)).sum::<f64>() / at_rows.len().max(1) as f64).sqrt();
    let (low, high) =
        data.rows.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), r| (a.min(r.q[joint]), b.max(r.q[joint])));
    let q: Vec<f64> = (0..SHAPE_SAMPLES).map(|i| low + (high - low) * i as f64 / (SHAPE_SAMPLES - 1) as f64).collect();
    let shortest_resolved = (std::f64::consts::TAU / (high - low).max(f64::MIN_POSITIVE)).ceil().max(1.0) as u32;
    let orders: Vec<u32> = (shortest_resolved..=order).collect();
    let amplitude = periodogram(series, &q, &orders);
    let mut dominant: Vec<DominantHarmonic> = (0..amplitude.len())
        .filter(|&i| {
            (i == 0 || amplitude[i] >= amplitude[i - 1])
                && (i + 1 == amplitude.len() || amplitude[i] > amplitude[i + 1])
        })
        .map(|i| DominantHarmonic {
            order: orders[i],
            period_deg: 360.0 / f64::from(orders[i]),
            amplitude_urad: amplitude[i] * 1e6,
        })
        .collect();
    dominant.sort_by(|a, b| b.amplitude_urad.total_cmp(&a.amplitude_urad));
    dominant.truncate(REPORTED);
    SeriesShape { rms_urad: rms * 1e6, range_deg: (high - low).to_degrees(), dominant }
}

/// The amplitude of each of `orders` in `series` sampled at `q`, its mean removed and
/// Hann-windowed.
fn periodogram(series: &dyn Fn(f64) -> f64, q: &[f64], orders: &[u32]) -> Vec<f64> {
    let mut f: Vec<f64> = q.iter().map(|&q| series(q)).collect();
    let sample_mean = statistics::mean(&f);
    f.iter_mut().for_each(|v| *v -= sample_mean);
    let window: Vec<f64> = (0..SHAPE_SAMPLES)
        .map(|i| 0.5 - 0.5 * (std::f64::consts::TAU * i as f64 / (SHAPE_SAMPLES - 1) as f64).cos())
        .collect();
    let gain: f64 = window.iter().sum();
    orders
        .iter()
        .map(|&h| {
            let (mut re, mut im) = (0.0, 0.0);
            for ((&v, &w), &a) in f.iter().zip(&window).zip(q) {
                let (sin, cos) = (f64::from(h) * a).sin_cos();
                re += w * v * cos;
                im += w * v * sin;
            }
            2.0 * (re * re + im * im).sqrt() / gain
        })
        .collect()
}

/// Diagnoses `data` measured on `robot`.
pub fn diagnose(
    robot: &RobotDescription,
    data: &MeasurementSet,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, Error> {
    options.validate()?;
    // The one binding of the diagnosis: the joints checked, each row's tool its own index (the
    // geometry fitted here takes the data's tools in their order).
    diagnosis(robot, &BoundSet::to_robot(data, &robot.joint_kinds())?, options)
}

/// [`diagnose`] of data already bound to `robot` ([`BoundSet::to_robot`]: the fit's
/// `--effects auto` passes its own binding).
pub fn diagnose_bound(
    robot: &RobotDescription,
    bound: &BoundSet<'_>,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, Error> {
    options.validate()?;
    diagnosis(robot, bound, options)
}

/// The diagnosis of `bound`, its options validated: the outlier screen, the geometry, the
/// candidates' pooled problem, the selection and its orders, the arcs, the structure GP, the
/// noise floor and the verdict, each a phase below, in this order.
fn diagnosis(robot: &RobotDescription, bound: &BoundSet<'_>, options: &DiagnoseOptions) -> Result<Diagnosis, Error> {
    let data = bound.set();
    let needed = options.folds * 10;
    if data.rows.len() < needed {
        return Err(Error::in_file(data.source.clone(), ErrorKind::TooFewRows { rows: data.rows.len(), needed }));
    }
    let nominal = robot.nominal_model()?;
    let screened = timings::phase("outlier screen", || outliers::screen(&nominal, bound, &options.outliers))?;
    let bound = screened.data.as_ref();
    let data = bound.set();
    let geometry = Geometry::fit(&nominal, data, options)?;
    let pooled = Pooled::new(robot, &nominal, &geometry, bound, options)?;
    let (pool, terms) = (&pooled.pool, &pooled.terms);
    let mut selection = timings::phase("selection", || selection::select(pool, terms, &options.selection))?;
    let (order_curves, arcs, heldout_folds) = over_arcs(&geometry, data, &pooled, &mut selection, options)?;
    let all_selected = selection.last();
    let checks = StructureChecks::run(&geometry, data, &pooled.fold, &selection, options)?;
    let noise = noise_floor(data, options);
    let (decision, verdict, verdict_result) = name_verdict(&pooled, &selection, &checks, &noise, options)?;
    let gross_outliers = screened.judged(&all_selected.errors);
    let (verdict, verdict_result) = gross_outliers.verdict(verdict, verdict_result);
    let shapes = series_shapes(pool, terms, &selection, data)?;
    let poses = pose_diagnoses(robot, &nominal, &geometry, data, &selection)?;
    let prismatic = prismatic_joints(robot);
    let regions = regions::regions(&poses, &geometry.moving, &prismatic);
    let before_mm = selection.baseline.mean_error() * 1e3;
    Ok(Diagnosis {
        robot: robot.name.clone(),
        n: data.rows.len(),
        full_pose: data.full_pose,
        moving_joints: geometry.moving.iter().map(|j| j + 1).collect(),
        prismatic_joints: prismatic,
        verdict,
        heldout_before_mm: before_mm,
        heldout_after_mm: verdict_result.map_or(before_mm, |m| m * 1e3),
        heldout_after_selected_mm: all_selected.mean_error() * 1e3,
        explained_fraction: decision.explained_fraction,
        candidates: candidate_scores(terms, &selection),
        selected: selected_effects(terms, &selection, shapes, order_curves),
        critical_z: selection.critical_z,
        explainable: checks.explainable,
        remaining: checks.remaining,
        noise,
        regions,
        off_poses_before_mm: arcs::mean_of(&arcs, |a| a.before_mm),
        off_poses_after_mm: arcs::mean_of(&arcs, |a| a.after_mm),
        arcs,
        poses,
        gross_outliers,
        folds: heldout_folds,
    })
}

/// The geometric model fitted to every (screened) row, and the linear problem around it.
struct Geometry {
    model: LocalPoe,
    design: Design,
    /// 0-based joints whose angles span more than `moving_min_range_rad`.
    moving: Vec<usize>,
}

impl Geometry {
    fn fit(nominal: &LocalPoe, data: &MeasurementSet, options: &DiagnoseOptions) -> Result<Self, Error> {
        let geometry =
            timings::phase("geometry", || fit_geometry(nominal, data, Scope::Full, &IdentificationOptions::default()))?;
        let model = geometry.model;
        let stats = poe::identify::evaluate(&model, &observations(data)).map_err(Error::kinematics)?;
        // Weight each kind of row by its own residual scale, so that neither swamps the other.
        let weights = Weights {
            position_m: (stats.rms_position_m / 3f64.sqrt()).max(1e-9),
            rotation_rad: stats.rms_rotation_rad.map_or(1.0, |r| (r / 3f64.sqrt()).max(1e-12)),
        };
        let design = Design::new(&model, data, weights)?;
        let moving = moving_joints(data, options.moving_min_range_rad);
        Ok(Self { model, design, moving })
    }
}

/// Every candidate effect as columns of one pooled problem: the candidates built from the data,
/// then the backlash sides learnt inside each fold.
struct Pooled {
    candidates: Vec<candidates::Candidate>,
    /// The candidates' terms, then one per learnt side.
    terms: Vec<Term>,
    /// Each learnt side's column on every row, in the order of its term.
    side_columns: Vec<Vec<f64>>,
    /// Each row's random fold.
    fold: Vec<usize>,
    kinematic_prior: pool::KinematicPrior,
    pool: Pool,
}

impl Pooled {
    fn new(
        robot: &RobotDescription,
        nominal: &LocalPoe,
        geometry: &Geometry,
        bound: &BoundSet<'_>,
        options: &DiagnoseOptions,
    ) -> Result<Self, Error> {
        let (model, design, data, folds) = (&geometry.model, &geometry.design, bound.set(), options.folds);
        let settings = candidates::Settings {
            moving: &geometry.moving,
            orders: &options.selection.series_orders,
            series_sd: options.prior.series_rad,
            inputs: options.candidates,
        };
        let (candidates, sides) =
            timings::phase("candidates", || candidates::build_candidates(robot, model, bound, design, &settings))?;
        let (mut terms, blocks) = terms_of(&candidates, design.kinematic.ncols());
        let fold = fold_assignment(data.rows.len(), folds, options.seed);
        let kinematic_prior = pool::KinematicPrior::new(nominal, model, &options.prior);
        let mut pool = Pool::new(design, &kinematic_prior, &blocks, &fold, folds, &options.prior);
        // Backlash sides learnt inside each fold: a column per fold and one on every row.
        let candidate_columns: Vec<Vec<usize>> = terms.iter().map(|t| t.columns.clone()).collect();
        let mut side_columns: Vec<Vec<f64>> = Vec::new();
        let learnt = timings::phase("learnt backlash sides", || {
            learnt_side::learnt_sides(&pool, design, model, bound, &candidates, &candidate_columns, &sides)
        })?;
        let sets: Vec<Vec<Vec<f64>>> = learnt
            .iter()
            .map(|side| side.per_fold.iter().chain(std::iter::once(&side.all)).cloned().collect())
            .collect();
        let ranges = pool.extend_sets(&sets, None, &options.prior);
        for (side, range) in learnt.into_iter().zip(ranges) {
            side_columns.push(side.all);
            let indices: Vec<usize> = range.collect();
            let all = indices[indices.len() - 1];
            terms.push(Term {
                effect: Effect::Backlash,
                joints: vec![side.joint + 1],
                columns: vec![all],
                per_fold: Some(indices[..indices.len() - 1].iter().map(|&c| vec![c]).collect()),
                orders: None,
                model: side.model,
            });
        }
        Ok(Self { candidates, terms, side_columns, fold, kinematic_prior, pool })
    }

    /// Term `t`'s columns on every row and their prior, for the fits over the arcs.
    fn columns_of(&self, t: usize) -> (Vec<Vec<f64>>, Option<f64>) {
        match self.candidates.get(t) {
            Some(c) => (c.columns.clone(), c.prior_sd),
            None => (vec![self.side_columns[t - self.candidates.len()].clone()], None),
        }
    }
}

/// Each selected series' order curve, the arc checks and the folds (`over_arcs`).
type OverArcs = (Vec<Vec<OrderScore>>, Vec<ArcCheck>, HeldoutFolds);

/// What the arcs decide and measure: each selected series' order (its curves), then the arc
/// checks and the folds, from one pool per moving joint.
fn over_arcs(
    geometry: &Geometry,
    data: &MeasurementSet,
    pooled: &Pooled,
    selection: &mut Selection,
    options: &DiagnoseOptions,
) -> Result<OverArcs, Error> {
    let arc_inputs = arcs::ArcInputs {
        design: &geometry.design,
        kinematic_prior: &pooled.kinematic_prior,
        prior: &options.prior,
        gear: &effects::GearOptions::default(),
        folds: options.arc_folds,
    };
    let arc_pools = timings::phase("arc pools", || {
        arcs::ArcPools::new(&arc_inputs, data, &geometry.moving, selection, &|t| pooled.columns_of(t))
    });
    let order_curves = choose_series_orders(&arc_pools, pooled, selection, options)?;
    let (arcs, heldout_folds) = arc_checks(&arc_inputs, &arc_pools, data, pooled, selection)?;
    Ok((order_curves, arcs, heldout_folds))
}

/// Each selected series' order: its random folds' curve and its curve over the other joints'
/// arcs, weighed (`SelectionOptions::arc_order_weight`). Returns every selected step's curve.
fn choose_series_orders(
    arc_pools: &arcs::ArcPools,
    pooled: &Pooled,
    selection: &mut Selection,
    options: &DiagnoseOptions,
) -> Result<Vec<Vec<OrderScore>>, Error> {
    let weight = options.selection.arc_order_weight;
    let arc_curves = if weight > 0.0 {
        timings::phase("arc order curves", || arcs::order_curves(arc_pools, &pooled.terms, selection))?
    } else {
        vec![None; selection.steps.len()]
    };
    let mut order_curves: Vec<Vec<OrderScore>> = Vec::with_capacity(selection.steps.len());
    for (step, arc_curve) in selection.steps.iter_mut().zip(&arc_curves) {
        let scores: Vec<OrderScore> = step
            .scored
            .curve
            .iter()
            .map(|&(order, random)| OrderScore {
                order,
                random_folds_mm: random * 1e3,
                arcs_mm: arc_curve
                    .as_ref()
                    .and_then(|(orders, c)| orders.iter().position(|&h| h == order).map(|i| c[i] * 1e3)),
            })
            .collect();
        if arc_curve.is_some() && !scores.is_empty() {
            let combined: Vec<f64> = scores
                .iter()
                .map(|s| (1.0 - weight) * s.random_folds_mm + weight * s.arcs_mm.unwrap_or(s.random_folds_mm))
                .collect();
            step.scored.order = Some(scores[selection::argmin(&combined)].order);
        }
        order_curves.push(scores);
    }
    Ok(order_curves)
}

/// Folds that see gaps: per moving joint, the held-out error when contiguous arcs of its angles
/// are left out; and the random folds and the arcs fold by fold, for a stage fitted on top.
fn arc_checks(
    arc_inputs: &arcs::ArcInputs<'_>,
    arc_pools: &arcs::ArcPools,
    data: &MeasurementSet,
    pooled: &Pooled,
    selection: &Selection,
) -> Result<(Vec<ArcCheck>, HeldoutFolds), Error> {
    let (arcs, arc_folds): (Vec<ArcCheck>, Vec<(usize, Vec<FoldResiduals>)>) =
        timings::phase("arcs", || arcs::arc_checks(arc_inputs, arc_pools, data, &pooled.terms, selection))?
            .into_iter()
            .map(|(check, folds)| {
                let joint = check.joint;
                (check, (joint, folds))
            })
            .unzip();
    let heldout_folds = HeldoutFolds {
        rows: data.rows.clone(),
        random: fold_residuals::random_folds(&pooled.pool, &selection.last().fold_columns)?,
        arcs: arc_folds,
    };
    Ok((arcs, heldout_folds))
}

/// 1-based prismatic joints.
fn prismatic_joints(robot: &RobotDescription) -> Vec<usize> {
    (0..robot.joint_count()).filter(|&j| robot.joints[j].kind == poe::JointKind::Prismatic).map(|j| j + 1).collect()
}

/// What any smooth function of the joint angles explains, before and after the effects.
struct StructureChecks {
    gp_before: Option<structure::Structure>,
    gp_after: Option<structure::Structure>,
    explainable: Option<GpCheck>,
    remaining: Option<GpCheck>,
}

impl StructureChecks {
    fn run(
        geometry: &Geometry,
        data: &MeasurementSet,
        fold: &[usize],
        selection: &Selection,
        options: &DiagnoseOptions,
    ) -> Result<Self, Error> {
        let all_selected = selection.last();
        let single_critical = statistics::normal_quantile(1.0 - options.selection.significance);
        let link1: Vec<lie::SO3> = data
            .rows
            .iter()
            .map(|row| Ok(geometry.model.frames(&row.q).map_err(Error::kinematics)?[0].rotation()))
            .collect::<Result<_, Error>>()?;
        let structure = |residuals: &[lie::Vector6]| {
            let (moving, folds) = (&geometry.moving, options.folds);
            structure::residual_structure(residuals, &link1, data, moving, fold, folds, &options.structure)
        };
        let (gp_before, gp_after) = if options.structure.enabled {
            // The two are independent (each deterministic): run side by side, so that their ten fold
            // fits share the threads.
            let (before, after) = timings::phase("structure GP", || {
                rayon::join(
                    || structure(&selection.baseline.residuals),
                    || (!selection.steps.is_empty()).then(|| structure(&all_selected.residuals)).transpose(),
                )
            });
            (Some(before?), after?)
        } else {
            (None, None)
        };
        let explainable =
            gp_before.as_ref().map(|s| GpCheck::new(&selection.baseline.errors, s, single_critical, &options.verdict));
        let remaining = match &gp_after {
            Some(s) => Some(GpCheck::new(&all_selected.errors, s, single_critical, &options.verdict)),
            None if selection.steps.is_empty() => explainable.clone(),
            None => None,
        };
        Ok(Self { gp_before, gp_after, explainable, remaining })
    }

    /// The 1-based joints of a GP that found significant structure (after the effects if it did
    /// there), for an `unknown` verdict; an insignificant GP's length scales point nowhere.
    fn telling_joints(&self, short_length_scale: f64) -> Vec<usize> {
        let significant = |check: &Option<GpCheck>| check.as_ref().is_some_and(|c| c.significant);
        let telling = if significant(&self.remaining) && self.gp_after.is_some() {
            self.gp_after.as_ref()
        } else if significant(&self.explainable) {
            self.gp_before.as_ref()
        } else {
            None
        };
        telling.map_or(vec![], |s| {
            let mut joints: Vec<usize> = s
                .relevant(short_length_scale)
                .into_iter()
                .filter_map(|(input, _)| match input {
                    GpInput::Joint(j) => Some(j),
                    _ => None,
                })
                .collect();
            joints.sort_unstable();
            joints
        })
    }
}

/// The noise floor: given, from repeated poses, stated by the data, or the instrument's default.
fn noise_floor(data: &MeasurementSet, options: &DiagnoseOptions) -> NoiseFloor {
    match (options.noise_mm, noise::from_repeats(data), noise::stated(data)) {
        (Some(sigma), _, _) => NoiseFloor::from_sigma(sigma, NoiseSource::Given),
        (None, Some(sigma), _) => NoiseFloor::from_sigma(sigma, NoiseSource::Repeats),
        (None, None, Some(sigma)) => NoiseFloor::from_sigma(sigma, NoiseSource::Stated),
        (None, None, None) => noise::tracker_default(data, &options.tracker),
    }
}

/// The verdict (before the gross outliers have their say) and the mean held-out error, m, with
/// its effect alone where that differs from every selected effect.
fn name_verdict(
    pooled: &Pooled,
    selection: &Selection,
    checks: &StructureChecks,
    noise: &NoiseFloor,
    options: &DiagnoseOptions,
) -> Result<(verdict::Decision, Verdict, Option<f64>), Error> {
    let (terms, all_selected) = (&pooled.terms, selection.last());
    let evidence = verdict::Evidence {
        before: &selection.baseline.errors,
        selected: &all_selected.errors,
        gp_before: checks
            .gp_before
            .as_ref()
            .map(|s| (s.errors.as_slice(), checks.explainable.as_ref().is_some_and(|c| c.significant))),
        gp_after: checks.gp_after.as_ref().map(|s| s.errors.as_slice()),
        floor: noise.floor_mm * 1e-3,
    };
    let decision = verdict::decide(&evidence, !selection.steps.is_empty(), &options.verdict);
    let (verdict, verdict_result) = match selection.steps.first() {
        _ if decision.unknown => (
            Verdict { effect: Effect::Unknown, joints: checks.telling_joints(options.structure.short_length_scale) },
            None,
        ),
        None => (Verdict { effect: Effect::None, joints: vec![] }, None),
        Some(first) => {
            let effect = terms[first.term].effect;
            let keep: Vec<usize> =
                (0..selection.steps.len()).filter(|&s| terms[selection.steps[s].term].effect == effect).collect();
            let mut joints: Vec<usize> =
                keep.iter().flat_map(|&s| terms[selection.steps[s].term].joints.clone()).collect();
            joints.sort_unstable();
            joints.dedup();
            let result = if keep.len() == selection.steps.len() {
                None
            } else {
                Some(selection::with_steps(&pooled.pool, terms, selection, &keep)?)
            };
            (Verdict { effect, joints }, Some(result.map_or(all_selected.mean_error(), |r| r.mean_error())))
        }
    };
    Ok((decision, verdict, verdict_result))
}

/// Every pose's residuals before and after the selected effects, in the robot's base frame.
fn pose_diagnoses(
    robot: &RobotDescription,
    nominal: &LocalPoe,
    geometry: &Geometry,
    data: &MeasurementSet,
    selection: &Selection,
) -> Result<Vec<PoseDiagnosis>, Error> {
    let all_selected = selection.last();
    // Base-frame axes for the breakdown: tracker_from_base = calibrated · nominal⁻¹ at q = 0.
    let zero = vec![0.0; robot.joint_count()];
    let tracker_from_base = geometry.model.frames(&zero).map_err(Error::kinematics)?[0]
        * nominal.frames(&zero).map_err(Error::kinematics)?[0].inverse();
    let base_from_tracker = tracker_from_base.inverse();
    let to_base = |v: &lie::Vector6| -> [f64; 3] {
        let r = base_from_tracker.rotation().act(&Vector3::new(v[0], v[1], v[2])) * 1e3;
        [r.x, r.y, r.z]
    };
    Ok(data
        .rows
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let p = base_from_tracker.transform_point(&geometry.design.points[i]);
            let (b, a) = (&selection.baseline.residuals[i], &all_selected.residuals[i]);
            let rotation = |v: &lie::Vector6| Vector3::new(v[3], v[4], v[5]).norm() * 1e3;
            PoseDiagnosis {
                line: row.line,
                q: row.q.clone(),
                payload_kg: row.payload_kg,
                temp_c: row.temp_c,
                t_s: row.t_s,
                reach_m: (p.x * p.x + p.y * p.y).sqrt(),
                height_m: p.z,
                before_mm: to_base(b),
                after_mm: to_base(a),
                rotation_mrad: data.full_pose.then(|| [rotation(b), rotation(a)]),
            }
        })
        .collect())
}

/// Every candidate tried alone on top of the geometric model, best first.
fn candidate_scores(terms: &[Term], selection: &Selection) -> Vec<CandidateScore> {
    let mut scores: Vec<CandidateScore> = terms
        .iter()
        .zip(&selection.single)
        .map(|(t, s)| CandidateScore {
            effect: t.effect,
            joints: t.joints.clone(),
            harmonic: s.order,
            parameters: s.order.map_or(t.columns.len(), |h| 2 * h as usize),
            heldout_after_mm: s.result.mean_error() * 1e3,
        })
        .collect();
    scores.sort_by(|a, b| a.heldout_after_mm.total_cmp(&b.heldout_after_mm));
    scores
}

/// The effects kept, in the order they were selected, with their shapes and order curves.
fn selected_effects(
    terms: &[Term],
    selection: &Selection,
    shapes: Vec<Option<SeriesShape>>,
    order_curves: Vec<Vec<OrderScore>>,
) -> Vec<SelectedEffect> {
    selection
        .steps
        .iter()
        .zip(shapes)
        .zip(order_curves)
        .map(|((s, shape), order_curve)| SelectedEffect {
            effect: terms[s.term].effect,
            joints: terms[s.term].joints.clone(),
            harmonic: s.scored.order,
            fold_orders: s.scored.fold_orders.clone(),
            order_curve,
            shape,
            heldout_after_mm: s.scored.result.mean_error() * 1e3,
            z: s.z,
        })
        .collect()
}
