//! The effects file of `calib simulate --effects` (loadsim's [`Effects`] as RON): read, and checked
//! against the robot at the field at fault. loadsim checks the same values when it simulates, but
//! without a file to point at; a hostile count (`fixed_point_iterations: 1e18`) it would run for ever.

use errors::ron_position::{field_position, field_position_in, ron_options};
use errors::{CommonKind, Error};
use loadsim::{DynamicsNeed, EffectKind, Effects, RobotFacts};
use robot::RobotDescription;
use ron::Value;
use std::path::Path;

// The bounds of a real cell an effects file is checked against live with each effect's
// simulation in loadsim (its `SimulatedEffect::check_entries`), and are re-exported here.
pub use loadsim::{
    MAX_DRIFT_PER_S, MAX_EXPANSION_PER_K, MAX_FIXED_POINT_ITERATIONS, MAX_JOINT_ERROR_RAD, MAX_NOISE, MAX_ORDER,
    MAX_SCREW_ERROR_M, MAX_TEMPERATURE_C,
};

/// Reads an [`Effects`] RON file (fields left out are off; `Some(..)` may be omitted) for
/// `robot`, checked by [`check_effects`].
pub fn read_effects(path: &Path, robot: &RobotDescription) -> Result<Effects, Error> {
    let text = errors::ron_position::read_text(path)?;
    let file = path.display().to_string();
    let effects = parse_effects(&text, &file)?;
    check_effects(&effects, robot, &text, &file)?;
    Ok(effects)
}

/// Parses an [`Effects`] RON text; `file` names it in errors. A field name that no effect has is
/// refused at its line: serde would skip it, and a misspelt effect would silently stay off.
pub fn parse_effects(text: &str, file: &str) -> Result<Effects, Error> {
    let at = |line: usize, column: usize, message: String| {
        Error::at_line(file.to_owned(), line as u64, column, CommonKind::RonFormat { message })
    };
    let syntax = |e: ron::error::SpannedError| at(e.span.start.line, e.span.start.col, e.code.to_string());
    let effects: Effects = ron_options().from_str(text).map_err(syntax)?;
    let given: Value = ron_options().from_str(text).map_err(syntax)?;
    // The parsed effects written back hold every field they know, switched on or not.
    let mut known = ron::to_string(&effects)
        .ok()
        .and_then(|written| ron::from_str::<Value>(&written).ok())
        .ok_or_else(|| at(1, 1, "the effects do not write back as RON".into()))?;
    // They are written as the SPEC names; the spellings before SPEC version 5 read as those.
    if let Value::Map(fields) = &mut known {
        for kind in EffectKind::ALL {
            if let (Some(field), Some(former)) = (kind.simulated_field(), kind.former_field())
                && let Some(value) = fields.get(&Value::String(field.to_owned())).cloned()
            {
                fields.insert(former, value);
            }
        }
    }
    match unknown_field(&given, &known) {
        Some(name) => {
            let (line, column) = field_position(text, &name, 0);
            Err(at(line, column, format!("unknown field `{name}`")))
        }
        None => Ok(effects),
    }
}

/// The first field name in `given` that `known` lacks, at any depth.
fn unknown_field(given: &Value, known: &Value) -> Option<String> {
    fn unwrap(value: &Value) -> &Value {
        match value {
            Value::Option(Some(inner)) => unwrap(inner),
            other => other,
        }
    }
    match (unwrap(given), unwrap(known)) {
        (Value::Map(given), Value::Map(known)) => given.iter().find_map(|(key, value)| match known.get(key) {
            Some(inner) => unknown_field(value, inner),
            None => Some(match key {
                Value::String(name) => name.clone(),
                other => format!("{other:?}"),
            }),
        }),
        (Value::Seq(given), Value::Seq(known)) => given.iter().zip(known).find_map(|(a, b)| unknown_field(a, b)),
        _ => None,
    }
}

/// Checks `effects` against `robot`: every joint index inside the robot, every value finite and
/// within the bounds of a real cell (`MAX_…`, which also keep the simulation from overflowing
/// into NaN poses), the robot's dynamics present where an effect needs them, the compliance
/// iterations bounded ([`MAX_FIXED_POINT_ITERATIONS`]). A refusal names the field in `text` (the file `file`): the
/// list entry at fault, or the effect where the field was left out.
pub fn check_effects(effects: &Effects, robot: &RobotDescription, text: &str, file: &str) -> Result<(), Error> {
    let at = |section: &str, field: &str, index: usize, message: String| {
        let (line, column) = field_position_in(text, section, field, index);
        Error::at_line(
            file.to_owned(),
            line as u64,
            column,
            CommonKind::RonFormat { message: format!("{section}: {message}") },
        )
    };
    let active = effects.active();
    for (kind, effect) in &active {
        let section = spelled_in(text, *kind);
        let what = match effect.needs_dynamics() {
            DynamicsNeed::Nothing => continue,
            DynamicsNeed::Masses => "link masses",
            DynamicsNeed::MassesAndStiffness => "masses and joint stiffness",
        };
        if robot.dynamics.is_none() {
            let message = format!(
                "needs the robot's {what} ({} has none: a `dynamics` block in a RON robot file, or an `<inertial>` \
                 on every moving link of a URDF)",
                robot.name
            );
            return Err(at(section, section, 0, message));
        }
    }
    let joints = robot.joint_kinds();
    let facts =
        RobotFacts { joints: &joints, dynamics: robot.dynamics.as_ref(), pitch_bounds_mm: robot::PITCH_BOUNDS_MM };
    for (kind, effect) in &active {
        let section = spelled_in(text, *kind);
        effect.check_entries(&facts).map_err(|f| at(section, &f.field, f.index, f.message))?;
    }
    Ok(())
}

/// The field of `kind` as `text` spells it: the SPEC name, or the spelling of a file written before
/// SPEC version 5, so that a refusal names the field the file has.
fn spelled_in(text: &str, kind: EffectKind) -> &'static str {
    // `active` holds only simulated kinds, which all have a field.
    let field = kind.simulated_field().unwrap_or(kind.name());
    match kind.former_field() {
        Some(former) if field_position(text, field, 0) == (1, 1) && field_position(text, former, 0) != (1, 1) => former,
        _ => field,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use loadsim::{JointComplianceModel, TrackerNoiseModel};

    #[test]
    fn an_effects_file_with_a_typo_is_refused_at_its_line() {
        let good = parse_effects("(compliance: (payload_only: true), tracker_noise: ())", "e.ron").unwrap();
        assert_eq!(
            good.joint_compliance,
            Some(JointComplianceModel { payload_only: true, ..JointComplianceModel::default() })
        );
        assert_eq!(good.tracker_noise, Some(TrackerNoiseModel::default()));
        let coupled = parse_effects(
            "(coupling: (terms: [(joint_index: 2, amplitude_rad: 1e-3, factors: [(source_joint_index: 1, order: 2.0, phase_rad: 0.0)])]))",
            "e.ron",
        )
        .unwrap();
        assert_eq!(coupled.coupling.map(|c| c.terms[0].factors[0].order), Some(2.0));
        for (text, line) in [
            ("(\n  complaince: (),\n)", 2),
            ("(\n  compliance: (),\n  tracker_noise: (\n    radial_sigma: 1e-5),\n)", 4),
            ("(\n  compliance: (payload_only: maybe),\n)", 2),
            (
                "(\n  coupling: (terms: [(joint_index: 2, amplitude_rad: 1e-3,\n    factors: [(source_joint: 1, order: 1.0, phase_rad: 0.0)])]),\n)",
                3,
            ),
        ] {
            let e = parse_effects(text, "e.ron").expect_err(text);
            assert!(matches!(e.kind::<CommonKind>(), Some(CommonKind::RonFormat { .. })), "{text}: {e:?}");
            let place = e.place().expect("a RON error has a place");
            assert_eq!((place.file(), place.line()), ("e.ron", Some(line)), "{text}");
        }
    }

    #[test]
    fn a_screw_error_is_taken_on_a_linear_axis_and_a_pitch_out_of_bounds_is_refused_at_its_entry() {
        let robot = testkit::robot("column_ur10.ron");
        let check = |text: &str| parse_effects(text, "e.ron").and_then(|e| check_effects(&e, &robot, text, "e.ron"));
        let good =
            "(screw: (harmonics: [(joint_index: 0, pitch_m: 0.01, order: 1.0, amplitude_m: 2e-5, phase_rad: 0.0)]))";
        check(good).unwrap();
        for (text, words) in [
            (
                "(screw: (harmonics: [\n  (joint_index: 0, pitch_m: 20.0, order: 1.0, amplitude_m: 2e-5, phase_rad: 0.0)]))",
                "e.ron:2:4: screw: harmonic 1: pitch_m is 20, expected 0.00001 to 10 m",
            ),
            (
                "(screw: (harmonics: [\n  (joint_index: 0, pitch_m: 0.01, order: 1.0, amplitude_m: 0.5, phase_rad: 0.0)]))",
                "e.ron:2:4: screw: harmonic 1: amplitude_m is 0.5, at most 0.001",
            ),
        ] {
            let message = check(text).expect_err(text).to_string();
            assert!(message.starts_with(words), "{message}");
        }
    }

    #[test]
    fn effect_values_the_robot_cannot_take_are_refused_at_their_entry() {
        let robot = testkit::robot("irb4400.ron");
        let check = |text: &str| parse_effects(text, "e.ron").and_then(|e| check_effects(&e, &robot, text, "e.ron"));
        check("(periodic: (harmonics: [(joint_index: 1, order: 2.0, amplitude_rad: 1e-5, phase_rad: 0.0)]))").unwrap();
        for (text, position, words) in [
            (
                "(periodic: (harmonics: [\n  (joint_index: 1, order: 2.0, amplitude_rad: 1e-5, phase_rad: 0.0),\n  (joint_index: 6, order: 2.0, amplitude_rad: 1e-5, phase_rad: 0.0)]))",
                (3, 4),
                "periodic: harmonic 2: ",
            ),
            ("(backlash: (joints: [\n  (joint_index: 0, half_band_rad: NaN)]))", (2, 4), "backlash: entry 1: "),
            (
                "(screw: (harmonics: [\n  (joint_index: 1, pitch_m: 0.005, order: 1.0, amplitude_m: 1e-6, phase_rad: 0.0)]))",
                (2, 4),
                "screw: harmonic 1: screw: joint 2 is revolute",
            ),
            ("(compliance: (\n  fixed_point_iterations: 1000000000000))", (2, 3), "at most 100"),
            ("(\n thermal: (reference_temp_c: inf))", (2, 12), "thermal: "),
            (
                "(backlash: (joints: [\n  (joint_index: 18446744073709551615, half_band_rad: 1e-4)]))",
                (2, 4),
                "names joint 18446744073709551615 but the robot has 6 joints",
            ),
            ("(tracker_noise: (\n radial_sigma_m: -1.0))", (2, 2), "tracker_noise: "),
            (
                "(tracker_noise: (radial_sigma_m: 1e-5,\n transverse_sigma_per_m: 1e308))",
                (2, 2),
                "transverse_sigma_per_m is 1e308, at most 1 in magnitude",
            ),
            (
                "(periodic: (harmonics: [\n  (joint_index: 1, order: 2.0, amplitude_rad: -1e308, phase_rad: 0.0)]))",
                (2, 4),
                "harmonic 1: amplitude_rad is -1e308, at most 0.1",
            ),
            ("(thermal: (\n expansion_per_k: 5.0))", (2, 2), "thermal: expansion_per_k is 5"),
            ("(drift: (\n twist_per_s: (0.0, 0.0, 0.0, 0.0, 0.0, 1e300)))", (2, 2), "drift: twist_per_s is 1e300"),
            (
                "(deflection: (links: [\n  (joint_index: 0, flexibility_per_nm2: (1e-7, 2e-7)),\n  (joint_index: 7, flexibility_per_nm2: (0.0, 0.0))]))",
                (3, 4),
                "deflection: link 2: ",
            ),
            (
                "(deflection: (links: [\n  (joint_index: 1, flexibility_per_nm2: (1e-7, 5.0))]))",
                (2, 4),
                "link 1: flexibility_per_nm2 is 5, at most 0.01",
            ),
            (
                "(coupling: (terms: [(joint_index: 2, amplitude_rad: 1e-3,\n factors: [(source_joint_index: 2, order: 1.0, phase_rad: 0.0)])]))",
                (1, 22),
                "coupling: term 1: ",
            ),
        ] {
            let e = check(text).expect_err(text);
            let Some(CommonKind::RonFormat { message }) = e.kind::<CommonKind>() else { panic!("{text}: {e:?}") };
            let place = e.place().expect("a RON error has a place");
            assert_eq!((place.file(), place.position()), ("e.ron", Some(position)), "{text}: {message}");
            assert!(message.contains(words), "{message}");
        }
    }

    #[test]
    fn effects_that_need_the_dynamics_are_refused_for_a_robot_without() {
        let mut robot = testkit::robot("irb4400.ron");
        robot.dynamics = None;
        let text = "(\n  compliance: ())";
        let effects = parse_effects(text, "e.ron").unwrap();
        let message = check_effects(&effects, &robot, text, "e.ron").unwrap_err().to_string();
        assert!(message.starts_with("e.ron:2:3: compliance: needs the robot's masses"), "{message}");
        let text = "(\n  deflection: (links: [(joint_index: 0, flexibility_per_nm2: (1e-7, 1e-7))]))";
        let effects = parse_effects(text, "e.ron").unwrap();
        let message = check_effects(&effects, &robot, text, "e.ron").unwrap_err().to_string();
        assert!(message.starts_with("e.ron:2:3: deflection: needs the robot's link masses"), "{message}");
        assert!(message.contains("`<inertial>` on every moving link of a URDF"), "{message}");
    }

    #[test]
    fn compliance_is_refused_for_masses_without_stiffness_and_a_deflection_is_taken() {
        let mut robot = testkit::robot("irb4400.ron");
        if let Some(dynamics) = &mut robot.dynamics {
            dynamics.stiffness_nm_per_rad.clear();
        }
        let text = "(\n  compliance: ())";
        let effects = parse_effects(text, "e.ron").unwrap();
        let message = check_effects(&effects, &robot, text, "e.ron").unwrap_err().to_string();
        assert!(message.starts_with("e.ron:2:3: compliance: joint compliance needs the joint stiffness"), "{message}");
        let text = "(\n  deflection: (links: [(joint_index: 0, flexibility_per_nm2: (1e-7, 1e-7))]))";
        let effects = parse_effects(text, "e.ron").unwrap();
        check_effects(&effects, &robot, text, "e.ron").unwrap();
    }

    #[test]
    fn each_effect_reads_under_its_effects_name_and_under_its_former_field_alike() {
        let samples = [
            (EffectKind::JointCompliance, "(payload_only: true)"),
            (
                EffectKind::GearPeriodic,
                "(harmonics: [(joint_index: 1, order: 2.0, amplitude_rad: 1e-5, phase_rad: 0.0)])",
            ),
            (EffectKind::TimeDrift, "(twist_per_s: (0.0, 0.0, 0.0, 0.0, 0.0, 1e-9))"),
            (EffectKind::LinkDeflection, "(links: [(joint_index: 0, flexibility_per_nm2: (1e-7, 2e-7))])"),
            (
                EffectKind::ScrewPeriodic,
                "(harmonics: [(joint_index: 0, pitch_m: 0.01, order: 1.0, amplitude_m: 2e-5, phase_rad: 0.0)])",
            ),
        ];
        let renamed: Vec<EffectKind> = EffectKind::ALL.iter().copied().filter(|k| k.former_field().is_some()).collect();
        assert_eq!(renamed, samples.map(|(kind, _)| kind), "a sample for every kind spelt otherwise before");
        for (kind, value) in samples {
            let (field, former) = (kind.simulated_field().unwrap(), kind.former_field().unwrap());
            assert_eq!(field, kind.name(), "the file's field is the --effects name");
            let new = parse_effects(&format!("({field}: {value}, tracker_noise: ())"), "new.ron").unwrap();
            assert!(new.is_on(kind) && new.is_on(EffectKind::TrackerNoise), "{field}");
            let old = parse_effects(&format!("({former}: {value}, tracker_noise: ())"), "old.ron").unwrap();
            assert_eq!(old, new, "{former}");
            let written = ron::to_string(&new).unwrap();
            assert!(written.starts_with(&format!("({field}:")) || written.contains(&format!(",{field}:")), "{written}");
            let both = format!("(\n  {field}: {value},\n  {former}: {value})");
            let message = parse_effects(&both, "both.ron").unwrap_err().to_string();
            assert!(message.starts_with("both.ron:3:") && message.contains("duplicate"), "{message}");
        }
        // A refusal names the field as the file spells it, at its place.
        let mut robot = testkit::robot("irb4400.ron");
        robot.dynamics = None;
        for field in ["joint_compliance", "compliance"] {
            let text = format!("(\n  tracker_noise: (),\n  {field}: ())");
            let effects = parse_effects(&text, "e.ron").unwrap();
            let message = check_effects(&effects, &robot, &text, "e.ron").unwrap_err().to_string();
            assert!(message.starts_with(&format!("e.ron:3:3: {field}: needs the robot's masses")), "{message}");
        }
    }
}
