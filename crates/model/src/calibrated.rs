//! A calibrated model: the identified kinematics, the effects identified with them, the optional
//! residual GP, and prediction by walking them in order (module `model_parts`).

use crate::Method;
use crate::model_parts::{Part, Walk};
use effects::IdentifiedEffect;
use errors::Error;
use lie::SE3;
use measurements::{BoundSet, Measurement, MeasurementSet};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};
use std::borrow::Cow;

/// What `calib fit` produces and `calib eval` / `calib predict` use.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct CalibratedModel {
    /// Version of this file layout ([`crate::SCHEMA_VERSION`]).
    pub schema_version: u32,
    /// Name of the robot description the fit started from.
    pub robot: String,
    /// The method that produced the model.
    pub method: Method,
    /// Whether the model was fitted on full-pose data (otherwise orientation is not calibrated).
    pub full_pose: bool,
    /// Tool identifiers, in the order of the kinematic model's tools.
    pub tools: Vec<String>,
    /// The identified local POE model; its reference frame is the tracker frame.
    pub kinematics: LocalPoe,
    /// Non-geometric effects identified with the geometry (`calib fit --effects`), applied after
    /// it and before the GP, in one left exponential of the sum of their twists.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub effects: Vec<IdentifiedEffect>,
    /// The geometry fitted alone, before the effects were identified with it: outside the joint
    /// angles an effect was fitted on, the model blends to it ([`Part::Fallback`]), so that where
    /// the effects know nothing the model is no worse than the geometric fit. Absent in files
    /// written before it was kept (the fitted geometry is then used everywhere).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback_kinematics: Option<LocalPoe>,
    /// The effects' posterior uncertainty: a σ for their correction at every row, and where the
    /// model falls back to [`CalibratedModel::fallback_kinematics`] because that σ is far above
    /// the training rows'. Files written before it was kept have none (no σ, no fallback by it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effect_uncertainty: Option<crate::EffectUncertainty>,
    /// The posterior uncertainty of the kinematics: for rows that put a joint outside
    /// the range the model was fitted on, the error the geometry's own uncertainty predicts
    /// there. Kept by fits under the prior toward the nominal geometry; files written before it
    /// was kept have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub geometry_uncertainty: Option<crate::GeometryUncertainty>,
    /// The GP on the residual, step 2 (methods `poe-gp`, `poe-gp-load`); `compensation` in the file.
    #[serde(default, skip_serializing_if = "Option::is_none", rename = "compensation")]
    pub residual_gp: Option<crate::ResidualGp>,
    /// The range of every input the model was fitted on: the check on reading probes the model
    /// inside it. Files written before it existed have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub training_range: Option<crate::TrainingRange>,
    /// The robot description's joint limits, SI (`None` for a joint without): `eval`, `predict`
    /// and `compensate` count rows beyond them. Files written before they were kept have none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub joint_limits: Vec<Option<[f64; 2]>>,
    /// The fit's estimate of its own held-out error ([`crate::HeldoutEstimate`]): what `calib
    /// register` judges a registration's residual against. Files written before it was kept, and
    /// fits that cannot estimate it (the sparse GP), have none.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub heldout: Option<crate::HeldoutEstimate>,
    /// The fit's own warnings, as `calib fit` printed them (few rows per parameter, gross
    /// outliers, a fit forced past the plausibility check, a GP search stopped early), so that a
    /// report written later shows them: empty when it gave none. `None` in files written before
    /// they were kept.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit_warnings: Option<Vec<String>>,
    /// The robot description the fit started from (its nominal geometry, limits and masses), so
    /// that the model alone can say what the robot did before calibration. Last in the file, so
    /// the checks' field positions above are not moved by its fields. Files written before it was
    /// kept have none (a command that needs it then asks for `--robot`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub robot_description: Option<robot::RobotDescription>,
}

/// A predicted tool pose and, where a GP is part of the model, its standard deviation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PredictedPose {
    /// `tracker_from_tool`.
    pub pose: SE3,
    /// GP standard deviation of the six pose-error components `(v, ω)` (metres, radians).
    pub std: Option<[f64; 6]>,
}

impl CalibratedModel {
    /// Number of joints of the robot.
    pub fn joint_count(&self) -> usize {
        self.kinematics.joint_count()
    }

    /// The kinds of the joints, base first.
    pub fn joint_kinds(&self) -> Vec<poe::JointKind> {
        self.kinematics.joints().iter().map(|j| j.kind).collect()
    }

    /// Index of a tool by its identifier. `""` is the default tool (a blank `tool` cell, or a
    /// file without the column), matched like any other name, as in the fit (SPEC v2); an
    /// identifier the model was not fitted with is refused.
    pub fn tool_index(&self, name: &str, file: &str, line: u64, column: usize) -> Result<usize, Error> {
        measurements::model_tool(&self.tools, name, file, line, column)
    }

    /// `data` bound to this model ([`BoundSet::to_model`]): its joint columns checked against the
    /// model's joints, each row's tool matched by identifier, an unknown one refused at its line.
    /// Every function that applies the model to rows takes the result, so a command binds once.
    pub fn bind<'a>(&self, data: impl Into<Cow<'a, MeasurementSet>>) -> Result<BoundSet<'a>, Error> {
        BoundSet::to_model(data, &self.joint_kinds(), &self.tools)
    }

    /// The measured signals the model takes as inputs (`calib fit --inputs`), by column name, in
    /// the order a file read for it keeps them: the GP's. A file without one of them is refused
    /// by its name ([`CalibratedModel::read_options`]).
    pub fn input_names(&self) -> Vec<String> {
        self.residual_gp.as_ref().map(|gp| gp.inputs.clone()).unwrap_or_default()
    }

    /// How a measurement file is read for this model: its joints, `columns` (`--columns`), and
    /// the columns of its inputs ([`CalibratedModel::input_names`]), required by name.
    pub fn read_options(&self, columns: measurements::ColumnMap) -> measurements::ReadOptions {
        measurements::ReadOptions::for_joints(self.joint_kinds()).with_columns(columns).with_inputs(self.input_names())
    }

    /// The posterior uncertainty and the effects it is of, where the model keeps it.
    pub(crate) fn uncertainty(&self) -> Option<(&crate::EffectUncertainty, &[IdentifiedEffect])> {
        self.effect_uncertainty.as_ref().map(|u| (u, self.effects.as_slice()))
    }

    /// The parts of the model in the order they apply: the geometry, each effect, the GP.
    pub fn parts(&self) -> Vec<Part<'_>> {
        let mut parts = vec![Part::Geometry(&self.kinematics)];
        parts.extend(self.effects.iter().map(Part::Effect));
        if !self.effects.is_empty() {
            parts.extend(self.fallback_kinematics.iter().map(Part::Fallback));
        }
        parts.extend(self.residual_gp.iter().map(Part::GaussianProcess));
        parts
    }

    /// The model without part `index` of [`CalibratedModel::parts`] (the geometry, index 0, stays:
    /// everything else applies to it).
    pub fn without_part(&self, index: usize) -> CalibratedModel {
        let mut model = self.clone();
        let effects = self.effects.len();
        let fallback = usize::from(self.fallback_kinematics.is_some() && effects > 0);
        if (1..=effects).contains(&index) {
            model.effects.remove(index - 1);
            // The uncertainty was of every effect together.
            model.effect_uncertainty = None;
        } else if fallback == 1 && index == effects + 1 {
            model.fallback_kinematics = None;
        } else if index == effects + fallback + 1 {
            model.residual_gp = None;
        }
        // The estimate was of the whole model.
        model.heldout = None;
        model
    }

    /// The model without its non-geometric parts (effects, the GP): the geometry alone, which is
    /// what a URDF can hold (`calib export`).
    pub fn geometry_only(&self) -> CalibratedModel {
        CalibratedModel {
            effects: Vec::new(),
            fallback_kinematics: None,
            effect_uncertainty: None,
            residual_gp: None,
            heldout: None,
            ..self.clone()
        }
    }

    /// The names of the parts a URDF cannot hold, in the order they apply.
    pub fn non_geometric_parts(&self) -> Vec<String> {
        self.parts().iter().filter(|p| !p.in_urdf()).map(Part::name).collect()
    }

    /// The poses of the geometry and the effects, before any GP.
    pub fn geometric_poses(&self, data: &BoundSet<'_>) -> Result<Vec<SE3>, Error> {
        let mut walk = Walk::new(data, self.uncertainty());
        for part in self.parts().iter().filter(|p| !matches!(p, Part::GaussianProcess(_))) {
            part.apply(&mut walk)?;
        }
        walk.flush();
        Ok(walk.poses)
    }

    /// Predicts the tool pose of rows of a measurement set by applying every part in turn; the
    /// GP is placed before the POE model as in the paper's Eq. 9: `T = exp(ĝ(q, m)) · T_POE(q)`.
    pub fn predict(&self, data: &BoundSet<'_>) -> Result<Vec<PredictedPose>, Error> {
        let mut walk = Walk::new(data, self.uncertainty());
        for part in self.parts() {
            part.apply(&mut walk)?;
        }
        walk.flush();
        Ok(match walk.standard_deviations() {
            Some(std) => {
                walk.poses.into_iter().zip(std).map(|(pose, s)| PredictedPose { pose, std: Some(s) }).collect()
            }
            None => walk.poses.into_iter().map(|pose| PredictedPose { pose, std: None }).collect(),
        })
    }
}

/// Rows at which the model's own σ (of the geometry and effects together) is so far above what the
/// training rows had that the model falls back to the geometry fitted alone: the rows excite a
/// combination of the effects' parameters that no training row did.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SigmaFallback {
    /// How many rows fall back, in part or fully.
    pub rows: usize,
    /// How many of them fully (the geometry alone).
    pub fully: usize,
    /// How many rows there are.
    pub of_rows: usize,
    /// The file line of the first.
    pub first_line: u64,
    /// The σ of the tool point's position above which the model falls back, mm.
    pub limit_mm: f64,
    /// The largest σ over the training rows, mm.
    pub training_max_mm: f64,
    /// The largest σ among these rows, mm.
    pub largest_sigma_mm: f64,
}

impl SigmaFallback {
    /// The rows whose weight (of [`CalibratedModel::sigma_weights`]) is below 1; `None` if none.
    pub fn of(rows: &[Measurement], weights: &[(f64, f64)], uncertainty: &crate::EffectUncertainty) -> Option<Self> {
        let mut fallen: Option<SigmaFallback> = None;
        for (row, &(weight, sigma)) in rows.iter().zip(weights) {
            if weight < 1.0 {
                let entry = fallen.get_or_insert(SigmaFallback {
                    rows: 0,
                    fully: 0,
                    of_rows: rows.len(),
                    first_line: row.line,
                    limit_mm: uncertainty.fallback_sigma_m * 1e3,
                    training_max_mm: uncertainty.training_sigma_m[1] * 1e3,
                    largest_sigma_mm: 0.0,
                });
                entry.rows += 1;
                entry.fully += usize::from(weight == 0.0);
                entry.largest_sigma_mm = entry.largest_sigma_mm.max(sigma * 1e3);
            }
        }
        fallen
    }
}

impl std::fmt::Display for SigmaFallback {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} rows (the first at line {}) excite combinations of the effects' parameters that no training \
             row did: the model's σ there reaches {:.3} mm, above the {:.3} mm it falls back from ({:.3} mm at \
             most on the training rows), so there it uses the geometry fitted alone ({} fully, {} blended)",
            self.rows,
            self.of_rows,
            self.first_line,
            self.largest_sigma_mm,
            self.limit_mm,
            self.training_max_mm,
            self.fully,
            self.rows - self.fully
        )
    }
}

/// Rows at which the GP's posterior keeps so much of its prior variance that its correction fades
/// toward the geometry ([`crate::ResidualGpOptions::fade_above_variance_ratio`]): the training rows
/// say little of them, and the GP's mean there would be its prior's extrapolation.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpFade {
    /// How many rows fade, in part or fully.
    pub rows: usize,
    /// How many of them fully (no GP correction).
    pub fully: usize,
    /// How many rows there are.
    pub of_rows: usize,
    /// The file line of the first.
    pub first_line: u64,
    /// The share of the prior variance (beyond the training rows', as a fraction of what they
    /// leave unexplained) above which the correction fades.
    pub fade_above: f64,
    /// The largest share the posterior keeps among these rows.
    pub largest_share: f64,
}

impl GpFade {
    /// The rows whose weight (of [`crate::ResidualGp::weights`]) is below 1; `None` if none.
    pub fn of(rows: &[Measurement], weights: &[(f64, f64)], fade_above: f64) -> Option<Self> {
        let mut faded: Option<GpFade> = None;
        for (row, &(weight, share)) in rows.iter().zip(weights) {
            if weight < 1.0 {
                let entry = faded.get_or_insert(GpFade {
                    rows: 0,
                    fully: 0,
                    of_rows: rows.len(),
                    first_line: row.line,
                    fade_above,
                    largest_share: 0.0,
                });
                entry.rows += 1;
                entry.fully += usize::from(weight == 0.0);
                entry.largest_share = entry.largest_share.max(share);
            }
        }
        faded
    }
}

impl std::fmt::Display for GpFade {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} of {} rows (the first at line {}) lie where the GP's training rows say little: its posterior keeps \
             up to {:.0} % of its prior variance there, above the {:.0} % from which its correction fades, so there \
             the model falls back toward the geometry ({} fully, {} blended; the σ counts what it no longer corrects)",
            self.rows,
            self.of_rows,
            self.first_line,
            self.largest_share * 100.0,
            self.fade_above * 100.0,
            self.fully,
            self.rows - self.fully
        )
    }
}

/// Rows at which an effect of the model is used outside the joint angles it was fitted on: there
/// the model extrapolates, and its error on them is not what the fit measured.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExtrapolationWarning {
    /// The effect, as reports name it (`gear_periodic:1:48`).
    pub effect: String,
    /// The 1-based joint.
    pub joint: usize,
    /// The joint's smallest and largest angle on the training poses, rad.
    pub fitted_range_rad: [f64; 2],
    /// The gaps inside that range where no training pose was (wider than half the series'
    /// shortest period), rad.
    pub gaps_rad: Vec<[f64; 2]>,
    /// How many of the rows put the joint outside that range or in a gap.
    pub rows_outside: usize,
    /// How many rows there are.
    pub rows: usize,
    /// The file line of the first of them.
    pub first_line: u64,
}

impl std::fmt::Display for ExtrapolationWarning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [low, high] = self.fitted_range_rad;
        write!(
            f,
            "{} of {} rows (the first at line {}) put joint {} outside the angles its {} effect was fitted on \
             ({:.4} … {:.4} rad{}): there the model extrapolates, and may be worse than without the effect",
            self.rows_outside,
            self.rows,
            self.first_line,
            self.joint,
            self.effect,
            low,
            high,
            match self.gaps_rad.len() {
                0 => String::new(),
                1 => ", less one gap".to_owned(),
                k => format!(", less {k} gaps"),
            }
        )
    }
}

impl CalibratedModel {
    /// Whether predictions carry a standard deviation: a GP, or an effect that reports what it
    /// leaves uncorrected where it fades out.
    pub fn predicts_std(&self) -> bool {
        self.residual_gp.is_some()
            || self.effect_uncertainty.is_some()
            || self.effects.iter().any(IdentifiedEffect::has_sigma)
    }

    /// One warning per input (joint, payload, temperature, time) that some of `rows` put outside
    /// the range the model was fitted on; none for model files that do not record it.
    pub fn outside_training_range(&self, rows: &[Measurement]) -> Vec<crate::OutOfRangeWarning> {
        let prismatic: Vec<bool> = self.joint_kinds().iter().map(|k| *k == poe::JointKind::Prismatic).collect();
        self.training_range.as_ref().map_or_else(Vec::new, |range| range.outside(rows, &prismatic))
    }

    /// What the geometry's own uncertainty predicts on the rows of `data` that put a joint
    /// outside the range the model was fitted on ([`crate::GeometrySigma`]); `None` where no row
    /// does, or the model keeps no range or no geometry uncertainty.
    pub fn geometry_sigma(&self, data: &BoundSet<'_>) -> Result<Option<crate::GeometrySigma>, Error> {
        let (Some(uncertainty), Some(range)) = (&self.geometry_uncertainty, &self.training_range) else {
            return Ok(None);
        };
        crate::GeometrySigma::of(uncertainty, &self.kinematics, data, |row| !range.contains_joints(row))
    }

    /// One warning per joint that some of `rows` put beyond the robot's limits; none for model
    /// files that do not keep them.
    pub fn beyond_joint_limits(&self, rows: &[Measurement]) -> Vec<crate::BeyondLimitsWarning> {
        let prismatic: Vec<bool> = self.joint_kinds().iter().map(|k| *k == poe::JointKind::Prismatic).collect();
        crate::beyond_limits(&self.joint_limits, &prismatic, rows)
    }

    /// How fully the effects apply at each row of `data` by the model's σ there
    /// ([`crate::EffectUncertainty::weight`]) and that σ of the tool point's position (m); `None`
    /// for a model that keeps no uncertainty.
    pub fn sigma_weights(&self, data: &BoundSet<'_>) -> Result<Option<Vec<(f64, f64)>>, Error> {
        let Some(uncertainty) = &self.effect_uncertainty else { return Ok(None) };
        let mut weights = Vec::with_capacity(data.len());
        for (row, tool) in data.iter() {
            let sigma = uncertainty.sigma(&self.kinematics, &self.effects, row, tool)?;
            let position = crate::EffectUncertainty::position(&sigma);
            weights.push((uncertainty.weight(position), position));
        }
        Ok(Some(weights))
    }

    /// The rows of `data` at which the model's σ is above its fallback limit,
    /// where it falls back to the geometry fitted alone ([`crate::EffectUncertainty`]); `None`
    /// when there are none or the model keeps no uncertainty.
    pub fn sigma_fallback(&self, data: &BoundSet<'_>) -> Result<Option<SigmaFallback>, Error> {
        let (Some(uncertainty), Some(weights)) = (&self.effect_uncertainty, self.sigma_weights(data)?) else {
            return Ok(None);
        };
        Ok(SigmaFallback::of(data.rows(), &weights, uncertainty))
    }

    /// The rows of `rows` at which the GP's correction fades ([`GpFade`]); `None` when there are
    /// none or the model has no GP that fades.
    pub fn gp_fade(&self, rows: &[Measurement]) -> Result<Option<GpFade>, Error> {
        let Some(gp) = &self.residual_gp else { return Ok(None) };
        let Some(fade) = gp.fade else { return Ok(None) };
        Ok(GpFade::of(rows, &gp.weights(rows)?, fade.above))
    }

    /// Whether any effect records the joint angles it was fitted on.
    pub fn records_coverage(&self) -> bool {
        self.effects.iter().any(|e| e.angle_coverage().is_some())
    }

    /// Whether `row` lies within the angles every effect was fitted on.
    pub fn covers(&self, row: &Measurement) -> bool {
        self.effects
            .iter()
            .filter_map(IdentifiedEffect::angle_coverage)
            .all(|gear| row.q.get(gear.joint).is_none_or(|&q| gear.covers(q)))
    }

    /// One warning per effect that `rows` use outside the joint angles it was fitted on.
    pub fn extrapolation(&self, rows: &[Measurement]) -> Vec<ExtrapolationWarning> {
        self.effects
            .iter()
            .filter_map(|effect| {
                let gear = effect.angle_coverage()?;
                let (joint, [low, high]) = (gear.joint, gear.fitted_range?);
                let outside: Vec<&Measurement> =
                    rows.iter().filter(|r| r.q.get(joint).is_some_and(|&q| !gear.covers(q))).collect();
                let first = outside.first()?;
                Some(ExtrapolationWarning {
                    effect: effect.label(),
                    joint: joint + 1,
                    fitted_range_rad: [low, high],
                    gaps_rad: if gear.taper_rad.is_some() { gear.turn_gaps.clone() } else { gear.fitted_gaps.clone() },
                    rows_outside: outside.len(),
                    rows: rows.len(),
                    first_line: first.line,
                })
            })
            .collect()
    }
}
