//! `calib register`: a calibrated model carried to a moved tracker and/or new or remounted tools
//! from a few measured poses, everything else (geometry, effects, GP) held.
//!
//! The model predicts each pose in the frame it was fitted in, `P_i` (every part applied); the
//! measurements are `X · P_i · D_t` ([`crate::registration`]). `X` is then put into the model
//! exactly: the first local transform of the geometry (and of the fallback geometry) is moved by
//! it, which carries the joints' spatial twists and so the effects along, and the GP's outputs
//! are carried by [`model::ResidualGp::moved_by`]. A tool becomes `T_{n,n+1} · D_t` of the
//! model tool it was measured against (a new tool: the model's first tool).

use crate::ErrorKind;
use crate::register_options::{Refit, RegisterOptions};
use crate::registration::{Registration, RegistrationRow, Unknowns, register_rows};
use crate::report::{Fitted, Heldout, HeldoutFrom, RegisterReport, RegisterWarning, RegisteredTool, Verdict};
use errors::Error;
use lie::{SE3, Vector3};
use measurements::{BoundSet, Measurement, MeasurementSet};
use model::CalibratedModel;

/// The registered model and what the registration found.
#[derive(Debug, Clone)]
pub struct Registered {
    /// The model in the new tracker frame with the new tools.
    pub model: CalibratedModel,
    /// The report (`calib register --json`).
    pub report: RegisterReport,
}

/// Registers `model` to `data`. `heldout_mm` is the model's own held-out mean position error
/// (e.g. `calib eval` on rows it was not fitted on), against which the residual is judged; without
/// it the fit's own estimate in the model file ([`model::HeldoutEstimate`]) is used, and without
/// that the verdict is [`Verdict::Unknown`]. Revolute angles a turn away from the fitted range are
/// wrapped into it where the joint's limits allow ([`model::WrappedJoint`]).
pub fn register(
    model: &CalibratedModel,
    data: &MeasurementSet,
    refit: Refit,
    heldout_mm: Option<f64>,
    options: &RegisterOptions,
) -> Result<Registered, Error> {
    options.validate()?;
    data.check_joints(&model.joint_kinds())?;
    let use_rotation = data.full_pose && model.full_pose;
    let known = model_tools(model, data, refit)?;
    let slots = tool_slots(data, refit);
    let tool_count = slots.iter().flatten().count();
    let unknowns = Unknowns { frame: refit.base, tools: tool_count, tool_rotations: use_rotation };
    check_counts(data, &slots, unknowns, use_rotation, options)?;

    // Angles one turn away from the training poses are taken back into the fitted range.
    let (rows, wrapped) = model::wrapped(model, &data.rows);
    let data = &MeasurementSet { rows, ..data.clone() };
    let rows = registration_rows(model, data, &known, &slots, use_rotation)?;
    let fit = register_rows(&rows, unknowns, &options.registration)?;
    let (registered, tools) = carried(model, data, &known, &slots, &fit);
    let warnings = warnings(model, data, refit, use_rotation, &tools, options);
    let heldout = match heldout_mm {
        Some(given) => Some(Heldout { mm: given, from: HeldoutFrom::Given }),
        None => model.heldout.map(|h| Heldout { mm: h.mean_position_error_mm, from: HeldoutFrom::ModelFile(h.source) }),
    };
    let report = RegisterReport::new(
        &registered,
        data,
        Fitted { refit, parameters: unknowns.count(), fit: &fit, tools },
        heldout,
        options,
        wrapped,
        warnings,
    )?;
    Ok(Registered { model: registered, report })
}

/// The model's tool of every data tool (`None` for a new one); a new tool is refused, at its
/// first row, unless tools are re-fitted.
fn model_tools(model: &CalibratedModel, data: &MeasurementSet, refit: Refit) -> Result<Vec<Option<usize>>, Error> {
    let column = data.tool_column.unwrap_or(1);
    let mut known = Vec::with_capacity(data.tools.len());
    for (index, name) in data.tools.iter().enumerate() {
        let found = model.tools.iter().position(|t| t == name);
        if found.is_none() && !refit.tools {
            let line = data.rows.iter().find(|r| r.tool == index).map_or(0, |r| r.line);
            return Err(Error::at_line(
                data.source.clone(),
                line,
                column,
                ErrorKind::NewToolWithoutRefit { tool: name.clone() },
            ));
        }
        known.push(found);
    }
    Ok(known)
}

/// Each data tool's slot among the re-fitted tools: the data tools that appear, in order, when
/// tools are re-fitted; none otherwise.
fn tool_slots(data: &MeasurementSet, refit: Refit) -> Vec<Option<usize>> {
    let used: Vec<bool> = (0..data.tools.len()).map(|t| data.rows.iter().any(|r| r.tool == t)).collect();
    if refit.tools {
        let mut next = 0;
        used.iter()
            .map(|&u| {
                u.then(|| {
                    next += 1;
                    next - 1
                })
            })
            .collect()
    } else {
        vec![None; data.tools.len()]
    }
}

/// Each row's measured pose beside the model's prediction, with its tool's slot.
fn registration_rows(
    model: &CalibratedModel,
    data: &MeasurementSet,
    known: &[Option<usize>],
    slots: &[Option<usize>],
    use_rotation: bool,
) -> Result<Vec<RegistrationRow>, Error> {
    // Each row on its model tool, a new tool measured against the model's first (`known`): the
    // binding of this path, made here since new tools are allowed.
    let on_model_tools = data.rows.iter().map(|r| Measurement { tool: known[r.tool].unwrap_or(0), ..r.clone() });
    let predicted = model.predict(&BoundSet::made_for_model(&data.source, on_model_tools.collect()))?;
    Ok(data
        .rows
        .iter()
        .zip(&predicted)
        .map(|(row, p)| RegistrationRow {
            predicted: p.pose,
            point: row.position,
            rotation: if use_rotation { row.orientation } else { None },
            slot: slots[row.tool],
        })
        .collect())
}

/// What the registration cannot carry or could not see, in the report's order.
fn warnings(
    model: &CalibratedModel,
    data: &MeasurementSet,
    refit: Refit,
    use_rotation: bool,
    tools: &[RegisteredTool],
    options: &RegisterOptions,
) -> Vec<RegisterWarning> {
    let mut warnings = Vec::new();
    if refit.base && model.effects.iter().any(|e| e.kind() == "time_drift") {
        warnings.push(RegisterWarning::DriftInOldFrame);
    }
    if model.full_pose && !use_rotation && tools.iter().any(|t| t.new) {
        warnings.push(RegisterWarning::NewToolOrientationUnknown);
    }
    if !model.full_pose && tools.iter().any(|t| t.new || t.point_change_mm > options.moved_point_mm) {
        warnings.push(RegisterWarning::PositionModelToolPoint);
    }
    if data.full_pose && !model.full_pose {
        warnings.push(RegisterWarning::OrientationsIgnored);
    }
    warnings
}

/// Refuses too few poses for what is re-fitted, with the counts.
fn check_counts(
    data: &MeasurementSet,
    slots: &[Option<usize>],
    unknowns: Unknowns,
    use_rotation: bool,
    options: &RegisterOptions,
) -> Result<(), Error> {
    let per_pose = if use_rotation { 6 } else { 3 };
    let poses = data.rows.len();
    let parameters = unknowns.count();
    let needed_rows = (options.min_redundancy * parameters as f64).ceil() as usize;
    // A frame needs three points off one line whatever the redundancy.
    let needed = needed_rows.div_ceil(per_pose).max(if unknowns.frame { 3 } else { 1 });
    if poses < needed {
        return Err(Error::new(ErrorKind::TooFewPoses {
            what: "the registration".into(),
            poses,
            needed_poses: needed,
            rows: poses * per_pose,
            parameters,
        }));
    }
    for (tool, slot) in slots.iter().enumerate() {
        if slot.is_none() {
            continue;
        }
        let mine = data.rows.iter().filter(|r| r.tool == tool).count();
        if mine < options.min_poses_per_tool {
            return Err(Error::new(ErrorKind::TooFewPoses {
                what: format!("tool '{}'", data.tools[tool]),
                poses: mine,
                needed_poses: options.min_poses_per_tool,
                rows: mine * per_pose,
                parameters: unknowns.per_tool(),
            }));
        }
    }
    Ok(())
}

/// The model with the fitted frame and tools put in.
fn carried(
    model: &CalibratedModel,
    data: &MeasurementSet,
    known: &[Option<usize>],
    slots: &[Option<usize>],
    fit: &Registration,
) -> (CalibratedModel, Vec<RegisteredTool>) {
    let mut out = model.clone();
    out.kinematics.change_reference(fit.frame);
    if let Some(fallback) = out.fallback_kinematics.as_mut() {
        fallback.change_reference(fit.frame);
    }
    if let Some(residual_gp) = out.residual_gp.as_mut() {
        residual_gp.moved_by = Some(fit.frame * residual_gp.moved_by.unwrap_or_else(SE3::identity));
    }
    // Every row was predicted with the model's tools as they were.
    let original = model.kinematics.tools();
    let original_fallback = model.fallback_kinematics.as_ref().map(|f| f.tools());
    let mut tools = original.to_vec();
    let mut fallback_tools = original_fallback.map(<[SE3]>::to_vec);
    let mut report = Vec::new();
    for (data_tool, slot) in slots.iter().enumerate() {
        let Some(slot) = slot else { continue };
        let change = fit.tools[*slot];
        let name = data.tools[data_tool].clone();
        let (index, new) = match known[data_tool] {
            Some(index) => (index, false),
            None => {
                tools.push(tools[0]);
                if let Some(f) = fallback_tools.as_mut() {
                    f.push(f[0]);
                }
                out.tools.push(name.clone());
                (tools.len() - 1, true)
            }
        };
        let measured_against = known[data_tool].unwrap_or(0);
        tools[index] = original[measured_against] * change;
        // The GP's tool-point correction stays at the point it was applied at when the rows were
        // predicted (that of the tool measured against), as the registration fitted it.
        if let Some(residual_gp) = out.residual_gp.as_mut() {
            let reference =
                model.residual_gp.as_ref().and_then(|g| g.tool_points.get(measured_against).copied().flatten());
            residual_gp.tool_points.resize(tools.len(), None);
            residual_gp.tool_points[index] =
                Some(change.inverse().transform_point(&reference.unwrap_or_else(Vector3::zeros)));
        }
        if let (Some(f), Some(o)) = (fallback_tools.as_mut(), original_fallback) {
            f[index] = o[measured_against] * change;
        }
        report.push(RegisteredTool {
            name,
            new,
            point_change_mm: change.translation().norm() * 1e3,
            rotation_change_mrad: change.rotation().log().norm() * 1e3,
        });
    }
    out.kinematics.set_tools(tools);
    if let (Some(fallback), Some(f)) = (out.fallback_kinematics.as_mut(), fallback_tools) {
        fallback.set_tools(f);
    }
    (out, report)
}

impl Verdict {
    /// The verdict of a residual against a held-out error.
    pub(crate) fn of(ratio: Option<f64>, limit: f64) -> Verdict {
        match ratio {
            None => Verdict::Unknown,
            Some(r) if r > limit => Verdict::RobotChanged,
            Some(_) => Verdict::Consistent,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::HeldoutFrom;
    use campaign::{GeneratorConfig, Perturbation};
    use lie::SO3;
    use model::Method;
    use pipeline::FitOptions;
    use rand::SeedableRng;
    use robot::RobotDescription;

    fn irb4400() -> RobotDescription {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots/irb4400.ron");
        RobotDescription::read(&path).unwrap()
    }

    /// A simulated cell's model, and data of the same robot seen from a moved tracker with a new tool.
    fn scenario(full_pose: bool, method: Method) -> (CalibratedModel, MeasurementSet, MeasurementSet, f64) {
        let robot = irb4400();
        let ranges = campaign::joint_ranges(&robot);
        let effects = campaign::paper_effects();
        let original = campaign::simulated_cell(&robot, &Perturbation::default(), 3).unwrap();
        let mut moved = original.clone();
        moved.tracker_from_base = campaign::tracker_placement(&mut rand_chacha::ChaCha8Rng::seed_from_u64(9));
        let tool = original.robot.tools()[original.tool]
            * SE3::new(SO3::exp(&Vector3::new(0.0, 0.3, 0.1)), Vector3::new(0.06, -0.05, 0.06));
        moved.robot.set_tools(vec![tool]);
        moved.tool = 0;
        let config = |rows, seed| GeneratorConfig { sample_count: rows, seed, ..GeneratorConfig::default() };
        let simulate =
            |cell, rows, seed| campaign::simulate(cell, &effects, &ranges, &config(rows, seed), full_pose).unwrap();
        let train = simulate(&original, 200, 1);
        let (model, _) = pipeline::fit(&robot, &train, method, &FitOptions::default()).unwrap();
        let heldout = model::evaluate(&model, &model.bind(simulate(&original, 300, 2)).unwrap())
            .unwrap()
            .summary
            .mean_position_error_mm;
        let rename = |mut set: MeasurementSet| {
            set.tools = vec!["probe2".into()];
            set
        };
        (model, rename(simulate(&moved, 20, 3)), rename(simulate(&moved, 300, 4)), heldout)
    }

    #[test]
    fn a_moved_tracker_and_a_new_tool_are_registered_from_full_poses() {
        let (model, few, test, heldout) = scenario(true, Method::Poe);
        let refit = Refit { base: true, tools: true };
        let registered = register(&model, &few, refit, Some(heldout), &RegisterOptions::default()).unwrap();
        let after = model::evaluate(&registered.model, &registered.model.bind(&test).unwrap())
            .unwrap()
            .summary
            .mean_position_error_mm;
        assert!(after < 1.3 * heldout, "{after} mm against {heldout} mm: {:#?}", registered.report);
        assert_eq!(registered.report.verdict, Verdict::Consistent);
        assert!(registered.report.warnings.is_empty(), "{:?}", registered.report.warnings);
    }

    #[test]
    fn without_a_given_held_out_error_the_fits_own_estimate_is_judged_against() {
        let (model, few, _, heldout) = scenario(true, Method::Poe);
        let stored = model.heldout.expect("a poe fit keeps its held-out estimate");
        assert_eq!(stored.source, model::HeldoutSource::DegreesOfFreedom);
        // The estimate is of the error measured on 300 poses the fit did not see.
        let ratio = stored.mean_position_error_mm / heldout;
        assert!((0.7..1.3).contains(&ratio), "{} mm estimated, {heldout} mm measured", stored.mean_position_error_mm);
        let refit = Refit { base: true, tools: true };
        let registered = register(&model, &few, refit, None, &RegisterOptions::default()).unwrap();
        assert_eq!(registered.report.heldout_from, Some(HeldoutFrom::ModelFile(stored.source)));
        assert_eq!(registered.report.model_heldout_mm, Some(stored.mean_position_error_mm));
        assert_eq!(registered.report.verdict, Verdict::Consistent);
        // An older model file has none: unknown, as before.
        let older = CalibratedModel { heldout: None, ..model };
        let registered = register(&older, &few, refit, None, &RegisterOptions::default()).unwrap();
        assert_eq!(registered.report.verdict, Verdict::Unknown);
    }

    #[test]
    fn angles_a_turn_away_are_wrapped_into_the_fitted_range_and_register_alike() {
        let (mut model, few, _, heldout) = scenario(true, Method::Poe);
        let range = model.training_range.clone().unwrap();
        let turned = |set: &MeasurementSet| {
            let mut set = set.clone();
            for row in &mut set.rows {
                row.q[0] += std::f64::consts::TAU;
            }
            set
        };
        let refit = Refit { base: true, tools: true };
        let options = RegisterOptions::default();
        // IRB 4400's joint 1 spans less than a turn: nothing is wrapped, the rows are outside.
        let narrow = register(&model, &turned(&few), refit, Some(heldout), &options).unwrap();
        assert!(narrow.report.wrapped.is_empty());
        assert!(narrow.report.out_of_range.iter().any(|w| w.input == "joint 1"), "{:?}", narrow.report.out_of_range);
        // With limits of two turns the same rows are wrapped back, and registered as the originals.
        model.joint_limits[0] = Some([-std::f64::consts::TAU, std::f64::consts::TAU]);
        let wide = register(&model, &turned(&few), refit, Some(heldout), &options).unwrap();
        assert_eq!(wide.report.wrapped.len(), 1, "{:?}", wide.report.wrapped);
        assert_eq!(wide.report.wrapped[0].joint, 1);
        assert_eq!(wide.report.wrapped[0].turns, vec![-1]);
        assert_eq!(wide.report.wrapped[0].rows_wrapped, few.rows.len());
        assert!(wide.report.out_of_range.iter().all(|w| w.input != "joint 1"));
        let plain = register(&model, &few, refit, Some(heldout), &options).unwrap();
        assert!(plain.report.wrapped.is_empty());
        let (a, b) = (wide.report.residual.mean_position_error_mm, plain.report.residual.mean_position_error_mm);
        assert!((a - b).abs() < 1e-6 * b, "{a} {b}");
        assert!(range.q[0][1] - range.q[0][0] < std::f64::consts::TAU);
    }

    #[test]
    fn the_registered_model_predicts_a_new_tool_as_the_registration_fitted_it() {
        // A tool-point GP corrects about the point it was applied at: the carried model must apply
        // it there (the old tool's point) and not about the new tool's, or the GP's orientation
        // correction misses the lever arm between the two (10 % of held-out on the IRB 4400).
        let (model, few, _, _) = scenario(true, Method::PoeGp);
        assert_eq!(model.residual_gp.as_ref().unwrap().residual_frame, model::ResidualFrame::ToolPoint);
        // The new tool measured against the model's first, as `register` does.
        let on_tool = |t: usize| few.rows.iter().map(move |r| Measurement { tool: t, ..r.clone() }).collect();
        let predicted = model.predict(&BoundSet::made_for_model("few", on_tool(0))).unwrap();
        let rows: Vec<RegistrationRow> = few
            .rows
            .iter()
            .zip(&predicted)
            .map(|(r, p)| RegistrationRow {
                predicted: p.pose,
                point: r.position,
                rotation: r.orientation,
                slot: Some(0),
            })
            .collect();
        let unknowns = Unknowns { frame: true, tools: 1, tool_rotations: true };
        let fit = register_rows(&rows, unknowns, &Default::default()).unwrap();
        let (carried, tools) = carried(&model, &few, &[None], &[Some(0)], &fit);
        assert!(tools[0].new && tools[0].point_change_mm > 50.0, "{tools:?}");
        let poses = carried.predict(&BoundSet::made_for_model("few", on_tool(carried.tools.len() - 1))).unwrap();
        for (row, pose) in rows.iter().zip(&poses) {
            let wanted = fit.pose(row);
            assert!((pose.pose.translation() - wanted.translation()).norm() < 1e-9, "{pose:?} {wanted:?}");
            assert!((pose.pose.rotation() * wanted.rotation().inverse()).log().norm() < 1e-9);
        }
    }

    #[test]
    fn a_new_tool_point_on_a_position_only_model_is_warned_about() {
        // A model fitted on one tool point knows the flange's orientation only as far as that
        // point shows it, so a point 10 cm away may be predicted millimetres off: the warning says
        // so whatever the outcome. The verdict must agree with what the new point's test poses
        // show: since the fit holds the links near the nominal geometry where the data leave them
        // free (the nominal prior), this flange is close enough (test poses 1.07× the
        // model's held-out error), and the verdict is `Consistent`; before the prior it was
        // millimetres off and `RobotChanged`.
        let (model, few, test, heldout) = scenario(false, Method::Poe);
        let refit = Refit { base: true, tools: true };
        let registered = register(&model, &few, refit, Some(heldout), &RegisterOptions::default()).unwrap();
        let after = model::evaluate(&registered.model, &registered.model.bind(&test).unwrap())
            .unwrap()
            .summary
            .mean_position_error_mm;
        assert!(registered.report.warnings.contains(&RegisterWarning::PositionModelToolPoint));
        let expected = if after > RegisterOptions::default().changed_ratio * heldout {
            Verdict::RobotChanged
        } else {
            Verdict::Consistent
        };
        assert_eq!(registered.report.verdict, expected, "{after} mm on the test poses against {heldout} mm held out");
    }

    #[test]
    fn too_few_poses_for_a_frame_and_a_tool_are_refused_with_the_counts() {
        let (model, few, _, _) = scenario(false, Method::Poe);
        let refit = Refit { base: true, tools: true };
        let err = register(&model, &few.subset(&[0, 1, 2, 3, 4, 5, 6, 7]), refit, None, &RegisterOptions::default())
            .unwrap_err();
        assert!(
            matches!(
                err.kind::<ErrorKind>(),
                Some(ErrorKind::TooFewPoses { poses: 8, needed_poses: 9, rows: 24, parameters: 9, .. })
            ),
            "{err}"
        );
    }
}
