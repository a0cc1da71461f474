//! Reading a robot file: RON (zero-configuration axes or a DH table) or a URDF chain, each checked
//! once where it is read.

use crate::description::limit_bound;
use crate::robot_dh::DhTable;
use crate::urdf_chain::{ChainEnds, UrdfDocument};
use crate::{FlangeDescription, JointDescription, RobotDescription, SCALE_BOUNDS, scale_in_bounds};
use errors::ron_position::{field_position, ron_options};
use errors::{CommonKind, Error};
use lie::Vector3;
use poe::JointKind;
use serde::Deserialize;
use std::path::Path;

/// Largest deviation from 1 of an axis norm, or from 0 of the flange axes' dot product.
const UNIT_TOLERANCE: f64 = 1e-6;

/// The robot file as written: the kinematics as zero-configuration axes (`joints` and `flange`) or
/// as a DH table (`dh`, and a `flange` only where it is not the last DH frame).
#[derive(Deserialize)]
#[serde(rename = "Robot", deny_unknown_fields)]
struct RobotFile {
    name: String,
    #[serde(default)]
    joints: Option<Vec<JointDescription>>,
    #[serde(default)]
    dh: Option<DhTable>,
    #[serde(default)]
    flange: Option<FlangeDescription>,
    #[serde(default)]
    tool: Option<[f64; 3]>,
    #[serde(default)]
    dynamics: Option<dynamics::RobotDynamics>,
}

impl RobotFile {
    fn into_description(self, text: &str, file: &str) -> Result<RobotDescription, Error> {
        let at = |field: &str, message: &str| {
            let (line, column) = field_position(text, field, 0);
            Error::at_line(file.to_owned(), line as u64, column, CommonKind::RonFormat { message: message.to_owned() })
        };
        let (joints, flange) = match (self.joints, self.dh) {
            (Some(_), Some(_)) => return Err(at("dh", "give the kinematics as `joints` or as a `dh` table, not both")),
            (None, None) => {
                return Err(at("name", "no kinematics: give `joints` (zero-configuration axes) or a `dh` table"));
            }
            (Some(joints), None) => match self.flange {
                Some(flange) => (joints, flange),
                None => return Err(at("joints", "`flange` is required with `joints`")),
            },
            (None, Some(table)) => {
                let (joints, last_frame) = table.zero_configuration(text, file)?;
                (joints, self.flange.unwrap_or(last_frame))
            }
        };
        Ok(RobotDescription {
            name: self.name,
            joints,
            flange,
            tool: self.tool,
            dynamics: self.dynamics,
            folded: Vec::new(),
        })
    }
}

impl RobotDescription {
    /// Reads and validates a robot description file: RON, or a URDF (`.urdf`) whose chain runs
    /// from its only root link to its only deepest leaf.
    pub fn read(path: &Path) -> Result<Self, Error> {
        Self::read_with(path, &ChainEnds::default())
    }

    /// Reads a robot description file; for a URDF, the chain between the links `ends` names
    /// (`--base-link`, `--tip-link`), which a RON file refuses.
    pub fn read_with(path: &Path, ends: &ChainEnds) -> Result<Self, Error> {
        let file = path.display().to_string();
        if path.extension().is_some_and(|e| e.eq_ignore_ascii_case("urdf")) {
            let robot = UrdfDocument::read(path)?.chain(ends)?.description();
            crate::robot_check::check_chain(&robot, None, &file)?;
            return Ok(robot);
        }
        if *ends != ChainEnds::default() {
            return Err(Error::at_line(
                file,
                1,
                1,
                CommonKind::RonFormat {
                    message: "--base-link and --tip-link choose the chain of a URDF (.urdf), not of a RON robot file"
                        .into(),
                },
            ));
        }
        let text = errors::ron_position::read_text(path)?;
        Self::parse(&text, &file)
    }

    /// Parses and validates a robot description; `file` names it in errors. The kinematics may be
    /// zero-configuration axes or a DH table (turned into axes, see [`DhTable`]).
    pub fn parse(text: &str, file: &str) -> Result<Self, Error> {
        let form: RobotFile = ron_options().from_str(text).map_err(|e| Error::ron(file, &e))?;
        let robot = form.into_description(text, file)?;
        robot.validate(text, file)?;
        Ok(robot)
    }

    /// The checks [`RobotDescription::parse`] runs, on a description kept inside another file (a
    /// model file's `robot_description`): `text` is that file's text from the description on,
    /// `file` its name; positions are counted from the start of `text`.
    pub fn check_kept(&self, text: &str, file: &str) -> Result<(), Error> {
        self.validate(text, file)
    }

    fn validate(&self, text: &str, file: &str) -> Result<(), Error> {
        let at = |field: &str, index: usize, message: String| {
            let (line, column) = field_position(text, field, index);
            Error::at_line(file.to_owned(), line as u64, column, CommonKind::RonFormat { message })
        };
        if self.joints.is_empty() {
            return Err(at("joints", 0, "a robot needs at least one joint".into()));
        }
        crate::robot_check::check_values(self, text, file)?;
        crate::robot_check::check_chain(self, Some(text), file)?;
        // The n-th `limits_deg` (or `limits_m`) in the file belongs to the n-th joint of its kind.
        let (mut deg_index, mut m_index) = (0, 0);
        for (i, joint) in self.joints.iter().enumerate() {
            self.check_joint_geometry(i, &at)?;
            let index = match joint.kind {
                JointKind::Revolute => &mut deg_index,
                JointKind::Prismatic => &mut m_index,
            };
            check_joint_limits(i, joint, index, &at)?;
        }
        self.check_flange(&at)?;
        if let Some(dynamics) = &self.dynamics {
            check_dynamics(dynamics, self.joints.len(), &at)?;
        }
        Ok(())
    }

    /// Joint `i`'s axis, scale, screw pitch and point: a unit axis, numbers in their bounds.
    fn check_joint_geometry(&self, i: usize, at: &impl Fn(&str, usize, String) -> Error) -> Result<(), Error> {
        let joint = &self.joints[i];
        let norm = Vector3::from(joint.axis).norm();
        if (norm - 1.0).abs() > UNIT_TOLERANCE {
            return Err(at("axis", i, format!("joint {}: axis has norm {norm}, expected 1", i + 1)));
        }
        if !scale_in_bounds(joint.scale) {
            let (lo, hi) = SCALE_BOUNDS;
            let message =
                format!("joint {}: scale {:e} must be a finite number from {lo:e} to {hi:e}", i + 1, joint.scale);
            let before = self.joints[..i].iter().filter(|j| j.scale != 1.0).count();
            return Err(at("scale", before, message));
        }
        if let Some(pitch) = joint.pitch_mm {
            let before = self.joints[..i].iter().filter(|j| j.pitch_mm.is_some()).count();
            let (lo, hi) = crate::PITCH_BOUNDS_MM;
            if joint.kind != JointKind::Prismatic {
                let message = format!(
                    "joint {}: pitch_mm is a linear axis's screw lead, and joint {} is {:?}",
                    i + 1,
                    i + 1,
                    joint.kind
                );
                return Err(at("pitch_mm", before, message));
            }
            if !(lo..=hi).contains(&pitch) {
                let message = format!("joint {}: pitch_mm {pitch:e} must be a number from {lo} to {hi} mm", i + 1);
                return Err(at("pitch_mm", before, message));
            }
        }
        if !joint.axis.iter().chain(&joint.point).all(|v| v.is_finite()) {
            return Err(at("axis", i, format!("joint {}: axis or point is not finite", i + 1)));
        }
        let limit = crate::MAX_TRANSLATION_M;
        if let Some(v) = joint.point.iter().find(|v| v.abs() > limit) {
            let message =
                format!("joint {}: point coordinate {v:e} m is beyond ±{limit:e} m, larger than any robot", i + 1);
            return Err(at("point", i, message));
        }
        Ok(())
    }

    /// The flange's axes: unit length and perpendicular.
    fn check_flange(&self, at: &impl Fn(&str, usize, String) -> Error) -> Result<(), Error> {
        let x = Vector3::from(self.flange.x_axis);
        let z = Vector3::from(self.flange.z_axis);
        for (name, axis) in [("x_axis", x), ("z_axis", z)] {
            if (axis.norm() - 1.0).abs() > UNIT_TOLERANCE {
                return Err(at(name, 0, format!("flange {name} has norm {}, expected 1", axis.norm())));
            }
        }
        if x.dot(&z).abs() > UNIT_TOLERANCE {
            return Err(at("x_axis", 0, format!("flange x_axis and z_axis are not perpendicular (dot {})", x.dot(&z))));
        }
        Ok(())
    }
}

/// Joint `i`'s limits: the field its kind takes (and not the other), finite, increasing and
/// within reach; `index` counts the earlier joints whose limits sit in the same field.
fn check_joint_limits(
    i: usize,
    joint: &JointDescription,
    index: &mut usize,
    at: &impl Fn(&str, usize, String) -> Error,
) -> Result<(), Error> {
    let (limits, field) = match joint.kind {
        JointKind::Revolute => (joint.limits_deg, "limits_deg"),
        JointKind::Prismatic => (joint.limits_m, "limits_m"),
    };
    let other = match joint.kind {
        JointKind::Revolute => joint.limits_m.map(|_| "limits_m"),
        JointKind::Prismatic => joint.limits_deg.map(|_| "limits_deg"),
    };
    if let Some(other) = other {
        return Err(at("kind", i, format!("joint {}: {other} does not fit a {:?} joint", i + 1, joint.kind)));
    }
    match limits {
        None => Err(at("kind", i, format!("joint {}: {field} is required", i + 1))),
        Some((lo, hi)) if !(lo.is_finite() && hi.is_finite() && lo < hi) => {
            Err(at(field, *index, format!("joint {}: limits ({lo}, {hi}) must be finite and increasing", i + 1)))
        }
        Some((lo, hi)) => {
            let (bound, unit) = limit_bound(joint.kind);
            let si = if joint.kind == JointKind::Revolute { 1f64.to_radians() } else { 1.0 };
            if lo.abs().max(hi.abs()) * si > bound {
                return Err(at(
                    field,
                    *index,
                    format!(
                        "joint {}: limits ({lo:e}, {hi:e}) reach beyond ±{bound:e} {unit}, further than any joint moves",
                        i + 1
                    ),
                ));
            }
            *index += 1;
            Ok(())
        }
    }
}

/// The dynamics section: one link per joint, stiffness (when given) one per joint and positive,
/// masses finite and not negative.
fn check_dynamics(
    dynamics: &dynamics::RobotDynamics,
    n: usize,
    at: &impl Fn(&str, usize, String) -> Error,
) -> Result<(), Error> {
    if dynamics.links.len() != n {
        return Err(at("links", 0, format!("{} links given, the robot has {n} joints", dynamics.links.len())));
    }
    // Left out (empty) where not known: compliance then cannot be simulated, nothing else needs it.
    if !dynamics.stiffness_nm_per_rad.is_empty() && dynamics.stiffness_nm_per_rad.len() != n {
        return Err(at(
            "stiffness_nm_per_rad",
            0,
            format!("{} stiffness values given, the robot has {n} joints", dynamics.stiffness_nm_per_rad.len()),
        ));
    }
    if let Some(k) = dynamics.stiffness_nm_per_rad.iter().position(|k| !(k.is_finite() && *k > 0.0)) {
        return Err(at("stiffness_nm_per_rad", 0, format!("joint {}: stiffness must be positive", k + 1)));
    }
    if let Some(k) = dynamics.links.iter().position(|l| !(l.mass_kg.is_finite() && l.mass_kg >= 0.0)) {
        return Err(at("mass_kg", k, format!("link {}: mass must be finite and not negative", k + 1)));
    }
    Ok(())
}
