//! The robot description file (SPEC "Robot description (RON)"): nominal zero-configuration joint
//! axes (or a DH table, `robot_dh.rs`), limits, the flange, and optionally a nominal tool and the
//! load model's data.

use crate::robot_dh::DhTable;
use crate::urdf_chain::{ChainEnds, UrdfDocument};
use errors::Error;
use errors::ron_position::{field_position, ron_options};
use lie::{Matrix3, SE3, SO3, Vector3};
use poe::{JointAxis, JointKind, LocalPoe};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Whether a joint turns or slides, as written in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum JointType {
    /// Rotation about the axis; limits in degrees.
    Revolute,
    /// Translation along the axis; limits in metres.
    Prismatic,
}

/// One joint at the zero configuration, base frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDescription {
    /// Revolute or prismatic.
    pub kind: JointType,
    /// Unit direction of the axis.
    pub axis: [f64; 3],
    /// A point on the axis, metres.
    pub point: [f64; 3],
    /// Limits of a revolute joint, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits_deg: Option<(f64, f64)>,
    /// Limits of a prismatic joint, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits_m: Option<(f64, f64)>,
    /// Radians (metres) the joint moves per unit of its value, 1 unless given: the summed motion
    /// of the stages one motor drives, where a URDF's mimic joints are folded into their actuated
    /// joint ([`FoldedJoint`]). The limits are the joint value's.
    #[serde(default = "unit_scale", skip_serializing_if = "is_unit_scale")]
    pub scale: f64,
}

fn unit_scale() -> f64 {
    1.0
}

#[allow(clippy::trivially_copy_pass_by_ref)] // serde's `skip_serializing_if` passes a reference
fn is_unit_scale(scale: &f64) -> bool {
    *scale == 1.0
}

/// The range of a joint's `scale`: no stage train moves a thousand times its motor's travel, or a
/// thousandth of it; beyond these a scale is a typing error, and one near 0 a joint that does not move.
pub const SCALE_BOUNDS: (f64, f64) = (1e-3, 1e3);

/// Whether a scale is finite and within [`SCALE_BOUNDS`].
pub fn scale_in_bounds(scale: f64) -> bool {
    scale.is_finite() && (SCALE_BOUNDS.0..=SCALE_BOUNDS.1).contains(&scale)
}

/// A URDF joint that follows the actuated joint of a folded joint (`<mimic>`), as written there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MimicStage {
    /// The URDF joint's name.
    pub joint: String,
    /// Its `multiplier`.
    pub multiplier: f64,
    /// Its `offset` (radians or metres), folded into the fixed transforms.
    pub offset: f64,
}

/// A joint of the description that stands for several URDF joints moved by one motor: an actuated
/// joint and the mimic joints that follow it, separated by fixed joints only, whose motions add
/// (parallel translations, or rotations about one line). Only the sum of their motions is seen:
/// how it splits between the stages cannot be identified.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FoldedJoint {
    /// The description's joint, 1-based.
    pub joint: usize,
    /// The actuated URDF joint: the joint value is its value.
    pub actuated: String,
    /// The URDF joints that follow it.
    pub stages: Vec<MimicStage>,
    /// The summed motion per unit of the joint value (the joint's `scale`).
    pub scale: f64,
}

impl std::fmt::Display for FoldedJoint {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let stages: Vec<String> =
            self.stages.iter().map(|s| format!("'{}' (multiplier {})", s.joint, s.multiplier)).collect();
        write!(
            f,
            "joint {} is URDF joint '{}' with its mimic joint(s) {}, together moving {} times the joint value: only \
             their summed motion is observed, how it splits between the stages (and each stage's own axis) cannot \
             be identified; the calibration corrects the combined axis, the multipliers are kept as written",
            self.joint,
            self.actuated,
            stages.join(", "),
            self.scale
        )
    }
}

/// The flange at the zero configuration: its origin and two of its axes, base frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FlangeDescription {
    /// Origin, metres.
    pub position: [f64; 3],
    /// Its x axis (unit, perpendicular to `z_axis`).
    pub x_axis: [f64; 3],
    /// Its z axis, usually out of the wrist (unit).
    pub z_axis: [f64; 3],
}

/// A robot description as read from `fixtures/robots/<name>.ron`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "Robot", deny_unknown_fields)]
pub struct RobotDescription {
    /// Human-readable name.
    pub name: String,
    /// The joints, base first.
    pub joints: Vec<JointDescription>,
    /// The flange at the zero configuration.
    pub flange: FlangeDescription,
    /// Nominal tool point in the flange frame, metres (the measured point's design position).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tool: Option<[f64; 3]>,
    /// Link masses, centres of mass and joint stiffness, for the load model.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<loadsim::RobotDynamics>,
    /// The joints that fold a URDF's mimic joints into their actuated joint (empty for a RON file).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub folded: Vec<FoldedJoint>,
}

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
    dynamics: Option<loadsim::RobotDynamics>,
}

impl RobotFile {
    fn into_description(self, text: &str, file: &str) -> Result<RobotDescription, Error> {
        let at = |field: &str, message: &str| {
            let (line, column) = field_position(text, field, 0);
            Error::RonFormat { file: file.to_owned(), line, column, message: message.to_owned() }
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

/// Largest deviation from 1 of an axis norm, or from 0 of the flange axes' dot product.
const UNIT_TOLERANCE: f64 = 1e-6;

/// Largest magnitude of a joint limit, in the joint's SI unit (rad, m). No arm turns a joint
/// 160,000 times or slides a kilometre; a joint without limits is written with limits this wide
/// or less. Beyond it the angles of a sampled or compensated pose lose their digits, and beyond
/// 1e154 rad the exponential map overflows into NaN poses (found by `cargo xtask fuzz`).
pub(crate) const MAX_LIMIT: [f64; 2] = [1e6, 1e3];

/// The limit bound of a joint kind, SI, and its unit.
pub(crate) fn limit_bound(kind: JointType) -> (f64, &'static str) {
    match kind {
        JointType::Revolute => (MAX_LIMIT[0], "rad"),
        JointType::Prismatic => (MAX_LIMIT[1], "m"),
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
            return Err(Error::RonFormat {
                file,
                line: 1,
                column: 1,
                message: "--base-link and --tip-link choose the chain of a URDF (.urdf), not of a RON robot file"
                    .into(),
            });
        }
        let text = errors::ron_position::read_text(path)?;
        Self::parse(&text, &file)
    }

    /// Parses and validates a robot description; `file` names it in errors. The kinematics may be
    /// zero-configuration axes or a DH table (turned into axes, see [`DhTable`]).
    pub fn parse(text: &str, file: &str) -> Result<Self, Error> {
        let form: RobotFile = ron_options().from_str(text).map_err(|e| Error::RonFormat {
            file: file.to_owned(),
            line: e.span.start.line,
            column: e.span.start.col,
            message: e.code.to_string(),
        })?;
        let robot = form.into_description(text, file)?;
        robot.validate(text, file)?;
        Ok(robot)
    }

    fn validate(&self, text: &str, file: &str) -> Result<(), Error> {
        let at = |field: &str, index: usize, message: String| {
            let (line, column) = field_position(text, field, index);
            Error::RonFormat { file: file.to_owned(), line, column, message }
        };
        if self.joints.is_empty() {
            return Err(at("joints", 0, "a robot needs at least one joint".into()));
        }
        crate::robot_check::check_values(self, text, file)?;
        crate::robot_check::check_chain(self, Some(text), file)?;
        let (mut deg_index, mut m_index) = (0, 0);
        for (i, joint) in self.joints.iter().enumerate() {
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
            if !joint.axis.iter().chain(&joint.point).all(|v| v.is_finite()) {
                return Err(at("axis", i, format!("joint {}: axis or point is not finite", i + 1)));
            }
            let limit = crate::MAX_TRANSLATION_M;
            if let Some(v) = joint.point.iter().find(|v| v.abs() > limit) {
                let message =
                    format!("joint {}: point coordinate {v:e} m is beyond ±{limit:e} m, larger than any robot", i + 1);
                return Err(at("point", i, message));
            }
            let (limits, field, index) = match joint.kind {
                JointType::Revolute => (joint.limits_deg, "limits_deg", &mut deg_index),
                JointType::Prismatic => (joint.limits_m, "limits_m", &mut m_index),
            };
            let other = match joint.kind {
                JointType::Revolute => joint.limits_m.map(|_| "limits_m"),
                JointType::Prismatic => joint.limits_deg.map(|_| "limits_deg"),
            };
            if let Some(other) = other {
                return Err(at("kind", i, format!("joint {}: {other} does not fit a {:?} joint", i + 1, joint.kind)));
            }
            match limits {
                None => return Err(at("kind", i, format!("joint {}: {field} is required", i + 1))),
                Some((lo, hi)) if !(lo.is_finite() && hi.is_finite() && lo < hi) => {
                    return Err(at(
                        field,
                        *index,
                        format!("joint {}: limits ({lo}, {hi}) must be finite and increasing", i + 1),
                    ));
                }
                Some((lo, hi)) => {
                    let (bound, unit) = limit_bound(joint.kind);
                    let si = if joint.kind == JointType::Revolute { 1f64.to_radians() } else { 1.0 };
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
                }
            }
        }
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
        if let Some(dynamics) = &self.dynamics {
            let n = self.joints.len();
            if dynamics.links.len() != n {
                return Err(at("links", 0, format!("{} links given, the robot has {n} joints", dynamics.links.len())));
            }
            if dynamics.stiffness_nm_per_rad.len() != n {
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
        }
        Ok(())
    }

    /// The common axis direction of a planar chain (every revolute axis parallel to it, every
    /// prismatic joint across it): its tool moves in a plane. `None` for a spatial chain.
    pub fn planar_direction(&self) -> Option<[f64; 3]> {
        crate::robot_check::planar_direction(self)
    }

    /// Number of joints.
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// The kinds of the joints, base first.
    pub fn joint_kinds(&self) -> Vec<JointKind> {
        self.joint_axes().iter().map(|axis| axis.kind).collect()
    }

    /// Joint limits in SI units (radians or metres), base first.
    pub fn limits(&self) -> Vec<(f64, f64)> {
        self.joints
            .iter()
            .map(|j| match (j.kind, j.limits_deg, j.limits_m) {
                (JointType::Revolute, Some((lo, hi)), _) => (lo.to_radians(), hi.to_radians()),
                (JointType::Prismatic, _, Some(limits)) => limits,
                _ => (f64::NEG_INFINITY, f64::INFINITY),
            })
            .collect()
    }

    /// The zero-configuration `base_from_flange` pose.
    pub fn base_from_flange_zero(&self) -> SE3 {
        let x = Vector3::from(self.flange.x_axis).normalize();
        let z = Vector3::from(self.flange.z_axis).normalize();
        let rotation = SO3::from_matrix_unchecked(Matrix3::from_columns(&[x, z.cross(&x), z]));
        SE3::new(rotation, Vector3::from(self.flange.position))
    }

    /// The zero-configuration joint axes as the kinematics crate takes them.
    pub fn joint_axes(&self) -> Vec<JointAxis> {
        self.joints
            .iter()
            .map(|joint| JointAxis {
                kind: match joint.kind {
                    JointType::Revolute => JointKind::Revolute,
                    JointType::Prismatic => JointKind::Prismatic,
                },
                direction: Vector3::from(joint.axis).normalize(),
                point: Vector3::from(joint.point),
            })
            .collect()
    }

    /// The nominal local POE model in the base frame, with one tool: the flange, or the nominal
    /// tool point if the description has one.
    pub fn nominal_model(&self) -> Result<LocalPoe, Error> {
        let mut model = LocalPoe::from_zero_configuration(&self.joint_axes(), self.base_from_flange_zero())?;
        for (joint, description) in model.joints_mut().iter_mut().zip(&self.joints) {
            joint.scale = description.scale;
        }
        if let Some(tool) = self.tool {
            let flange = model.tools()[0];
            model.set_tools(vec![flange * SE3::from_translation(Vector3::from(tool))]);
        }
        Ok(model)
    }

    /// The robot described by the file at `path`'s content, as RON text (for writing fixtures).
    pub fn to_ron(&self) -> String {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default().struct_names(true))
            .unwrap_or_else(|e| format!("// cannot serialise robot: {e}"))
    }
}
