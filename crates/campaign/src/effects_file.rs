//! The effects file of `calib simulate --effects` (loadsim's [`Effects`] as RON): read, and checked
//! against the robot at the field at fault. loadsim checks the same values when it simulates, but
//! without a file to point at; a hostile count (`fixed_point_iterations: 1e18`) it would run for ever.

use errors::ron_position::{field_position, field_position_in, ron_options};
use errors::{Error, ErrorKind};
use loadsim::{Backlash, Effects, JointCoupling, LinkDeflection, PeriodicError, ScrewError};
use robot::RobotDescription;
use ron::Value;
use std::path::Path;

/// Largest magnitude of a joint error an effects file may give (gear and coupling amplitudes,
/// backlash half-bands), rad. Industrial transmissions err by arcminutes (3e-4 rad); 0.1 rad
/// (5.7°) is past any joint that still works, and far below where the sums of many terms could
/// overflow into a NaN pose.
pub const MAX_JOINT_ERROR_RAD: f64 = 0.1;

/// Largest amplitude of a linear axis's screw (or rack) error, m: ground ball screws err
/// periodically by a few µm per turn (ISO 3408-3's `v_2π` of class 5 to 10: 8 to 40 µm), rolled
/// screws and racks by tens of µm; a millimetre per turn is a broken drive.
pub const MAX_SCREW_ERROR_M: f64 = 1e-3;

/// Largest harmonic order (periods per joint turn): gear errors appear up to the tooth count of
/// the last stage, a few hundred; beyond 1e3 the angle `order · q` loses its digits.
pub const MAX_ORDER: f64 = 1e3;

/// Largest tracker noise, m (and m per m of range for the transverse part, rad for the
/// orientation): trackers and photogrammetry err by micrometres to a millimetre, a metre is none.
pub const MAX_NOISE: f64 = 1.0;

/// Largest thermal expansion coefficient, 1/K: engineering solids lie below 2e-4 (steel 1.2e-5,
/// aluminium 2.3e-5, plastics up to 2e-4).
pub const MAX_EXPANSION_PER_K: f64 = 1e-3;

/// Largest magnitude of a reference temperature, °C.
pub const MAX_TEMPERATURE_C: f64 = 1e4;

/// Largest drift rate per component, m/s or rad/s: a settling cell drifts by micrometres per hour;
/// a base moving a metre per second is not drifting.
pub const MAX_DRIFT_PER_S: f64 = 1.0;

/// Largest link flexibility `1/EI`, 1/(N·m²) (link deflection): an aluminium tube of 20 mm
/// diameter and 1 mm wall, too thin to carry any arm, has `EI ≈ 220 N·m²` (4.5e-3); an industrial
/// column or boom has `EI` of 1e5 to 1e7 N·m². Beyond the bound the bend is no longer small.
pub const MAX_FLEXIBILITY_PER_NM2: f64 = 1e-2;

/// Most fixed-point steps of the compliance equilibrium an effects file may ask for. Each step
/// shrinks the error by the factor `C·∂τ/∂q`, below 1e-2 for industrial arms (loadsim's
/// `JointCompliance`), so 100 steps are far past double precision; more is a typo or a hostile file.
pub const MAX_FIXED_POINT_ITERATIONS: usize = 100;

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
        Error::at_line(file.to_owned(), line as u64, column, ErrorKind::RonFormat { message })
    };
    let syntax = |e: ron::error::SpannedError| at(e.span.start.line, e.span.start.col, e.code.to_string());
    let effects: Effects = ron_options().from_str(text).map_err(syntax)?;
    let given: Value = ron_options().from_str(text).map_err(syntax)?;
    // The parsed effects written back hold every field they know, switched on or not.
    let known = ron::to_string(&effects)
        .ok()
        .and_then(|written| ron::from_str::<Value>(&written).ok())
        .ok_or_else(|| at(1, 1, "the effects do not write back as RON".into()))?;
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

/// A number as a person writes it: `1e308` rather than 309 digits.
fn short(value: f64) -> String {
    if value != 0.0 && !(1e-4..1e6).contains(&value.abs()) { format!("{value:e}") } else { format!("{value}") }
}

/// Checks `effects` against `robot`: every joint index inside the robot, every value finite and
/// within the bounds of a real cell (`MAX_…`, which also keep the simulation from overflowing
/// into NaN poses), the robot's dynamics present where an effect needs them, the compliance
/// iterations bounded ([`MAX_FIXED_POINT_ITERATIONS`]). A refusal names the field in `text` (the file `file`): the
/// list entry at fault, or the effect where the field was left out.
pub fn check_effects(effects: &Effects, robot: &RobotDescription, text: &str, file: &str) -> Result<(), Error> {
    let n = robot.joint_count();
    let at = |section: &str, field: &str, index: usize, message: String| {
        let (line, column) = field_position_in(text, section, field, index);
        Error::at_line(
            file.to_owned(),
            line as u64,
            column,
            ErrorKind::RonFormat { message: format!("{section}: {message}") },
        )
    };
    // The field a loadsim error names, as the file writes it (`thermal.reference_temp_c` → `reference_temp_c`).
    let named = |error: &loadsim::Error| match error {
        loadsim::Error::InvalidParameter { field, .. } | loadsim::Error::LengthMismatch { field, .. } => {
            field.rsplit('.').next().unwrap_or(field).to_owned()
        }
        _ => String::new(),
    };
    let needs_dynamics = [
        ("compliance", effects.compliance.is_some()),
        ("backlash", effects.backlash.is_some()),
        ("deflection", effects.deflection.is_some()),
    ];
    for (section, on) in needs_dynamics {
        if on && robot.dynamics.is_none() {
            let what = if section == "compliance" { "masses and joint stiffness" } else { "link masses" };
            let message = format!(
                "needs the robot's {what} ({} has none: a `dynamics` block in a RON robot file, or an `<inertial>` \
                 on every moving link of a URDF)",
                robot.name
            );
            return Err(at(section, section, 0, message));
        }
    }
    // A URDF's masses come without stiffness: joint compliance has nothing to deflect by.
    if effects.compliance.is_some()
        && let Some(Err(error)) = robot.dynamics.as_ref().map(|d| d.stiffness("joint compliance"))
    {
        return Err(at("compliance", "compliance", 0, error.to_string()));
    }
    if let Some(compliance) = &effects.compliance
        && compliance.fixed_point_iterations > MAX_FIXED_POINT_ITERATIONS
    {
        let message = format!(
            "fixed_point_iterations is {}, at most {MAX_FIXED_POINT_ITERATIONS} (each step gains about two digits)",
            compliance.fixed_point_iterations
        );
        return Err(at("compliance", "fixed_point_iterations", 0, message));
    }
    // A value loadsim takes (finite) but that no cell has and that can overflow the simulation.
    let beyond = |values: &[(&str, f64, f64)]| {
        values
            .iter()
            .find(|(_, value, limit)| value.abs() > *limit)
            .map(|(field, value, limit)| format!("{field} is {}, at most {limit} in magnitude", short(*value)))
    };
    if let Some(periodic) = &effects.periodic {
        for (k, h) in periodic.harmonics.iter().enumerate() {
            let alone = PeriodicError { harmonics: vec![*h] };
            let fault = alone.validate(n).err().map(|e| e.to_string()).or_else(|| {
                beyond(&[("amplitude_rad", h.amplitude_rad, MAX_JOINT_ERROR_RAD), ("order", h.order, MAX_ORDER)])
            });
            if let Some(fault) = fault {
                return Err(at("periodic", "joint_index", k, format!("harmonic {}: {fault}", k + 1)));
            }
        }
    }
    if let Some(screw) = &effects.screw {
        let prismatic: Vec<bool> = robot.joints.iter().map(|j| j.kind == robot::JointType::Prismatic).collect();
        let (low, high) = errors::PITCH_BOUNDS_MM;
        for (k, h) in screw.harmonics.iter().enumerate() {
            let alone = ScrewError { harmonics: vec![*h] };
            let fault = alone.validate(&prismatic).err().map(|e| e.to_string()).or_else(|| {
                beyond(&[("amplitude_m", h.amplitude_m, MAX_SCREW_ERROR_M), ("order", h.order, MAX_ORDER)])
            });
            let pitch_mm = h.pitch_m * 1e3;
            let fault = fault.or_else(|| {
                (!(low..=high).contains(&pitch_mm))
                    .then(|| format!("pitch_m is {}, expected {} to {} m", short(h.pitch_m), low * 1e-3, high * 1e-3))
            });
            if let Some(fault) = fault {
                return Err(at("screw", "joint_index", k, format!("harmonic {}: {fault}", k + 1)));
            }
        }
    }
    if let Some(backlash) = &effects.backlash {
        for (k, joint) in backlash.joints.iter().enumerate() {
            let alone = Backlash { joints: vec![*joint] };
            let fault = alone
                .validate(n)
                .err()
                .map(|e| e.to_string())
                .or_else(|| beyond(&[("half_band_rad", joint.half_band_rad, MAX_JOINT_ERROR_RAD)]));
            if let Some(fault) = fault {
                return Err(at("backlash", "joint_index", k, format!("entry {}: {fault}", k + 1)));
            }
        }
    }
    if let Some(deflection) = &effects.deflection {
        for (k, link) in deflection.links.iter().enumerate() {
            let alone = LinkDeflection { links: vec![*link] };
            let bounds: Vec<_> =
                link.flexibility_per_nm2.iter().map(|&f| ("flexibility_per_nm2", f, MAX_FLEXIBILITY_PER_NM2)).collect();
            let fault = alone.validate(n).err().map(|e| e.to_string()).or_else(|| beyond(&bounds));
            if let Some(fault) = fault {
                return Err(at("deflection", "joint_index", k, format!("link {}: {fault}", k + 1)));
            }
        }
    }
    if let Some(coupling) = &effects.coupling {
        for (k, term) in coupling.terms.iter().enumerate() {
            let alone = JointCoupling { terms: vec![term.clone()] };
            let mut bounds = vec![("amplitude_rad", term.amplitude_rad, MAX_JOINT_ERROR_RAD)];
            bounds.extend(term.factors.iter().map(|f| ("order", f.order, MAX_ORDER)));
            let fault = alone.validate(n).err().map(|e| e.to_string()).or_else(|| beyond(&bounds));
            if let Some(fault) = fault {
                return Err(at("coupling", "joint_index", k, format!("term {}: {fault}", k + 1)));
            }
        }
    }
    if let Some(thermal) = &effects.thermal {
        thermal.validate(n).map_err(|e| at("thermal", &named(&e), 0, e.to_string()))?;
        let mut bounds = vec![
            ("reference_temp_c", thermal.reference_temp_c, MAX_TEMPERATURE_C),
            ("expansion_per_k", thermal.expansion_per_k, MAX_EXPANSION_PER_K),
        ];
        bounds.extend(thermal.link_expansion_per_k.iter().map(|&a| ("link_expansion_per_k", a, MAX_EXPANSION_PER_K)));
        if let Some((field, fault)) = bounds.iter().find_map(|b| beyond(&[*b]).map(|f| (b.0, f))) {
            return Err(at("thermal", field, 0, fault));
        }
    }
    if let Some(drift) = &effects.drift {
        drift.validate().map_err(|e| at("drift", &named(&e), 0, e.to_string()))?;
        let bounds: Vec<_> = drift.twist_per_s.iter().map(|&v| ("twist_per_s", v, MAX_DRIFT_PER_S)).collect();
        if let Some(fault) = beyond(&bounds) {
            return Err(at("drift", "twist_per_s", 0, fault));
        }
    }
    if let Some(noise) = &effects.tracker_noise {
        noise.validate().map_err(|e| at("tracker_noise", &named(&e), 0, e.to_string()))?;
        let bounds = [
            ("radial_sigma_m", noise.radial_sigma_m, MAX_NOISE),
            ("transverse_sigma_m", noise.transverse_sigma_m, MAX_NOISE),
            ("transverse_sigma_per_m", noise.transverse_sigma_per_m, MAX_NOISE),
            ("orientation_sigma_rad", noise.orientation_sigma_rad, MAX_NOISE),
        ];
        if let Some((field, fault)) = bounds.iter().find_map(|b| beyond(&[*b]).map(|f| (b.0, f))) {
            return Err(at("tracker_noise", field, 0, fault));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use loadsim::{JointCompliance, TrackerNoise};

    #[test]
    fn an_effects_file_with_a_typo_is_refused_at_its_line() {
        let good = parse_effects("(compliance: (payload_only: true), tracker_noise: ())", "e.ron").unwrap();
        assert_eq!(good.compliance, Some(JointCompliance { payload_only: true, ..JointCompliance::default() }));
        assert_eq!(good.tracker_noise, Some(TrackerNoise::default()));
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
            assert!(matches!(e.kind(), ErrorKind::RonFormat { .. }), "{text}: {e:?}");
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
            let ErrorKind::RonFormat { message } = e.kind() else { panic!("{text}: {e:?}") };
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
}
