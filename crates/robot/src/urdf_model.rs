//! The parts of a URDF that a kinematic chain needs, read from the [`xml_outline`](crate::xml_outline)
//! of the file: the robot's name, its links' names, and each joint's type, parent and child links,
//! `<origin>`, `<axis>`, `<limit>` and `<mimic>`. What a calibration does not use (`<visual>`,
//! `<collision>`, `<material>`, `<transmission>`, `<gazebo>`, …) is not read, so a mesh path or a
//! colour that another tool would refuse does not stop a calibration. `<inertial>` is read apart
//! (`urdf_inertial.rs`).
//!
//! The rules are those of urdfdom, the ROS reference parser, and of `urdf-rs`, which this replaces
//! (it parsed the file a second time, through three XML crates, without positions):
//! - `<origin>` defaults to zero; `<axis>` to `1 0 0`; `xyz`, `rpy` and an axis are three numbers;
//! - URDF 1.1 (`<robot version="1.1">` and later) may give `quat_xyzw` instead of `rpy`;
//! - `<limit>`: before URDF 1.2 `lower` and `upper` default to 0 and `velocity` is required; from
//!   1.2 on an omitted `lower`/`upper` means none (−∞/+∞), `upper < lower` and a negative effort or
//!   velocity are refused;
//! - `<mimic joint=..>` with an optional `multiplier` (1) and `offset` (0).
//!
//! Every refusal names the line and column of the element, or of the attribute's value, at fault.

use crate::xml_outline::{Element, Position};

/// A joint's type (`<joint type=..>`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UrdfJointType {
    /// Rotates about its axis within limits.
    Revolute,
    /// Rotates about its axis without limits.
    Continuous,
    /// Slides along its axis.
    Prismatic,
    /// Does not move.
    Fixed,
    /// Six degrees of freedom.
    Floating,
    /// Moves in a plane.
    Planar,
    /// Three rotations.
    Spherical,
}

impl UrdfJointType {
    /// The type's name as the file writes it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Revolute => "revolute",
            Self::Continuous => "continuous",
            Self::Prismatic => "prismatic",
            Self::Fixed => "fixed",
            Self::Floating => "floating",
            Self::Planar => "planar",
            Self::Spherical => "spherical",
        }
    }

    fn parse(text: &str) -> Option<Self> {
        [Self::Revolute, Self::Continuous, Self::Prismatic, Self::Fixed, Self::Floating, Self::Planar, Self::Spherical]
            .into_iter()
            .find(|t| t.name() == text)
    }
}

/// A `<link>`: its name (its `<inertial>` is read apart).
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfLink {
    /// The link's name.
    pub name: String,
}

/// A joint's `<origin>`: the child link's frame in the parent link's.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UrdfOrigin {
    /// Translation, m.
    pub xyz: [f64; 3],
    /// Roll, pitch and yaw about the fixed x, y and z axes, rad.
    pub rpy: [f64; 3],
}

/// A joint's `<limit>` positions (rad or m); 0 where not given before URDF 1.2, ∓∞ from 1.2 on.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct UrdfLimit {
    /// Lower position limit.
    pub lower: f64,
    /// Upper position limit.
    pub upper: f64,
}

/// A joint's `<mimic>`: its position is `multiplier × joint + offset`.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfMimic {
    /// The joint followed.
    pub joint: String,
    /// Its `multiplier`, if given (1 otherwise).
    pub multiplier: Option<f64>,
    /// Its `offset`, if given (0 otherwise).
    pub offset: Option<f64>,
}

/// A `<joint>`.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfJoint {
    /// The joint's name.
    pub name: String,
    /// Its type.
    pub joint_type: UrdfJointType,
    /// The parent link's name.
    pub parent: String,
    /// The child link's name.
    pub child: String,
    /// The child link's frame in the parent's.
    pub origin: UrdfOrigin,
    /// The axis in the child link's frame (not normalised).
    pub axis: [f64; 3],
    /// The position limits (see [`UrdfLimit`]; whether a `<limit>` is there at all is the
    /// outline's to say).
    pub limit: UrdfLimit,
    /// The joint it follows, if it is a mimic joint.
    pub mimic: Option<UrdfMimic>,
}

/// The links and joints of a URDF, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfRobot {
    /// `<robot name>` ("" if none).
    pub name: String,
    /// The `<link>` elements.
    pub links: Vec<UrdfLink>,
    /// The `<joint>` elements.
    pub joints: Vec<UrdfJoint>,
}

/// A refusal: where, and why.
pub(crate) type Refusal = (Position, String);

/// A URDF version, `(major, minor)`; a missing or malformed `version` is 1.0, as in urdfdom.
fn version(root: &Element) -> (u32, u32) {
    root.attribute("version")
        .and_then(|v| {
            let (major, minor) = v.trim().split_once('.')?;
            Some((major.parse().ok()?, minor.parse().ok()?))
        })
        .unwrap_or((1, 0))
}

/// Reads the links and joints of the outline `root` (a `<robot>`) of `text`.
pub(crate) fn read_robot(root: &Element, text: &str) -> Result<UrdfRobot, Refusal> {
    let version = version(root);
    let mut links = Vec::new();
    let mut joints = Vec::new();
    for element in &root.children {
        match element.name.as_str() {
            "link" => links.push(UrdfLink { name: required(element, "name")?.to_owned() }),
            "joint" => joints.push(read_joint(element, text, version)?),
            _ => {}
        }
    }
    Ok(UrdfRobot { name: root.attribute("name").unwrap_or_default().to_owned(), links, joints })
}

fn read_joint(element: &Element, text: &str, version: (u32, u32)) -> Result<UrdfJoint, Refusal> {
    let name = required(element, "name")?.to_owned();
    let context = |what: String| format!("joint '{name}': {what}");
    let kind = required(element, "type")?;
    let joint_type = UrdfJointType::parse(kind).ok_or_else(|| {
        (
            value_position(element, text, "type"),
            context(format!(
                "type \"{kind}\" is none of revolute, continuous, prismatic, fixed, floating, planar, spherical"
            )),
        )
    })?;
    let link_of = |tag: &str| -> Result<String, Refusal> {
        let child = element.child(tag).ok_or_else(|| (element.position, context(format!("no <{tag} link=..>"))))?;
        Ok(required(child, "link")?.to_owned())
    };
    let (parent, child) = (link_of("parent")?, link_of("child")?);
    let origin = match element.child("origin") {
        None => UrdfOrigin::default(),
        Some(origin) => read_origin(origin, text, version).map_err(|(at, why)| (at, context(why)))?,
    };
    let axis = match element.child("axis") {
        None => [1.0, 0.0, 0.0],
        Some(axis) => {
            let xyz = required(axis, "xyz").map_err(|(at, why)| (at, context(why)))?;
            numbers(xyz).ok_or_else(|| (value_position(axis, text, "xyz"), context(three("axis", "xyz", xyz))))?
        }
    };
    let limit = match element.child("limit") {
        None => UrdfLimit::default(),
        Some(limit) => read_limit(limit, text, version).map_err(|(at, why)| (at, context(why)))?,
    };
    let mimic = match element.child("mimic") {
        None => None,
        Some(mimic) => {
            let number = |attribute: &str| {
                mimic.attribute(attribute).map(|v| {
                    v.trim().parse::<f64>().map_err(|_| {
                        (
                            value_position(mimic, text, attribute),
                            context(format!("<mimic {attribute}=\"{v}\"> is not a number")),
                        )
                    })
                })
            };
            Some(UrdfMimic {
                joint: required(mimic, "joint").map_err(|(at, why)| (at, context(why)))?.to_owned(),
                multiplier: number("multiplier").transpose()?,
                offset: number("offset").transpose()?,
            })
        }
    };
    Ok(UrdfJoint { name, joint_type, parent, child, origin, axis, limit, mimic })
}

fn read_origin(origin: &Element, text: &str, version: (u32, u32)) -> Result<UrdfOrigin, Refusal> {
    let triple = |attribute: &str| match origin.attribute(attribute) {
        None => Ok([0.0; 3]),
        Some(v) => numbers(v).ok_or_else(|| (value_position(origin, text, attribute), three("origin", attribute, v))),
    };
    let xyz = triple("xyz")?;
    let mut rpy = triple("rpy")?;
    // URDF 1.1 added `quat_xyzw`; older files' is ignored, as urdfdom does.
    if let (Some(quat), true) = (origin.attribute("quat_xyzw"), version >= (1, 1)) {
        let at = value_position(origin, text, "quat_xyzw");
        if origin.attribute("rpy").is_some() {
            return Err((at, "<origin> gives both rpy and quat_xyzw: give one".into()));
        }
        let values: Option<Vec<f64>> = quat.split_whitespace().map(|w| w.parse::<f64>().ok()).collect();
        let Some(Ok(values)) = values.map(<[f64; 4]>::try_from) else {
            return Err((at, format!("<origin quat_xyzw=\"{quat}\"> must be four numbers separated by spaces")));
        };
        rpy = quaternion_to_rpy(values);
    }
    Ok(UrdfOrigin { xyz, rpy })
}

fn read_limit(limit: &Element, text: &str, version: (u32, u32)) -> Result<UrdfLimit, Refusal> {
    let number = |attribute: &str| -> Result<Option<f64>, Refusal> {
        limit
            .attribute(attribute)
            .map(|v| match v.trim().parse::<f64>() {
                Ok(x) if !x.is_nan() => Ok(x),
                _ => Err((
                    value_position(limit, text, attribute),
                    format!("<limit {attribute}=\"{v}\"> is not a number"),
                )),
            })
            .transpose()
    };
    let (lower, upper) = (number("lower")?, number("upper")?);
    let (effort, velocity) = (number("effort")?, number("velocity")?);
    if version < (1, 2) {
        // urdfdom before 1.2 requires the velocity, as urdf-rs did.
        if velocity.is_none() {
            return Err((limit.position, "<limit> has no velocity (required before URDF 1.2)".into()));
        }
        return Ok(UrdfLimit { lower: lower.unwrap_or(0.0), upper: upper.unwrap_or(0.0) });
    }
    if let (Some(lower), Some(upper)) = (lower, upper)
        && upper < lower
    {
        return Err((limit.position, format!("<limit> upper {upper} is below lower {lower}")));
    }
    for (attribute, value) in [("effort", effort), ("velocity", velocity)] {
        if let Some(value) = value.filter(|v| *v < 0.0) {
            return Err((value_position(limit, text, attribute), format!("<limit> {attribute} {value} is negative")));
        }
    }
    Ok(UrdfLimit { lower: lower.unwrap_or(f64::NEG_INFINITY), upper: upper.unwrap_or(f64::INFINITY) })
}

/// The attribute's value, or a refusal at the element.
fn required<'a>(element: &'a Element, attribute: &str) -> Result<&'a str, Refusal> {
    element.attribute(attribute).ok_or_else(|| (element.position, format!("<{}> has no {attribute}", element.name)))
}

/// Three numbers separated by white space (non-finite ones included: the chain refuses them with
/// the joint's name).
pub(crate) fn numbers(text: &str) -> Option<[f64; 3]> {
    let values: Vec<f64> = text.split_whitespace().map(|w| w.parse::<f64>().ok()).collect::<Option<_>>()?;
    values.try_into().ok()
}

fn three(element: &str, attribute: &str, value: &str) -> String {
    format!("<{element} {attribute}=\"{value}\"> must be three numbers separated by spaces")
}

/// Where the value of `attribute` starts in the text (inside its quotes), or the element's position.
fn value_position(element: &Element, text: &str, attribute: &str) -> Position {
    let tag = &text[element.span.0..element.span.1.min(text.len())];
    let tag = &tag[..tag.find('>').unwrap_or(tag.len())];
    let mut from = 0;
    // `name = "…"`: the attribute's name at a word boundary, then `=` and a quote.
    while let Some(i) = tag[from..].find(attribute) {
        let start = from + i;
        let before_ok = tag[..start].chars().next_back().is_some_and(char::is_whitespace);
        let rest = tag[start + attribute.len()..].trim_start();
        if before_ok && let Some(rest) = rest.strip_prefix('=') {
            let rest = rest.trim_start();
            if rest.starts_with(['"', '\'']) {
                let offset = element.span.0 + tag.len() - rest.len() + 1;
                return line_column(text, offset);
            }
        }
        from = start + attribute.len();
    }
    element.position
}

/// 1-based line and column of a byte offset.
pub(crate) fn line_column(text: &str, offset: usize) -> Position {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

/// A quaternion (x, y, z, w) as roll, pitch, yaw, as urdfdom's `Rotation::getRPY` computes it.
fn quaternion_to_rpy([x, y, z, w]: [f64; 4]) -> [f64; 3] {
    let norm = (x * x + y * y + z * z + w * w).sqrt();
    let [x, y, z, w] = if norm > 0.0 { [x / norm, y / norm, z / norm, w / norm] } else { [0.0, 0.0, 0.0, 1.0] };
    let sin_pitch = -2.0 * (x * z - w * y);
    if sin_pitch <= -0.99999 {
        [0.0, -std::f64::consts::FRAC_PI_2, 2.0 * x.atan2(-y)]
    } else if sin_pitch >= 0.99999 {
        [0.0, std::f64::consts::FRAC_PI_2, 2.0 * (-x).atan2(y)]
    } else {
        let (sqx, sqy, sqz, sqw) = (x * x, y * y, z * z, w * w);
        [
            (2.0 * (y * z + w * x)).atan2(sqw - sqx - sqy + sqz),
            sin_pitch.asin(),
            (2.0 * (x * y + w * z)).atan2(sqw + sqx - sqy - sqz),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::xml_outline::outline;
    use lie::SO3;

    fn robot(text: &str) -> Result<UrdfRobot, Refusal> {
        read_robot(&outline(text).unwrap(), text)
    }

    const JOINT: &str = "<robot name=\"r\" VERSION>\n  <link name=\"a\"/>\n  <link name=\"b\"/>\n  <joint name=\"j\" type=\"revolute\">\n    <parent link=\"a\"/>\n    <child link=\"b\"/>\n    ORIGIN\n    LIMIT\n  </joint>\n</robot>\n";

    fn joint(version: &str, origin: &str, limit: &str) -> Result<UrdfJoint, Refusal> {
        let text = JOINT.replace("VERSION", version).replace("ORIGIN", origin).replace("LIMIT", limit);
        robot(&text).map(|r| r.joints[0].clone())
    }

    #[test]
    fn defaults_are_urdfdoms() {
        let j = joint("", "", "<limit upper=\"1\" velocity=\"1\"/>").unwrap();
        assert_eq!(
            (j.origin, j.axis, j.limit),
            (UrdfOrigin::default(), [1.0, 0.0, 0.0], UrdfLimit { lower: 0.0, upper: 1.0 })
        );
        assert_eq!((j.parent.as_str(), j.child.as_str(), j.joint_type), ("a", "b", UrdfJointType::Revolute));
        let j = joint("version=\"1.2\"", "", "<limit effort=\"3\"/>").unwrap();
        assert_eq!(j.limit, UrdfLimit { lower: f64::NEG_INFINITY, upper: f64::INFINITY });
    }

    #[test]
    fn a_quaternion_is_read_from_urdf_1_1_on_and_ignored_before() {
        let origin = "<origin quat_xyzw=\"0 0 0.3826834323650898 0.9238795325112867\"/>";
        let limit = "<limit lower=\"-1\" upper=\"1\" velocity=\"1\"/>";
        let j = joint("version=\"1.1\"", origin, limit).unwrap();
        let expected = SO3::from_rpy(0.0, 0.0, std::f64::consts::FRAC_PI_4);
        let read = SO3::from_rpy(j.origin.rpy[0], j.origin.rpy[1], j.origin.rpy[2]);
        assert!((read.matrix() - expected.matrix()).amax() < 1e-12, "{:?}", j.origin.rpy);
        assert_eq!(joint("", origin, limit).unwrap().origin.rpy, [0.0; 3]);
        let both = "<origin rpy=\"0 0 1\" quat_xyzw=\"0 0 0 1\"/>";
        assert!(joint("version=\"1.1\"", both, limit).unwrap_err().1.contains("both rpy and quat_xyzw"));
    }

    #[test]
    fn bad_values_are_refused_at_the_value() {
        let limit = "<limit lower=\"-1\" upper=\"1\" velocity=\"1\"/>";
        let (at, why) = joint("", "<origin xyz=\"0 0 x\"/>", limit).unwrap_err();
        assert_eq!(at, (7, 18), "{why}");
        assert!(why.contains("joint 'j': <origin xyz=\"0 0 x\"> must be three numbers"), "{why}");
        let (at, why) = joint("", "<origin rpy=\"0 0\"/>", limit).unwrap_err();
        assert_eq!(at, (7, 18), "{why}");
        let (at, why) = joint("", "", "<limit lower=\"a\" upper=\"1\" velocity=\"1\"/>").unwrap_err();
        assert_eq!((at, why.as_str()), ((8, 19), "joint 'j': <limit lower=\"a\"> is not a number"));
        let (at, why) = joint("", "", "<limit lower=\"-1\" upper=\"1\"/>").unwrap_err();
        assert_eq!(at, (8, 5), "{why}");
        assert!(why.contains("no velocity"), "{why}");
        let (_, why) = joint("version=\"1.2\"", "", "<limit lower=\"1\" upper=\"-1\"/>").unwrap_err();
        assert!(why.contains("upper -1 is below lower 1"), "{why}");
        let (at, why) = joint("version=\"1.2\"", "", "<limit velocity=\"-1\"/>").unwrap_err();
        assert_eq!(at, (8, 22), "{why}");
        let text = JOINT.replace("VERSION", "").replace("ORIGIN", "").replace("LIMIT", "").replace("revolute", "screw");
        let (at, why) = robot(&text).unwrap_err();
        assert_eq!(at, (4, 25), "{why}");
        assert!(why.contains("type \"screw\" is none of"), "{why}");
        let text =
            JOINT.replace("VERSION", "").replace("ORIGIN", "").replace("LIMIT", "").replace("<child link=\"b\"/>", "");
        assert_eq!(robot(&text).unwrap_err(), ((4, 3), "joint 'j': no <child link=..>".into()));
    }

    #[test]
    fn an_attribute_name_inside_another_is_not_taken_for_it() {
        let text = "<robot>\n<origin rxyz=\"1\" xyz = 'a b c'/>\n</robot>";
        let root = outline(text).unwrap();
        assert_eq!(value_position(&root.children[0], text, "xyz"), (2, 25));
        assert_eq!(value_position(&root.children[0], text, "rpy"), (2, 1));
    }
}
