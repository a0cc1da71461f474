//! The numbers of a robot file that parsing accepts but the models cannot use: a NaN or an infinity
//! in the flange, the tool or the load data, a balancer out of its range. Each is refused at its
//! field, so that the user is sent to the line at fault (a NaN flange once surfaced as "the poses
//! are too alike to register the tracker: rank 0 of 13").

use crate::ron_position::field_position;
use crate::{Error, RobotDescription};

/// Checks the flange, the tool and the dynamics of `robot`, read from `text`.
pub(crate) fn check_values(robot: &RobotDescription, text: &str, file: &str) -> Result<(), Error> {
    let not_finite = |field: &str, index: usize, name: String, value: f64| {
        let (line, column) = field_position(text, field, index);
        let file = file.to_owned();
        if value.is_finite() {
            Error::ModelValue { file, line, column, field: name, value, limit: crate::model_check::MAX_TRANSLATION_M }
        } else {
            Error::NotFinite { file, line, column, field: name, value }
        }
    };
    // Not finite, or beyond a kilometre (in m, m/s² or rad): larger than any robot, and its
    // products overflow downstream (`model_check::MAX_TRANSLATION_M`).
    let limit = crate::model_check::MAX_TRANSLATION_M;
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
        // loadsim names the field as `counterbalance.<name>`; the file writes `<name>:`.
        let (field, message) = match &error {
            loadsim::Error::InvalidParameter { field, value } if !value.is_finite() => {
                let name = field.rsplit('.').next().unwrap_or(field);
                return Err(not_finite(name, 0, format!("counterbalance.{name}"), *value));
            }
            loadsim::Error::InvalidParameter { field, .. } => {
                (field.rsplit('.').next().unwrap_or("counterbalance"), error.to_string())
            }
            loadsim::Error::UnknownJoint { .. } => ("joint_index", error.to_string()),
            _ => ("counterbalance", error.to_string()),
        };
        // The radii-difference check names no single field: point at the first radius.
        let field = if field.contains(' ') { "anchor_radius_m" } else { field };
        let (line, column) = field_position(text, field, 0);
        return Err(Error::RonFormat { file: file.to_owned(), line, column, message });
    }
    Ok(())
}
