//! The side of a joint's backlash band, learnt from the data inside each fold: the sign of the
//! joint's torque `τ = Y(q) π` with `π` unknown (a balancer or an unknown mass moves its zero away
//! from where a stand-in mass model puts it).
//!
//! On the training rows of one fold only: start from the sign of the joint's fitted compliance
//! deflection (proportional to the torque); then alternate: given the signs, fit the band to what
//! the kinematics leave and flip every pose whose residual the other side explains better; given
//! the flipped signs, refit `π` by least squares on them (a linear classifier over the torque
//! regressors), so that the side stays a function of the torque and does not follow the noise.
//! The held-out poses get the side that classifier gives them: nothing about them is learnt.

use super::candidates::{Candidate, SideSource, columns_of};
use super::design::Design;
use super::pool::Pool;
use effects::{BacklashTerm, Direction, GearPeriodicTerm, IdentifiedEffect, RowTwists, TorqueSign};
use errors::Error;
use lie::Vector6;
use measurements::BoundSet;
use poe::LocalPoe;
use rayon::prelude::*;

/// Alternations of the side and the classifier (the sides settle in two or three).
const ALTERNATIONS: usize = 5;

/// One joint's learnt side: a column per fold, learnt without its rows, and one on every row.
#[derive(Debug, Clone)]
pub(crate) struct LearntSide {
    /// 0-based joint.
    pub joint: usize,
    /// Weighted column of every pose, side learnt without fold `f`'s rows.
    pub per_fold: Vec<Vec<f64>>,
    /// The same learnt on every row, and the effect it defines (what a fit would use).
    pub all: Vec<f64>,
    /// The effect learnt on every row.
    pub model: IdentifiedEffect,
}

fn sign(x: f64) -> f64 {
    loadsim::backlash_joint_regressor(&[x])[0]
}

/// What every fold's learnt side of one joint is computed from, once for all of them.
struct SideRows<'a> {
    /// The compliance candidate's features at every row and its pool columns.
    compliance: (&'a [Vec<f64>], &'a [usize]),
    /// The joint's bare twist as weighted rows, `rows_per_pose` per pose.
    twist_rows: &'a [f64],
    /// The joint's row of the gravity-torque regressors at every row (`TorqueSign::learnt_torque`).
    regressors: &'a [Vec<f64>],
    /// The joint's twist at every row.
    twists: &'a [Vector6],
}

/// Learns the side of `source`'s joint without the folds `left_out`; returns the effect and its
/// weighted column on every row: [`columns_of`] of that effect, from the regressors and twists
/// computed once for every fold (the same products in the same order).
fn learn(
    pool: &Pool,
    design: &Design,
    source: &SideSource,
    rows: &SideRows<'_>,
    data: &BoundSet<'_>,
    left_out: &[usize],
) -> Result<(IdentifiedEffect, Vec<f64>), Error> {
    let ((scalars, compliance_columns), twist_rows) = (rows.compliance, rows.twist_rows);
    let k = twist_rows.len() / data.len().max(1);
    let train: Vec<usize> = (0..pool.folds()).filter(|f| !left_out.contains(f)).collect();
    let torque = |theta: &[f64], i: usize| -> f64 { scalars[i].iter().zip(theta).map(|(s, t)| s * t).sum() };
    let kinematic = pool.kinematic_columns();
    let with: Vec<usize> = kinematic.iter().chain(compliance_columns).copied().collect();
    let beta = pool.solve(left_out, &with)?;
    let mut pi: Vec<f64> = beta[kinematic.len()..].to_vec();
    let mut signs: Vec<f64> = (0..data.len()).map(|i| sign(torque(&pi, i))).collect();
    // What the kinematics alone leave on the training rows, pose by pose.
    let beta0 = pool.solve(left_out, &kinematic)?;
    let residual: Vec<(usize, Vec<f64>)> = train
        .iter()
        .flat_map(|&g| {
            let r = pool.weighted_residual(g, &kinematic, &beta0);
            pool.fold_poses(g)
                .iter()
                .enumerate()
                .map(move |(p, &i)| (i, r[p * k..(p + 1) * k].to_vec()))
                .collect::<Vec<_>>()
        })
        .collect();
    let dot = |i: usize, r: &[f64]| -> f64 { (0..k).map(|c| twist_rows[i * k + c] * r[c]).sum() };
    for _ in 0..ALTERNATIONS {
        let (mut numerator, mut denominator) = (0.0, 0.0);
        for (i, r) in &residual {
            numerator += signs[*i] * dot(*i, r);
            denominator += (0..k).map(|c| twist_rows[i * k + c].powi(2)).sum::<f64>();
        }
        let band = numerator / denominator.max(f64::MIN_POSITIVE);
        // Flipping a pose's side moves its prediction by −2 b s_i t_i: better when b s_i ⟨t_i, r_i⟩ < 0.
        let flipped: Vec<(usize, f64)> = residual
            .iter()
            .map(|(i, r)| (*i, if band * signs[*i] * dot(*i, r) < 0.0 { -signs[*i] } else { signs[*i] }))
            .collect();
        let width = pi.len();
        let y = nalgebra::DMatrix::from_fn(flipped.len(), width, |p, l| scalars[flipped[p].0][l]);
        let norms: Vec<f64> = (0..width).map(|l| y.column(l).norm().max(f64::MIN_POSITIVE)).collect();
        let scaled = nalgebra::DMatrix::from_fn(flipped.len(), width, |p, l| y[(p, l)] / norms[l]);
        let target = nalgebra::DVector::from_iterator(flipped.len(), flipped.iter().map(|(_, s)| *s));
        // A failed SVD keeps the sides found so far, which are a valid classifier's.
        let Ok(solution) = scaled.svd(true, true).solve(&target, 1e-10) else {
            break;
        };
        pi = solution.iter().zip(&norms).map(|(p, n)| p / n).collect();
        let next: Vec<f64> = (0..data.len()).map(|i| sign(torque(&pi, i))).collect();
        if next == signs {
            break;
        }
        signs = next;
    }
    let columns: Vec<usize> = source.terms.iter().map(|t| t.column).collect();
    let coefficients: Vec<f64> = pi.iter().zip(&source.terms).map(|(c, t)| c / t.scale).collect();
    let torques: Vec<f64> =
        rows.regressors.iter().map(|row| TorqueSign::learnt_torque(row, &columns, &coefficients)).collect();
    let learnt = TorqueSign::Learnt { load: source.load.clone(), columns, coefficients };
    let term = BacklashTerm::with_torques(source.joint, learnt, &torques);
    let k = design.rows_per_pose;
    let mut column = vec![0.0; k * torques.len()];
    for (i, (&torque, twist)) in torques.iter().zip(rows.twists).enumerate() {
        design.twist_rows(i, &(twist * term.feature_of(torque)), &mut column[i * k..(i + 1) * k]);
    }
    Ok((IdentifiedEffect::Backlash(term), column))
}

/// The learnt side of every source joint: per fold, and on every row.
pub(crate) fn learnt_sides(
    pool: &Pool,
    design: &Design,
    model: &LocalPoe,
    data: &BoundSet<'_>,
    candidates: &[Candidate],
    candidate_columns: &[Vec<usize>],
    sources: &[SideSource],
) -> Result<Vec<LearntSide>, Error> {
    // Each source, and each fold's side within it, is learnt on its own: side by side on the
    // rayon pool, collected in order, so the result is the serial one.
    let learnt = sources
        .par_iter()
        .map(|source| -> Result<Option<LearntSide>, Error> {
            let compliance = &candidates[source.compliance];
            let columns = &candidate_columns[source.compliance];
            // The joint's bare twist: order 0's cosine feature is 1 on every row.
            let bare = IdentifiedEffect::GearPeriodic(GearPeriodicTerm::new(source.joint, vec![0], data.rows())?);
            let twist_rows = columns_of(design, &bare, model, data)?.swap_remove(0);
            // The compliance's features of every row, once for all the folds' alternations.
            let scalars: Vec<Vec<f64>> =
                data.iter().map(|(row, tool)| compliance.model.features(row, tool)).collect::<Result<_, _>>()?;
            // The regressors and the joint's twists of every row, once for all the folds' sides.
            let regressors = TorqueSign::learnt_regressor_rows(&source.load, source.joint, data)?;
            let twists: Vec<Vector6> = data
                .iter()
                .map(|(row, tool)| RowTwists::new(model, &row.q, tool).twist(Direction::Joint(source.joint)))
                .collect::<Result<_, _>>()?;
            let rows = SideRows {
                compliance: (scalars.as_slice(), columns.as_slice()),
                twist_rows: &twist_rows,
                regressors: &regressors,
                twists: &twists,
            };
            // Folds 0 … k-1 each held out, then none (k): every row.
            let mut fits = (0..=pool.folds())
                .into_par_iter()
                .map(|f| {
                    let held = [f];
                    let held: &[usize] = if f < pool.folds() { &held } else { &[] };
                    learn(pool, design, source, &rows, data, held)
                })
                .collect::<Result<Vec<_>, _>>()?;
            let (effect, all) = fits.pop().expect("the fit on every row");
            let per_fold: Vec<Vec<f64>> = fits.into_iter().map(|(_, column)| column).collect();
            let nonzero = |c: &Vec<f64>| c.iter().any(|v| v.abs() > 1e-12);
            let learnt = nonzero(&all) && per_fold.iter().all(nonzero);
            Ok(learnt.then_some(LearntSide { joint: source.joint, per_fold, all, model: effect }))
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(learnt.into_iter().flatten().collect())
}

#[cfg(test)]
mod tests {
    use super::super::candidates::{Settings, build_candidates};
    use super::super::design::Weights;
    use super::super::pool::{KinematicPrior, PriorOptions};
    use super::super::{fold_assignment, terms_of};
    use super::*;
    use campaign::{Effects, GeneratorConfig, Perturbation, TrackerNoiseModel, joint_ranges, simulate, simulated_cell};
    use robot::RobotDescription;

    /// A simulated IRB 4400 campaign with backlash, the robot without its mass model (so its
    /// sides are learnt), its nominal model and the geometry fitted to it.
    fn simulated_backlash() -> (RobotDescription, measurements::MeasurementSet, LocalPoe, LocalPoe) {
        let robot = testkit::robot("irb4400.ron");
        let cell = simulated_cell(&robot, &Perturbation::default(), 41).unwrap();
        let effects = Effects {
            backlash: Some(loadsim::BacklashModel::uniform(6, 3e-4)),
            tracker_noise: Some(TrackerNoiseModel::default()),
            ..Effects::default()
        };
        let config = GeneratorConfig { sample_count: 120, seed: 41, ..GeneratorConfig::default() };
        let data = simulate(&cell, &effects, &joint_ranges(&robot), &config, false).unwrap();
        let blind = RobotDescription { dynamics: None, ..robot.clone() };
        let nominal = blind.nominal_model().unwrap();
        let model = model::geometric::fit_geometry(
            &nominal,
            &data,
            poe::identify::Scope::Full,
            &poe::identify::IdentificationOptions::default(),
        )
        .unwrap()
        .model;
        (blind, data, nominal, model)
    }

    fn settings() -> Settings<'static> {
        Settings { moving: &[], orders: &[1], series_sd: 1e-3, inputs: effects::CandidateOptions::default() }
    }

    #[test]
    fn a_fold_s_learnt_side_does_not_depend_on_the_fold_s_own_rows() {
        let (blind, data, nominal, model) = simulated_backlash();
        let design = Design::new(&model, &data, Weights { position_m: 1e-4, rotation_rad: 1.0 }).unwrap();
        let settings = settings();
        let bound = measurements::BoundSet::to_robot(&data, &blind.joint_kinds()).unwrap();
        let (candidates, sources) = build_candidates(&blind, &model, &bound, &design, &settings).unwrap();
        assert!(!sources.is_empty());
        let fold = fold_assignment(data.rows.len(), 5, 0);
        let prior = PriorOptions::default();
        let sides = |design: &Design| {
            let (terms, blocks) = terms_of(&candidates, design.kinematic.ncols());
            let columns: Vec<Vec<usize>> = terms.iter().map(|t| t.columns.clone()).collect();
            let pool = Pool::new(design, &KinematicPrior::new(&nominal, &model, &prior), &blocks, &fold, 5, &prior);
            learnt_sides(&pool, design, &model, &bound, &candidates, &columns, &sources).unwrap()
        };
        let before = sides(&design);
        // Other measurements on the poses of fold 0 only.
        let mut changed = design.clone();
        for (i, _) in fold.iter().enumerate().filter(|(_, f)| **f == 0) {
            for r in 0..3 {
                changed.y[3 * i + r] += if (i + r) % 2 == 0 { 40.0 } else { -40.0 };
            }
        }
        let after = sides(&changed);
        assert_eq!(before.len(), after.len());
        let mut moved_elsewhere = false;
        for (a, b) in before.iter().zip(&after) {
            assert_eq!(a.per_fold[0], b.per_fold[0], "joint {}: fold 0's side saw fold 0", a.joint + 1);
            moved_elsewhere |= a.per_fold[1] != b.per_fold[1];
        }
        assert!(moved_elsewhere, "the other folds learn from fold 0's rows");
    }

    /// The learnt side's column is built from regressors and twists computed once for every fold:
    /// it must be, to the bit, what the effect's own regressor gives on every row.
    #[test]
    fn a_learnt_side_s_column_is_its_effect_s_own_columns() {
        let (blind, data, nominal, model) = simulated_backlash();
        let design = Design::new(&model, &data, Weights { position_m: 1e-4, rotation_rad: 1.0 }).unwrap();
        let bound = measurements::BoundSet::to_robot(&data, &blind.joint_kinds()).unwrap();
        let (candidates, sources) = build_candidates(&blind, &model, &bound, &design, &settings()).unwrap();
        let fold = fold_assignment(data.rows.len(), 5, 0);
        let prior = PriorOptions::default();
        let (terms, blocks) = terms_of(&candidates, design.kinematic.ncols());
        let columns: Vec<Vec<usize>> = terms.iter().map(|t| t.columns.clone()).collect();
        let pool = Pool::new(&design, &KinematicPrior::new(&nominal, &model, &prior), &blocks, &fold, 5, &prior);
        let sides = learnt_sides(&pool, &design, &model, &bound, &candidates, &columns, &sources).unwrap();
        assert!(!sides.is_empty());
        for side in &sides {
            let own = columns_of(&design, &side.model, &model, &bound).unwrap().swap_remove(0);
            let same = own.iter().zip(&side.all).all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same && own.len() == side.all.len(), "joint {}", side.joint + 1);
        }
    }
}
