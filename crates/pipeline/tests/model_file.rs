//! Model files whose parts do not fit together (edited by hand, or corrupt) are refused when read,
//! at the field at fault; before, `eval` and `predict` panicked on an index or silently dropped
//! compliance terms.

use campaign::{GeneratorConfig, Perturbation, joint_ranges, paper_effects, simulate, simulated_cell};
use effects::IdentifiedEffect;
use errors::{CommonKind, Error};
use model::{CalibratedModel, Method};
use pipeline::FitOptions;

/// A `poe-gp-load` model with joint compliance (every part a model can have), and its file text.
fn fitted(full_pose: bool) -> (CalibratedModel, String) {
    let robot = testkit::robot("irb4400.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), 3).unwrap();
    let config = GeneratorConfig { sample_count: 60, seed: 3, ..GeneratorConfig::default() };
    let data = simulate(&cell, &paper_effects(), &joint_ranges(&robot), &config, full_pose).unwrap();
    let options = FitOptions::default().with_effects("joint_compliance".parse().unwrap());
    let (model, _) = pipeline::fit(&robot, &data, Method::PoeGpLoad, &options).unwrap();
    (model.clone(), text_of(&model))
}

fn text_of(model: &CalibratedModel) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.ron");
    model::write_model(&path, model).unwrap();
    std::fs::read_to_string(&path).unwrap()
}

/// The refusal of `text`, checked to name the file and a line past the first.
fn refused(text: &str) -> (Error, String) {
    let error = model::parse_model(text, "m.ron").expect_err("the model must be refused");
    let message = error.to_string();
    let line: usize = message.split(':').nth(1).and_then(|l| l.parse().ok()).unwrap_or(0);
    assert!(message.starts_with("m.ron:") && line > 1, "{message}");
    (error, message)
}

#[test]
fn a_written_model_reads_back_and_passes_its_check() {
    let (model, text) = fitted(false);
    let again = model::parse_model(&text, "m.ron").unwrap();
    assert_eq!(again.tools, model.tools);
    model.check(&text, "m.ron").unwrap();
}

#[test]
fn a_compliance_term_of_a_joint_the_robot_lacks_is_refused() {
    let (_, text) = fitted(false);
    let (error, message) = refused(&text.replacen("joint: 1,", "joint: 9,", 1));
    assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelIndex { index: 9, limit: 6, .. })), "{message}");
    assert!(message.contains("effects[0].terms[") && message.contains("].joint is 9, it must be below 6"), "{message}");
    let (error, message) = refused(&text.replacen("column: ", "column: 9999", 1));
    assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelIndex { limit: 25, .. })), "{message}");
}

#[test]
fn compliance_values_that_do_not_match_their_terms_are_refused() {
    let (mut model, _) = fitted(false);
    let Some(IdentifiedEffect::JointCompliance(compliance)) = model.effects.first_mut() else {
        panic!("no compliance")
    };
    compliance.theta.pop();
    let terms = compliance.terms.len();
    let (error, message) = refused(&text_of(&model));
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelCount { found, expected, .. }) if *found == terms - 1 && *expected == terms),
        "{message}"
    );
    assert!(message.contains("effects[0].theta has"), "{message}");
}

#[test]
fn tool_names_that_do_not_match_the_kinematics_are_refused() {
    let (mut model, _) = fitted(false);
    model.tools.push("second".into());
    let (error, message) = refused(&text_of(&model));
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelCount { found: 2, expected: 1, .. })),
        "{message}"
    );
    assert!(message.contains("tools has 2 tool names, the rest of the model needs 1"), "{message}");
}

#[test]
fn a_gp_of_the_wrong_dimensions_is_refused() {
    let (position_only, _) = fitted(false);
    let (mut full_pose, _) = fitted(true);
    // A full-pose model with the position-only GP: 3 outputs where 6 are needed.
    full_pose.residual_gp = position_only.residual_gp.clone();
    full_pose.residual_gp.as_mut().unwrap().full_pose = true;
    let (error, message) = refused(&text_of(&full_pose));
    assert!(
        matches!(
            error.kind::<CommonKind>(),
            Some(CommonKind::ModelCount { what: "outputs", found: 3, expected: 6, .. })
        ),
        "{message}"
    );
    // The payload input dropped from the method but not from the GP.
    let mut model = position_only.clone();
    model.method = Method::PoeGp;
    let (_, message) = refused(&text_of(&model));
    assert!(message.contains("with_payload is true for method poe-gp"), "{message}");
    let mut model = position_only;
    model.residual_gp.as_mut().unwrap().with_payload = false;
    model.method = Method::PoeGp;
    let (error, message) = refused(&text_of(&model));
    assert!(
        matches!(
            error.kind::<CommonKind>(),
            Some(CommonKind::ModelCount { what: "inputs", found: 7, expected: 6, .. })
        ),
        "{message}"
    );
}

#[test]
fn a_gp_method_without_a_gp_is_refused() {
    let (mut model, _) = fitted(false);
    model.residual_gp = None;
    let (_, message) = refused(&text_of(&model));
    assert!(message.contains("method poe-gp-load but the model has no residual GP"), "{message}");
}

/// A fitted model's file with the first coordinate of its first translation set to `value`.
fn first_translation_set_to(value: &str) -> String {
    let (_, text) = fitted(false);
    let at = text.find("translation: (").unwrap() + "translation: (".len();
    let end = at + text[at..].find(',').unwrap();
    format!("{}{value}{}", &text[..at], &text[end..])
}

#[test]
fn a_non_finite_transform_is_refused_at_its_translation() {
    let (error, message) = refused(&first_translation_set_to("NaN"));
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::NotFinite { field, .. }) if field == "kinematics.joints[0]"),
        "{message}"
    );
}

/// The layout of a version-1 model file, whose only effect was joint compliance.
#[derive(serde::Serialize)]
struct Version1 {
    schema_version: u32,
    robot: String,
    method: Method,
    full_pose: bool,
    tools: Vec<String>,
    kinematics: poe::LocalPoe,
    joint_compliance: Option<Version1Compliance>,
    #[serde(rename = "compensation")]
    residual_gp: Option<model::ResidualGp>,
}

#[derive(serde::Serialize)]
struct Version1Compliance {
    base_model: poe::LocalPoe,
    gravity_m_per_s2: [f64; 3],
    terms: Vec<effects::ComplianceParameter>,
    theta: Vec<f64>,
}

#[test]
fn a_version_1_file_with_joint_compliance_reads_and_predicts_as_before() {
    let (model, _) = fitted(true);
    let Some(IdentifiedEffect::JointCompliance(compliance)) = model.effects.first() else { panic!("no compliance") };
    let effects::ComplianceTorque::GravityRegressor(load) = &compliance.torque else {
        panic!("simulated data without torques")
    };
    let old = Version1 {
        schema_version: 1,
        robot: model.robot.clone(),
        method: model.method,
        full_pose: model.full_pose,
        tools: model.tools.clone(),
        kinematics: model.kinematics.clone(),
        joint_compliance: Some(Version1Compliance {
            base_model: load.base_model.clone(),
            gravity_m_per_s2: load.gravity_m_per_s2,
            terms: compliance.terms.clone(),
            theta: compliance.theta.clone(),
        }),
        residual_gp: model.residual_gp.clone(),
    };
    let text = ron::ser::to_string_pretty(&old, ron::ser::PrettyConfig::default()).unwrap();
    assert!(text.contains("joint_compliance:") && !text.contains("effects:"), "{text}");
    let read = model::parse_model(&text, "old.ron").unwrap();
    assert_eq!(read.schema_version, model::SCHEMA_VERSION);
    let (Some(IdentifiedEffect::JointCompliance(again)), 1) = (read.effects.first(), read.effects.len()) else {
        panic!("{:?}", read.effects)
    };
    assert_eq!((&again.terms, &again.theta), (&compliance.terms, &compliance.theta));
    let data = simulate(
        &simulated_cell(&testkit::robot("irb4400.ron"), &Perturbation::default(), 3).unwrap(),
        &paper_effects(),
        &joint_ranges(&testkit::robot("irb4400.ron")),
        &GeneratorConfig { sample_count: 20, seed: 4, ..GeneratorConfig::default() },
        true,
    )
    .unwrap();
    let now = model::evaluate(&model, &model.bind(&data).unwrap()).unwrap().errors;
    let then = model::evaluate(&read, &read.bind(&data).unwrap()).unwrap().errors;
    for (a, b) in now.iter().zip(&then) {
        assert!((a.position_mm - b.position_mm).abs() < 1e-9, "{a:?} {b:?}");
    }
    // A version this build does not know is refused with both versions.
    let future = text.replacen("schema_version: 1", "schema_version: 9", 1);
    let message = model::parse_model(&future, "new.ron").unwrap_err().to_string();
    assert!(message.contains("schema version 9") && message.contains("versions 1 to 2"), "{message}");
}

/// A `poe` model with a gear error and time drift, and its file text.
fn with_effects() -> (CalibratedModel, String) {
    let robot = testkit::robot("irb4400.ron");
    let cell = simulated_cell(&robot, &Perturbation::default(), 5).unwrap();
    let config = GeneratorConfig { sample_count: 60, seed: 5, ..GeneratorConfig::default() };
    let data = simulate(&cell, &paper_effects(), &joint_ranges(&robot), &config, false).unwrap();
    let options = FitOptions::default().with_effects("gear_periodic:2:3,time_drift".parse().unwrap());
    let (model, _) = pipeline::fit(&robot, &data, Method::Poe, &options).unwrap();
    (model.clone(), text_of(&model))
}

#[test]
fn an_effect_on_a_joint_the_robot_lacks_is_refused_at_its_field() {
    let (mut model, _) = with_effects();
    let Some(IdentifiedEffect::GearPeriodic(gear)) = model.effects.first_mut() else { panic!("no gear effect") };
    gear.joint = 8;
    let (error, message) = refused(&text_of(&model));
    assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelIndex { index: 8, limit: 6, .. })), "{message}");
    assert!(message.contains("effects[0].joint is 8"), "{message}");
}

#[test]
fn effect_values_that_do_not_match_their_features_are_refused_at_their_field() {
    let (mut model, _) = with_effects();
    let Some(IdentifiedEffect::GearPeriodic(gear)) = model.effects.first_mut() else { panic!("no gear effect") };
    gear.theta.push(0.0);
    let (error, message) = refused(&text_of(&model));
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelCount { found: 7, expected: 6, .. })),
        "{message}"
    );
    assert!(message.contains("effects[0].theta"), "{message}");
    // The second effect's field is placed at its own occurrence, past the first effect's.
    let (model, text) = with_effects();
    let Some(IdentifiedEffect::TimeDrift(drift)) = model.effects.get(1) else { panic!("no drift") };
    let reference = format!("reference_s: {:?}", drift.reference_s);
    assert!(text.contains(&reference), "{text}");
    let broken = text.replacen(&reference, "reference_s: inf", 1);
    let (error, message) = refused(&broken);
    assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::NotFinite { .. })), "{message}");
    let line = broken.lines().position(|l| l.contains("reference_s: inf")).unwrap() + 1;
    assert!(message.starts_with(&format!("m.ron:{line}:")), "{message}");
    assert!(message.contains("effects[1].reference_s[0]"), "{message}");
}

#[test]
fn a_finite_but_absurd_translation_is_refused_at_its_field() {
    // 1e308 is finite: before, it was read, and every prediction was NaN (cargo xtask fuzz).
    let (error, message) = refused(&first_translation_set_to("1e308"));
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelValue { field, .. }) if field == "kinematics.joints[0]"),
        "{message}"
    );
    assert!(message.contains("1e308") && message.contains("larger than any robot cell"), "{message}");
}

#[test]
fn a_vanishing_feature_scale_is_refused_not_left_to_predict_nan() {
    // A scale of 1e-320 passes "positive and finite" but makes the scaled feature overflow.
    let (mut model, _) = with_effects();
    let Some(IdentifiedEffect::GearPeriodic(gear)) = model.effects.first_mut() else { panic!("no gear effect") };
    gear.scale[1] = 1e-320;
    let (error, message) = refused(&text_of(&model));
    assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::RonFormat { .. })), "{message}");
    assert!(message.contains("effects: part 1 (gear_periodic"), "{message}");
}

#[test]
fn gp_training_data_that_overflow_its_weights_are_refused() {
    let (model, text) = fitted(false);
    assert!(model.residual_gp.is_some());
    let at = text.find("training_outputs: [").unwrap();
    let first = at + text[at..].find(|c: char| c == '-' || c.is_ascii_digit()).unwrap();
    let end = first + text[first..].find(',').unwrap();
    let edited = format!("{}1e308{}", &text[..first], &text[end..]);
    let (_, message) = refused(&edited);
    assert!(message.contains("residual_gp: part") && message.contains("gaussian_process"), "{message}");
}

/// Files written before SPEC version 4 call the residual GP `compensation` (the word now means
/// `calib compensate`'s joint targets alone): such a file reads as the same model, written back
/// under the new name, and a refusal names the field as the file spells it.
#[test]
fn a_file_that_calls_the_residual_gp_compensation_reads_as_the_same_model() {
    let (model, text) = fitted(false);
    assert!(model.residual_gp.is_some() && text.contains("\n    residual_gp: Some(("), "{text}");
    assert!(!text.contains("compensation"), "the old name is written again");
    let old = text.replacen("\n    residual_gp: Some((", "\n    compensation: Some((", 1);
    let read = model::parse_model(&old, "old.ron").unwrap();
    assert_eq!(text_of(&read), text);
    let (_, message) = refused(&old.replacen("with_payload: true", "with_payload: false", 1));
    assert!(message.contains("compensation.with_payload is false for method poe-gp-load"), "{message}");
    let (_, message) = refused(&text.replacen("with_payload: true", "with_payload: false", 1));
    assert!(message.contains("residual_gp.with_payload is false for method poe-gp-load"), "{message}");
}

#[test]
fn an_absurd_effect_coefficient_is_refused_at_its_field() {
    // Found by `cargo xtask fuzz` (seed 2026): theta = 1e308 of a term whose feature is 0 at the
    // reference rows passed the walk, and predicted NaN on real rows.
    let (mut model, _) = with_effects();
    let Some(IdentifiedEffect::TimeDrift(drift)) = model.effects.get_mut(1) else { panic!("no drift") };
    drift.theta[0] = -1e308;
    let (error, message) = refused(&text_of(&model));
    assert!(
        matches!(error.kind::<CommonKind>(), Some(CommonKind::ModelValue { field, .. }) if field == "effects[1].theta[0]"),
        "{message}"
    );
}

/// `text` with the first `from` after `robot_description:` replaced by `to`.
fn in_robot(text: &str, from: &str, to: &str) -> String {
    let start = text.find("robot_description:").expect("the model keeps its robot");
    format!("{}{}", &text[..start], text[start..].replacen(from, to, 1))
}

#[test]
fn the_robot_a_model_keeps_is_checked_as_a_robot_file_and_against_the_kinematics() {
    let (model, text) = fitted(false);
    assert_eq!(model.robot_description, Some(testkit::robot("irb4400.ron")), "the robot the fit started from");
    let (_, message) = refused(&in_robot(&text, "axis: (0.0,", "axis: (5.0,"));
    assert!(message.contains("robot_description is not a valid robot") && message.contains("norm"), "{message}");
    let prismatic = in_robot(&text, "kind: Revolute", "kind: Prismatic");
    let (_, message) =
        refused(&in_robot(&prismatic, "limits_deg: Some((-165.0, 165.0))", "limits_m: Some((0.0, 1.0))"));
    assert!(message.contains("its joint kinds are not the kinematics'"), "{message}");
    let line: usize = message.split(':').nth(1).unwrap().parse().unwrap();
    let field_line = 1 + text[..text.find("robot_description:").unwrap()].matches('\n').count();
    assert_eq!(line, field_line, "{message}");
}

/// The effects' uncertainty is checked on reading: a factor of the wrong size, a number
/// that is not one, a free parameter the kinematics lacks and a fallback limit that is not above
/// zero are refused at the field, with its line and column.
#[test]
fn an_effect_uncertainty_that_does_not_fit_the_model_is_refused_at_its_field() {
    let (model, text) = fitted(false);
    let uncertainty = model.effect_uncertainty.clone().expect("a fit with effects keeps its uncertainty");
    let at_field = |message: &str, field: &str| {
        let line = text.lines().position(|l| l.contains("effect_uncertainty:")).unwrap() + 1;
        assert!(message.starts_with(&format!("m.ron:{line}:")), "{message}");
        assert!(message.contains(field), "{message}");
    };
    let mut short = model.clone();
    short.effect_uncertainty.as_mut().unwrap().factor.pop();
    let (_, message) = refused(&text_of(&short));
    at_field(&message, "effect_uncertainty.factor:");
    let mut free = model.clone();
    free.effect_uncertainty.as_mut().unwrap().free[0] = 999;
    let (_, message) = refused(&text_of(&free));
    at_field(&message, "999 is not a parameter of the kinematics");
    let mut limit = model.clone();
    limit.effect_uncertainty.as_mut().unwrap().fallback_sigma_m = 0.0;
    let (_, message) = refused(&text_of(&limit));
    at_field(&message, "fallback_sigma_m");
    let first = format!("{:.6e}", uncertainty.factor[0]);
    let (_, message) = refused(&text.replacen(&first, "x1", 1));
    assert!(message.contains("'x1', is not a number"), "{message}");
    // The packed numbers read back exactly as the fit used them.
    let again = model::parse_model(&text, "m.ron").unwrap();
    assert_eq!(again.effect_uncertainty, Some(uncertainty));
}
