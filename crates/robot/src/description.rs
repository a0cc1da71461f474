//! The robot description file (SPEC "Robot description (RON)"): nominal zero-configuration joint
//! axes (or a DH table, `robot_dh.rs`), limits, the flange, and optionally a nominal tool and the
//! load model's data.

use errors::Error;
use lie::{Matrix3, SE3, SO3, Vector3};
use poe::{JointAxis, JointKind, LocalPoe};
use serde::{Deserialize, Serialize};

/// One joint at the zero configuration, base frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JointDescription {
    /// Revolute or prismatic, written `Revolute` or `Prismatic` in the file.
    pub kind: JointKind,
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
    /// A linear axis's screw lead (or its rack pinion's circumference): the travel per turn of
    /// the part whose error repeats, mm. Where given, the diagnosis offers a `screw_periodic`
    /// candidate on the joint and `--effects auto` fits it with this pitch; absent (older files,
    /// URDFs, DH tables) no such candidate is offered. Only on a prismatic joint.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch_mm: Option<f64>,
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
    /// Link masses, centres of mass and joint stiffness, for the load model (a URDF's `<inertial>`
    /// masses, without stiffness, where every joint carries one).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<dynamics::RobotDynamics>,
    /// The joints that fold a URDF's mimic joints into their actuated joint (empty for a RON file).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub folded: Vec<FoldedJoint>,
}

/// Largest magnitude of a joint limit, in the joint's SI unit (rad, m). No arm turns a joint
/// 160,000 times or slides a kilometre; a joint without limits is written with limits this wide
/// or less. Beyond it the angles of a sampled or compensated pose lose their digits, and beyond
/// 1e154 rad the exponential map overflows into NaN poses (found by `cargo xtask fuzz`).
pub(crate) const MAX_LIMIT: [f64; 2] = [1e6, 1e3];

/// The limit bound of a joint kind, SI, and its unit.
pub(crate) fn limit_bound(kind: JointKind) -> (f64, &'static str) {
    match kind {
        JointKind::Revolute => (MAX_LIMIT[0], "rad"),
        JointKind::Prismatic => (MAX_LIMIT[1], "m"),
    }
}

impl RobotDescription {
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
                (JointKind::Revolute, Some((lo, hi)), _) => (lo.to_radians(), hi.to_radians()),
                (JointKind::Prismatic, _, Some(limits)) => limits,
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
                kind: joint.kind,
                direction: Vector3::from(joint.axis).normalize(),
                point: Vector3::from(joint.point),
            })
            .collect()
    }

    /// The nominal local POE model in the base frame, with one tool: the flange, or the nominal
    /// tool point if the description has one.
    pub fn nominal_model(&self) -> Result<LocalPoe, Error> {
        let mut model = LocalPoe::from_zero_configuration(&self.joint_axes(), self.base_from_flange_zero())
            .map_err(Error::kinematics)?;
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
