//! `calib diagnose`: where the geometric model still misses, which unmodelled effect explains it,
//! and how far the error shrinks once that effect is modelled — all on held-out rows.
//!
//! 1. *Where*: the local POE model is fitted to every row; K-fold cross-validation of one
//!    linearised step from that solution gives each row's held-out residual, broken down by
//!    component, payload, joint angle, reach, height, temperature and time (module `regions`).
//! 2. *Which*: each effect of `loadsim` becomes extra columns of the same linear problem
//!    (module `candidates`); greedy forward selection keeps an effect only when its held-out
//!    gain is significant (module `selection`).
//! 3. *How far*: held-out error before and after, overall and per region.

mod candidates;
mod design;
mod noise;
mod regions;
mod report;
mod selection;
mod statistics;
mod structure;
mod svg;

pub use candidates::{CandidateOptions, Effect};
pub use noise::{NoiseFloor, NoiseSource};
pub use regions::{PoseDiagnosis, Region};
pub use report::{CandidateScore, Remaining, SelectedEffect, Verdict};
pub use selection::SelectionOptions;

use crate::geometric::{fit_geometry, observations};
use crate::{Error, MeasurementSet, RobotDescription};
use design::{Design, Weights};
use lie::Vector3;
use poe::identify::{IdentificationOptions, Scope};
use rand::SeedableRng;
use rand::seq::SliceRandom;
use serde::{Deserialize, Serialize};

/// How to diagnose.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct DiagnoseOptions {
    /// Number of cross-validation folds.
    pub folds: usize,
    /// Seed of the fold assignment.
    pub seed: u64,
    /// The measurement noise per axis, mm, if known; otherwise it is estimated.
    pub noise_mm: Option<f64>,
    /// Which candidates to try.
    pub candidates: CandidateOptions,
    /// How strict the selection is.
    pub selection: SelectionOptions,
    /// Look for structure no candidate explains with a cross-validated GP on the final residual
    /// (the `unknown` verdict). It costs a few GP fits.
    pub check_structure: bool,
    /// The GP must lower the held-out error by at least this fraction to count as structure.
    pub structure_min_gain: f64,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            folds: 5,
            seed: 0,
            noise_mm: None,
            candidates: CandidateOptions::default(),
            selection: SelectionOptions::default(),
            check_structure: true,
            structure_min_gain: 0.1,
        }
    }
}

/// The diagnosis of one data set.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Diagnosis {
    /// The robot's name.
    pub robot: String,
    /// Number of poses.
    pub n: usize,
    /// Whether the data has orientations.
    pub full_pose: bool,
    /// The verdict.
    pub verdict: Verdict,
    /// Cross-validated mean position error of the geometric model, mm.
    pub heldout_before_mm: f64,
    /// The same with the verdict's effects modelled, mm.
    pub heldout_after_mm: f64,
    /// Every candidate tried alone on top of the geometric model, best first.
    pub candidates: Vec<CandidateScore>,
    /// The effects kept, in the order they were selected.
    pub selected: Vec<SelectedEffect>,
    /// The critical paired t value a candidate had to pass.
    pub critical_t: f64,
    /// What a GP on the final residual still finds, if that was checked.
    pub remaining: Option<Remaining>,
    /// The noise floor.
    pub noise: NoiseFloor,
    /// The held-out error by region.
    pub regions: Vec<Region>,
    /// Every pose.
    pub poses: Vec<PoseDiagnosis>,
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

/// Diagnoses `data` measured on `robot`.
pub fn diagnose(
    robot: &RobotDescription,
    data: &MeasurementSet,
    options: &DiagnoseOptions,
) -> Result<Diagnosis, Error> {
    data.check_joint_count(robot.joint_count())?;
    let folds = options.folds.max(2);
    let needed = folds * 10;
    if data.rows.len() < needed {
        return Err(Error::TooFewRows { file: data.source.clone(), rows: data.rows.len(), needed });
    }
    let nominal = robot.nominal_model()?;
    let geometry = fit_geometry(&nominal, data, Scope::Full, &IdentificationOptions::default())?;
    let model = geometry.model;
    let stats = poe::identify::evaluate(&model, &observations(data))?;
    // Weight each kind of row by its own residual scale, so that neither swamps the other.
    let weights = Weights {
        position_m: (stats.rms_position_m / 3f64.sqrt()).max(1e-9),
        rotation_rad: stats.rms_rotation_rad.map_or(1.0, |r| (r / 3f64.sqrt()).max(1e-12)),
    };
    let design = Design::new(&model, data, weights)?;
    let candidates = candidates::build_candidates(robot, &model, data, &design, &options.candidates)?;
    let fold = fold_assignment(data.rows.len(), folds, options.seed);
    let selection = selection::select(&design, &candidates, &fold, folds, &options.selection);

    let after = selection.steps.last().map_or(&selection.baseline, |s| &s.result);
    let structure =
        if options.check_structure { Some(structure::residual_structure(after, data, &fold, folds)?) } else { None };
    let remaining = structure.as_ref().map(|s| {
        let critical = statistics::normal_quantile(1.0 - options.selection.significance);
        let gain = 1.0 - s.after_gp_m / after.mean_error().max(f64::MIN_POSITIVE);
        Remaining {
            heldout_after_gp_mm: s.after_gp_m * 1e3,
            t: s.t,
            significant: s.t > critical && gain >= options.structure_min_gain,
        }
    });
    let noise = match (options.noise_mm, noise::from_repeats(data), &structure) {
        (Some(sigma), _, _) => NoiseFloor::from_sigma(sigma, NoiseSource::Given),
        (None, Some(sigma), _) => NoiseFloor::from_sigma(sigma, NoiseSource::Repeats),
        (None, None, Some(s)) => NoiseFloor::from_sigma(s.sigma_m * 1e3, NoiseSource::ResidualGp),
        (None, None, None) => report::residual_noise(after),
    };

    // Base-frame axes for the breakdown: tracker_from_base = calibrated · nominal⁻¹ at q = 0.
    let zero = vec![0.0; robot.joint_count()];
    let tracker_from_base = model.frames(&zero)?[0] * nominal.frames(&zero)?[0].inverse();
    let base_from_tracker = tracker_from_base.inverse();
    let to_base = |v: &lie::Vector6| -> [f64; 3] {
        let r = base_from_tracker.rotation().act(&Vector3::new(v[0], v[1], v[2])) * 1e3;
        [r.x, r.y, r.z]
    };
    let poses: Vec<PoseDiagnosis> = data
        .rows
        .iter()
        .enumerate()
        .map(|(i, row)| {
            let p = base_from_tracker.transform_point(&design.points[i]);
            let (b, a) = (&selection.baseline.residuals[i], &after.residuals[i]);
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
        .collect();
    Ok(report::assemble(robot, data, &candidates, &selection, remaining, noise, poses))
}
