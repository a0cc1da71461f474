//! Gathering a [`Report`] from a model, its robot and measurements. The after-calibration numbers
//! are `calib eval`'s own ([`model::evaluate`] and [`EvalReport`]); nothing is recomputed
//! another way.

use crate::content::{
    BeforeCalibration, DataSummary, EffectCurve, EffectView, ErrorStats, GpView, GroupedErrors, JointSummary,
    KernelScales, ModelSummary, Report, RobotSummary, RowError,
};
use crate::{Iso9283, RepeatOptions};
use cell::CompensateOptions;
use diagnose::Diagnosis;
use effects::{GearPeriodicTerm, IdentifiedEffect};
use measurements::{BoundSet, MeasurementSet};
use model::{CalibratedModel, ErrorSummary, EvalReport, Evaluation, GpModel, PoseError};
use poe::JointKind;
use robot::RobotDescription;
use serde::Serialize;

/// What the report is made of.
#[derive(Debug, Clone, Copy)]
pub struct ReportInputs<'a> {
    /// The calibrated model.
    pub model: &'a CalibratedModel,
    /// Its file, as the report names it.
    pub model_file: &'a str,
    /// The robot description the model was fitted from.
    pub robot: &'a RobotDescription,
    /// Its file.
    pub robot_file: &'a str,
    /// The test measurements.
    pub data: &'a MeasurementSet,
    /// The training measurements, if given: the effects' training angles and the diagnosis.
    pub training: Option<&'a MeasurementSet>,
}

/// How the report is made.
#[derive(Debug, Clone, Serialize)]
pub struct ReportOptions {
    /// Which rows are one pose measured again (ISO 9283 repeatability).
    pub repeat: RepeatOptions,
    /// Points on each effect curve. 600: one per pixel of its 640-pixel chart, so that a series
    /// of order 48 (a period of 7.5°) over a full turn is drawn with ~12 points per period.
    pub curve_points: usize,
    /// Degrees drawn past the outermost training or test angle on each side of an effect curve.
    /// 10°: wider than the taper of any series of order ≥ 9, so the fade to zero is seen.
    pub curve_margin_deg: f64,
    /// How the nominal model is placed on the calibrated one ("before calibration") without
    /// training data: the options `calib compensate` uses for the same placement.
    pub nominal: CompensateOptions,
    /// The `base-tool` fit that places the nominal model on the training data, where it is given.
    #[serde(skip)]
    pub base_tool: pipeline::FitOptions,
}

impl Default for ReportOptions {
    fn default() -> Self {
        Self {
            repeat: RepeatOptions::default(),
            curve_points: 600,
            curve_margin_deg: 10.0,
            nominal: CompensateOptions::default(),
            base_tool: pipeline::FitOptions::default(),
        }
    }
}

impl Report {
    /// The report of `inputs`, with `diagnosis` (of the training data) where there is one.
    pub fn build(
        inputs: &ReportInputs<'_>,
        diagnosis: Option<Diagnosis>,
        options: &ReportOptions,
    ) -> Result<Self, errors::Error> {
        let ReportInputs { model, data: given, .. } = *inputs;
        // Angles a turn away from the fitted range are taken into it, as `calib eval` does: the
        // same link positions, and the model's answer where it was fitted. The rows keep the
        // angles given for display.
        let (rows, wrapped) = model::wrapped(model, &given.rows);
        let data = &MeasurementSet { rows, ..given.clone() };
        let bound = model.bind(data)?;
        let evaluation = model::evaluate(model, &bound)?;
        let eval = EvalReport { wrapped, ..EvalReport::new(model, &bound, &evaluation) };
        let predicted: Vec<[f64; 3]> = model.predict(&bound)?.iter().map(|p| p.pose.translation().into()).collect();
        let before = before_calibration(inputs, &bound, options)?;
        let rows = data
            .rows
            .iter()
            .zip(&evaluation.errors)
            .enumerate()
            .map(|(i, (row, e))| RowError {
                line: row.line,
                position_m: row.position.into(),
                q: given.rows[i].q.clone(),
                payload_kg: row.payload_kg,
                tool: tool_name(data, row.tool),
                after_mm: e.position_mm,
                after_mrad: e.rotation_mrad,
                before_mm: before.as_ref().map(|(_, b)| b.errors[i].position_mm),
                inside_coverage: model.covers(row),
            })
            .collect();
        Ok(Self {
            robot: robot_summary(inputs.robot, inputs.robot_file),
            data: data_summary(given, inputs.robot),
            training: inputs.training.map(|t| data_summary(t, inputs.robot)),
            model: ModelSummary {
                method: model.method.to_string(),
                file: inputs.model_file.to_owned(),
                parts: model.parts().iter().map(model::Part::name).collect(),
                full_pose: model.full_pose,
                tools: model.tools.clone(),
            },
            after_groups: grouped(data, &evaluation),
            before: before.map(|(how, e)| BeforeCalibration { how, groups: grouped(data, &e) }),
            iso9283: Iso9283::new(&data.rows, &predicted, options.repeat),
            rows,
            effects: model
                .effects
                .iter()
                .map(|e| effect_view(e, inputs.robot, data, inputs.training, options))
                .collect(),
            gp: model.residual_gp.as_ref().map(|c| gp_view(c, model)),
            warnings: warnings(model, &eval),
            fit_warnings: model.fit_warnings.clone(),
            eval,
            diagnosis,
        })
    }
}

/// The nominal model evaluated on the data, its base and tools placed by the `base-tool` method on
/// the training data where it is given (what `calib fit` reports as "before" on its own rows),
/// otherwise on the calibrated model at random configurations ([`cell::registered_nominal`]),
/// which the report flags: far from the training poses the calibrated geometry is not
/// determined, so that placement can overstate the error before calibration.
fn before_calibration(
    inputs: &ReportInputs<'_>,
    bound: &BoundSet<'_>,
    options: &ReportOptions,
) -> Result<Option<(String, Evaluation)>, errors::Error> {
    let model = inputs.model;
    if let Some(train) = inputs.training {
        let (placed, _) = pipeline::fit(inputs.robot, train, model::Method::BaseTool, &options.base_tool)?;
        let how = format!(
            "the nominal kinematics of {} with its base and tools fitted on the training data (method base-tool), \
             as `calib fit` reports its \"before\"",
            inputs.robot.name
        );
        // Its tools are the training data's: the test data bound to it on their own.
        return Ok(Some((how, model::evaluate(&placed, &placed.bind(inputs.data)?)?)));
    }
    let placed = match cell::registered_nominal(model, inputs.robot, inputs.robot_file, &options.nominal) {
        Ok(placed) => placed,
        // A robot file that is not this robot: "before" is unknown, and the report says so.
        Err(_) => return Ok(None),
    };
    let nominal = CalibratedModel {
        kinematics: placed.model,
        effects: Vec::new(),
        fallback_kinematics: None,
        residual_gp: None,
        ..model.clone()
    };
    let how = format!(
        "the nominal kinematics of {} with its base and tools placed on the calibrated model by a base-and-tool \
         fit at {} random configurations ({:.3} mm RMS apart there; no --train given). Far from the training poses \
         the calibrated geometry is not determined, so this can overstate the error before calibration: give \
         --train for the placement `calib fit` uses",
        inputs.robot.name,
        options.nominal.registration_configurations,
        placed.rms_m * 1e3
    );
    // The calibrated model's tools, so the data bound to it serve.
    Ok(Some((how, model::evaluate(&nominal, bound)?)))
}

fn tool_name(data: &MeasurementSet, tool: usize) -> String {
    data.tools.get(tool).cloned().unwrap_or_default()
}

/// The statistics of `errors` (the same [`ErrorSummary`] as `calib eval`) and their 95th percentile.
pub(crate) fn stats(errors: &[PoseError]) -> ErrorStats {
    let mut positions: Vec<f64> = errors.iter().map(|e| e.position_mm).collect();
    positions.sort_by(f64::total_cmp);
    let rank = (0.95 * positions.len() as f64).ceil() as usize;
    ErrorStats {
        summary: ErrorSummary::from_errors(errors),
        p95_position_error_mm: positions.get(rank.saturating_sub(1)).copied().unwrap_or(0.0),
    }
}

fn grouped(data: &MeasurementSet, evaluation: &Evaluation) -> GroupedErrors {
    let pick = |keep: &dyn Fn(&measurements::Measurement) -> bool| -> ErrorStats {
        let part: Vec<PoseError> =
            data.rows.iter().zip(&evaluation.errors).filter(|(r, _)| keep(r)).map(|(_, e)| *e).collect();
        stats(&part)
    };
    GroupedErrors {
        all: ErrorStats { summary: evaluation.summary, ..stats(&evaluation.errors) },
        per_payload: payloads(data).into_iter().map(|(kg, _)| (kg, pick(&|r| r.payload_kg == kg))).collect(),
        per_tool: tools(data)
            .into_iter()
            .map(|(name, _)| {
                let stats = pick(&|r| tool_name(data, r.tool) == name);
                (name, stats)
            })
            .collect(),
    }
}

fn payloads(data: &MeasurementSet) -> Vec<(f64, usize)> {
    let mut values: Vec<f64> = data.rows.iter().map(|r| r.payload_kg).collect();
    values.sort_by(f64::total_cmp);
    let mut out: Vec<(f64, usize)> = Vec::new();
    for v in values {
        match out.last_mut() {
            Some((last, count)) if *last == v => *count += 1,
            _ => out.push((v, 1)),
        }
    }
    out
}

fn tools(data: &MeasurementSet) -> Vec<(String, usize)> {
    let mut counts = vec![0usize; data.tools.len().max(1)];
    for row in &data.rows {
        if let Some(c) = counts.get_mut(row.tool) {
            *c += 1;
        }
    }
    counts.into_iter().enumerate().filter(|(_, c)| *c > 0).map(|(t, c)| (tool_name(data, t), c)).collect()
}

fn is_prismatic(robot: &RobotDescription, joint: usize) -> bool {
    robot.joints.get(joint).is_some_and(|j| j.kind == JointKind::Prismatic)
}

/// A joint value in the unit reports use: degrees, or mm for a prismatic joint.
fn shown(robot: &RobotDescription, joint: usize, value: f64) -> f64 {
    if is_prismatic(robot, joint) { value * 1e3 } else { value.to_degrees() }
}

fn robot_summary(robot: &RobotDescription, file: &str) -> RobotSummary {
    RobotSummary {
        name: robot.name.clone(),
        file: file.to_owned(),
        joints: robot
            .joints
            .iter()
            .map(|j| match j.kind {
                JointKind::Prismatic => {
                    JointSummary { kind: "prismatic", limits: j.limits_m.map(|(a, b)| [a * 1e3, b * 1e3]), unit: "mm" }
                }
                _ => JointSummary { kind: "revolute", limits: j.limits_deg.map(|(a, b)| [a, b]), unit: "deg" },
            })
            .collect(),
    }
}

fn data_summary(data: &MeasurementSet, robot: &RobotDescription) -> DataSummary {
    let joint_ranges = (0..data.joint_count)
        .map(|j| {
            let values = data.rows.iter().filter_map(|r| r.q.get(j)).map(|&q| shown(robot, j, q));
            values.fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], v| [a.min(v), b.max(v)])
        })
        .collect();
    DataSummary {
        source: data.source.clone(),
        rows: data.rows.len(),
        full_pose: data.full_pose,
        payloads: payloads(data),
        tools: tools(data),
        joint_ranges,
    }
}

fn effect_view(
    effect: &IdentifiedEffect,
    robot: &RobotDescription,
    data: &MeasurementSet,
    training: Option<&MeasurementSet>,
    options: &ReportOptions,
) -> EffectView {
    let curve = match effect {
        IdentifiedEffect::GearPeriodic(gear) => Some(gear_curve(gear, data, training, options)),
        _ => None,
    };
    EffectView {
        label: effects::reported_label(effect, &robot.joint_kinds()),
        parameters: effects::reported_parameters(effect, &robot.joint_kinds()),
        curve,
    }
}

fn gear_curve(
    gear: &GearPeriodicTerm,
    data: &MeasurementSet,
    training: Option<&MeasurementSet>,
    options: &ReportOptions,
) -> EffectCurve {
    let angles = |set: &MeasurementSet| -> Vec<f64> {
        set.rows.iter().filter_map(|r| r.q.get(gear.joint)).map(|q| q.to_degrees()).collect()
    };
    let test_deg = angles(data);
    let training_deg = training.map(angles).unwrap_or_default();
    let fitted = gear.fitted_range.map(|[a, b]| [a.to_degrees(), b.to_degrees()]);
    let all = test_deg.iter().chain(&training_deg).chain(fitted.iter().flatten());
    let (low, high) = all.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| (a.min(v), b.max(v)));
    let (low, high) = if low.is_finite() { (low, high) } else { (-180.0, 180.0) };
    let (low, high) = (low - options.curve_margin_deg, high + options.curve_margin_deg);
    let n = options.curve_points.max(2);
    let angle_deg: Vec<f64> = (0..n).map(|k| low + (high - low) * k as f64 / (n - 1) as f64).collect();
    let error_urad = angle_deg.iter().map(|d| gear.joint_error(d.to_radians()) * 1e6).collect();
    let sigma_urad = angle_deg.iter().map(|d| gear.faded_sigma(d.to_radians()) * 1e6).collect();
    let mut fitted_deg: Vec<[f64; 2]> = Vec::new();
    for &d in &angle_deg {
        if gear.covers(d.to_radians()) {
            match fitted_deg.last_mut() {
                Some(arc) if arc[1] >= d - (high - low) / (n - 1) as f64 * 1.5 => arc[1] = d,
                _ => fitted_deg.push([d, d]),
            }
        }
    }
    EffectCurve { joint: gear.joint + 1, angle_deg, error_urad, sigma_urad, training_deg, test_deg, fitted_deg }
}

/// The GP's kind, its input scales and its kernels with the outputs each serves.
type GpParts<'a> = (&'static str, &'a [f64], Vec<(&'a [usize], &'a gp::Kernel)>);

fn gp_view(residual_gp: &model::ResidualGp, model: &CalibratedModel) -> GpView {
    let gp = &residual_gp.gp;
    let mut inputs: Vec<String> = (1..=model.joint_count()).map(|j| format!("q{j}")).collect();
    if residual_gp.with_payload {
        inputs.push("payload".into());
    }
    inputs.extend(residual_gp.inputs.iter().cloned());
    let signals = residual_gp
        .inputs
        .iter()
        .map(|name| {
            let span = model.training_range.as_ref().and_then(|r| r.input(name));
            span.cloned().unwrap_or(model::InputSpan {
                name: name.clone(),
                unit: measurements::input_unit(name),
                fitted: [f64::NAN; 2],
            })
        })
        .collect();
    let (kind, scale, components): GpParts<'_> = match gp {
        GpModel::Exact(g) => (
            "exact",
            &g.input_standardiser().scale,
            g.report().components.iter().map(|c| (c.outputs.as_slice(), &c.kernel)).collect(),
        ),
        GpModel::Sparse(g) => (
            "sparse",
            &g.input_standardiser().scale,
            g.report().components.iter().map(|c| (c.outputs.as_slice(), &c.kernel)).collect(),
        ),
    };
    let dim = inputs.len();
    let kernels = components
        .into_iter()
        .map(|(outputs, kernel)| {
            let (family, length_scales, isotropic) = match kernel {
                gp::Kernel::Quadratic(k) => ("Eq. 5 (isotropic)", vec![1.0 / k.theta1.sqrt(); dim], true),
                gp::Kernel::SquaredExponentialArd(k) => ("squared exponential, ARD", k.length_scales.clone(), false),
                gp::Kernel::Matern52Ard(k) => ("Matérn 5/2, ARD", k.length_scales.clone(), false),
                gp::Kernel::Composite(k) => ("composite (Eq. 5, ARD), stationary term", k.length_scales.clone(), false),
            };
            KernelScales { outputs: outputs.to_vec(), family: family.to_owned(), length_scales, isotropic }
        })
        .collect();
    GpView { kind: kind.to_owned(), inputs, input_scale: scale.to_vec(), kernels, signals }
}

fn warnings(model: &CalibratedModel, eval: &EvalReport) -> Vec<String> {
    // Another tracker placement first: it explains the numbers of every other section.
    let mut out: Vec<String> = eval.other_placement.iter().map(ToString::to_string).collect();
    out.extend(eval.warnings.iter().map(ToString::to_string));
    out.extend(eval.out_of_range.iter().map(ToString::to_string));
    out.extend(eval.beyond_joint_limits.iter().map(ToString::to_string));
    if eval.orientations_not_evaluated {
        out.push(model::ORIENTATIONS_NOT_EVALUATED.to_owned());
    }
    // A model that keeps the fit's warnings says this itself, among them.
    if let Some(residual_gp) = model.residual_gp.as_ref().filter(|_| model.fit_warnings.is_none()) {
        let converged = |o: &Option<gp::OptimisationReport>| o.as_ref().is_none_or(|o| o.converged);
        let unconverged: Vec<&[usize]> = match &residual_gp.gp {
            GpModel::Exact(g) => {
                g.report().components.iter().filter(|c| !converged(&c.optimisation)).map(|c| &c.outputs[..]).collect()
            }
            GpModel::Sparse(g) => g
                .report()
                .components
                .iter()
                .filter(|c| c.subset_fit.as_ref().is_some_and(|s| !converged(&s.optimisation)))
                .map(|c| &c.outputs[..])
                .collect(),
        };
        if !unconverged.is_empty() {
            out.push(format!(
                "the GP's hyperparameter search for output(s) {:?} stopped without meeting its tolerance (as the \
                 fit warned): the compensation may be less accurate than it could be",
                unconverged.concat()
            ));
        }
    }
    out
}
