//! The numbers of a robot file that parsing accepts but the models cannot use: a NaN or an infinity
//! in the flange, the tool or the load data, a balancer out of its range. Each is refused at its
//! field, so that the user is sent to the line at fault (a NaN flange once surfaced as "the poses
//! are too alike to register the tracker: rank 0 of 13").

use crate::ErrorKind;
use crate::RobotDescription;
use errors::ron_position::field_position;
use errors::{CommonKind, Error, Place};

/// Checks the flange, the tool and the dynamics of `robot`, read from `text`.
pub(crate) fn check_values(robot: &RobotDescription, text: &str, file: &str) -> Result<(), Error> {
    let not_finite = |field: &str, index: usize, name: String, value: f64| {
        let (line, column) = field_position(text, field, index);
        let file = file.to_owned();
        if value.is_finite() {
            Error::at_line(
                file,
                line as u64,
                column,
                CommonKind::ModelValue { field: name, value, limit: crate::MAX_TRANSLATION_M },
            )
        } else {
            Error::at_line(file, line as u64, column, CommonKind::NotFinite { field: name, value })
        }
    };
    // Not finite, or beyond a kilometre (in m, m/s² or rad): larger than any robot, and its
    // products overflow downstream (`model_check::MAX_TRANSLATION_M`).
    let limit = crate::MAX_TRANSLATION_M;
    let first_bad = |values: &[f64]| values.iter().copied().find(|v| !v.is_finite() || v.abs() > limit);
    let flange = &robot.flange;
    for (field, values) in [("position", flange.position), ("x_axis", flange.x_axis), ("z_axis", flange.z_axis)] {
        if let Some(value) = first_bad(&values) {
            return Err(not_finite(field, 0, format!("flange.{field}"), value));
        }
    }
    if let Some(value) = robot.tool.and_then(|tool| first_bad(&tool)) {
        return Err(not_finite("tool", 0, "tool".into(), value));
    }
    let Some(dynamics) = &robot.dynamics else { return Ok(()) };
    for (k, link) in dynamics.links.iter().enumerate() {
        if let Some(value) = first_bad(&link.com_m) {
            return Err(not_finite("com_m", k, format!("links[{k}].com_m"), value));
        }
    }
    if let Some(value) = first_bad(&dynamics.gravity_m_per_s2) {
        return Err(not_finite("gravity_m_per_s2", 0, "gravity_m_per_s2".into(), value));
    }
    if let Some(balancer) = &dynamics.counterbalance
        && let Err(error) = balancer.validate(robot.joint_count())
    {
        // dynamics names the field as `counterbalance.<name>`; the file writes `<name>:`.
        let (field, message) = match &error {
            dynamics::Error::InvalidParameter { field, value } if !value.is_finite() => {
                let name = field.rsplit('.').next().unwrap_or(field);
                return Err(not_finite(name, 0, format!("counterbalance.{name}"), *value));
            }
            dynamics::Error::InvalidParameter { field, .. } => {
                (field.rsplit('.').next().unwrap_or("counterbalance"), error.to_string())
            }
            dynamics::Error::UnknownJoint { .. } => ("joint_index", error.to_string()),
            _ => ("counterbalance", error.to_string()),
        };
        // The radii-difference check names no single field: point at the first radius.
        let field = if field.contains(' ') { "anchor_radius_m" } else { field };
        let (line, column) = field_position(text, field, 0);
        return Err(Error::at_line(file.to_owned(), line as u64, column, CommonKind::RonFormat { message }));
    }
    Ok(())
}

/// Largest angle between two axes, rad, that still counts them as parallel, and largest distance
/// between their lines, m, that counts them as one line: far below any real arm's offsets (the
/// smallest on the fixtures is the UR10's 0.0922 m), far above the rounding of a DH conversion.
const SAME_LINE_TOLERANCE: [f64; 2] = [1e-9, 1e-9];

/// The first pair of consecutive joints whose motions are one: two revolute joints about the same
/// line, or two prismatic joints along the same direction. No joint between them moves one off
/// the other, so their columns of the identification Jacobian are equal at every pose and their
/// values cannot be told apart, at any singularity threshold. 1-based.
pub(crate) fn repeated_axis(robot: &RobotDescription) -> Option<(usize, usize)> {
    use lie::Vector3;
    use poe::JointKind;
    let [angle, distance] = SAME_LINE_TOLERANCE;
    robot.joints.windows(2).enumerate().find_map(|(i, pair)| {
        let (a, b) = (&pair[0], &pair[1]);
        let (da, db) = (Vector3::from(a.axis).normalize(), Vector3::from(b.axis).normalize());
        let parallel = da.cross(&db).norm() <= angle;
        let same = match (a.kind, b.kind) {
            (JointKind::Revolute, JointKind::Revolute) => {
                parallel && (Vector3::from(b.point) - Vector3::from(a.point)).cross(&da).norm() <= distance
            }
            (JointKind::Prismatic, JointKind::Prismatic) => parallel,
            _ => false,
        };
        same.then_some((i + 1, i + 2))
    })
}

/// The common direction of a planar chain: every revolute axis parallel to it and every prismatic
/// joint across it, so the tool point moves in a plane and 3-D positions cannot be drawn (a
/// simulation) or its out-of-plane placement identified. `None` for a spatial chain.
pub(crate) fn planar_direction(robot: &RobotDescription) -> Option<[f64; 3]> {
    use lie::Vector3;
    use poe::JointKind;
    let [angle, _] = SAME_LINE_TOLERANCE;
    let first = robot.joints.iter().find(|j| j.kind == JointKind::Revolute)?;
    let d = Vector3::from(first.axis).normalize();
    robot
        .joints
        .iter()
        .all(|j| {
            let axis = Vector3::from(j.axis).normalize();
            match j.kind {
                JointKind::Revolute => axis.cross(&d).norm() <= angle,
                JointKind::Prismatic => axis.dot(&d).abs() <= angle,
            }
        })
        .then_some([d.x, d.y, d.z])
}

/// [`repeated_axis`] as the refusal of the file `file` (`text` for a RON file's position).
pub(crate) fn check_chain(robot: &RobotDescription, text: Option<&str>, file: &str) -> Result<(), Error> {
    let Some((first, second)) = repeated_axis(robot) else { return Ok(()) };
    // A RON file's refusal is placed at the second joint's axis; another file's names the file.
    let place = match text.map(|text| field_position(text, "axis", second - 1)) {
        Some((line, column)) => Place::new(file, line as u64, column),
        None => Place::in_file(file),
    };
    let joint = &robot.joints[second - 1];
    Err(Error::at(
        place,
        ErrorKind::RepeatedJointAxis {
            first,
            second,
            revolute: joint.kind == poe::JointKind::Revolute,
            axis: joint.axis,
            point: joint.point,
        },
    ))
}

impl RobotDescription {
    /// The common axis direction of a planar chain (every revolute axis parallel to it, every
    /// prismatic joint across it): its tool moves in a plane. `None` for a spatial chain.
    pub fn planar_direction(&self) -> Option<[f64; 3]> {
        planar_direction(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const TWO_COAXIAL: &str = r#"Robot(
    name: "two coaxial",
    joints: [
        (kind: Revolute, axis: (0.0, 0.0, 1.0), point: (0.0, 0.0, 0.0), limits_deg: (-90.0, 90.0)),
        (kind: Revolute, axis: (0.0, 0.0, -1.0), point: (0.0, 0.0, 0.4), limits_deg: (-90.0, 90.0)),
        (kind: Revolute, axis: (0.0, 1.0, 0.0), point: (0.0, 0.0, 0.5), limits_deg: (-90.0, 90.0)),
    ],
    flange: (position: (0.3, 0.0, 0.5), x_axis: (0.0, 0.0, -1.0), z_axis: (1.0, 0.0, 0.0)),
)"#;

    #[test]
    fn two_consecutive_joints_about_one_line_are_refused_at_the_second() {
        let error = RobotDescription::parse(TWO_COAXIAL, "coaxial.ron").unwrap_err();
        let message = error.to_string();
        assert!(
            matches!(error.kind::<ErrorKind>(), Some(ErrorKind::RepeatedJointAxis { first: 1, second: 2, .. }))
                && matches!(error.position(), Some((5, _))),
            "{message}"
        );
        assert!(message.starts_with("coaxial.ron:5:"), "{message}");
        assert!(message.contains("joints 1 and 2 turn about the same line"), "{message}");
    }

    #[test]
    fn parallel_but_offset_axes_and_coaxial_joints_with_one_between_are_kept() {
        // Joints 1 and 3 of the iiwa are coaxial at zero, but joint 2 moves them apart.
        for robot in ["irb4400.ron", "ur10.ron", "iiwa7.ron"] {
            let path = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/robots").join(robot);
            let robot = RobotDescription::read(&path).unwrap();
            assert_eq!((repeated_axis(&robot), planar_direction(&robot)), (None, None));
        }
        let offset = TWO_COAXIAL.replace("point: (0.0, 0.0, 0.4)", "point: (0.1, 0.0, 0.4)");
        assert!(RobotDescription::parse(&offset, "offset.ron").is_ok());
    }

    #[test]
    fn a_chain_of_parallel_revolute_axes_is_planar() {
        let planar = TWO_COAXIAL
            .replace("point: (0.0, 0.0, 0.4)", "point: (0.3, 0.0, 0.4)")
            .replace("axis: (0.0, 1.0, 0.0), point: (0.0, 0.0, 0.5)", "axis: (0.0, 0.0, 1.0), point: (0.6, 0.0, 0.5)");
        let robot = RobotDescription::parse(&planar, "planar.ron").unwrap();
        assert_eq!(planar_direction(&robot), Some([0.0, 0.0, 1.0]));
    }
}
