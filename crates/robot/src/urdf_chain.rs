//! A URDF as a robot description (SPEC version 2, `--robot arm.urdf`): the kinematic chain from a
//! base link to a tip link, fixed joints folded in, turned exactly into zero-configuration axes.
//!
//! The file is read once, into its [`xml_outline`](crate::xml_outline), which gives every refusal
//! its line and column; `urdf_model.rs` reads the links and joints from it. The base link defaults to the one root link; the tip to the leaf with the
//! most movable joints on the way down from the base (or from the link the base hangs from by
//! fixed joints); several such leaves are ambiguous and need `--tip-link`. The chain may run up
//! through fixed joints (a base link below the root, such as the ROS-Industrial `base` frame),
//! never through a movable joint backwards. Mimic joints are folded into the joint that drives
//! them where their motions add (`urdf_mimic.rs`). The links' `<inertial>` masses become the
//! load model's data where every joint's body has one (`urdf_inertial.rs`).

use crate::ErrorKind;
use crate::urdf_inertial::{ChainMasses, LinkInertial, LinkTree, chain_masses, read_inertials};
use crate::urdf_mimic::{ChainJoint, OffChain, fold, folded_joint};
use crate::urdf_model::{UrdfJoint, UrdfJointType, UrdfRobot, read_robot};
use crate::urdf_steps::{ChainStep, StepMimic, StepMotion};
use crate::xml_outline::{Element, Position, outline};
use crate::{FlangeDescription, JointDescription, RobotDescription};
use errors::Error;
use lie::{SE3, SO3, Vector3};
use poe::JointKind;
use std::collections::{HashMap, HashSet};
use std::path::Path;

/// Which links the chain runs between; `None` picks the only candidate or refuses.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ChainEnds {
    /// The link whose frame is the robot's base frame (`--base-link`).
    pub base_link: Option<String>,
    /// The link whose frame is the flange (`--tip-link`).
    pub tip_link: Option<String>,
}

/// The chain between two links of a URDF.
#[derive(Debug, Clone, PartialEq)]
pub struct UrdfChain {
    /// The `<robot name>`.
    pub robot_name: String,
    /// The base link.
    pub base_link: String,
    /// The tip link.
    pub tip_link: String,
    /// The joints from the base link to the tip link.
    pub steps: Vec<ChainStep>,
    /// The description's joints: each actuated joint with the mimic joints folded into it.
    pub joints: Vec<ChainJoint>,
    /// The links' masses as the load model's data (no stiffness: a URDF has none), where every
    /// joint's body has an `<inertial>`.
    pub dynamics: Option<dynamics::RobotDynamics>,
    /// The joints (1-based) whose body has no `<inertial>`, for which no mass model is made.
    pub joints_without_mass: Vec<usize>,
}

/// A parsed URDF with the positions of its elements.
#[derive(Debug, Clone)]
pub struct UrdfDocument {
    file: String,
    text: String,
    robot: UrdfRobot,
    outline: Element,
    /// Each link's `<inertial>`, read from the outline so that a bad value is placed.
    inertials: HashMap<String, LinkInertial>,
    /// Indices looked up by name, so that every walk of the tree stays linear in its size (a
    /// file of 100,000 links took minutes with scans of the lists; found by `cargo xtask fuzz`).
    index: NameIndex,
}

/// The links, joints and top-level elements of a URDF by name.
#[derive(Debug, Clone, Default)]
struct NameIndex {
    links: HashSet<String>,
    /// Child link → the joint (index into `robot.joints`) it hangs from.
    parent_joint: HashMap<String, usize>,
    /// Parent link → the joints below it, in file order.
    child_joints: HashMap<String, Vec<usize>>,
    /// Joint name → its index into `robot.joints`.
    joints: HashMap<String, usize>,
    /// `(element name, name attribute)` → index among the outline's children (the first one).
    elements: HashMap<(String, String), usize>,
}

/// Largest allowed `|axis|` below which a joint axis counts as zero.
const ZERO_AXIS: f64 = 1e-9;

impl UrdfDocument {
    /// Reads and checks a URDF file.
    pub fn read(path: &Path) -> Result<Self, Error> {
        let file = path.display().to_string();
        // Bytes that are not UTF-8 are refused at their line and column, like a RON file's.
        let text = errors::ron_position::read_text(path)?;
        Self::parse(&text, &file)
    }

    /// Parses and checks a URDF; `file` names it in errors.
    pub fn parse(text: &str, file: &str) -> Result<Self, Error> {
        let at = |(line, column): Position, message: String| {
            Error::at_line(file.to_owned(), line as u64, column, ErrorKind::UrdfFormat { message })
        };
        let root = outline(text).map_err(|e| at(e.position, e.message))?;
        if root.name != "robot" {
            return Err(at(root.position, format!("the root element is <{}>, a URDF's is <robot>", root.name)));
        }
        if let Some(xacro) = find(&root, &|e| {
            e.name.starts_with("xacro:") || e.attributes.iter().any(|(n, _)| n.starts_with("xmlns:xacro"))
        }) {
            return Err(at(xacro.position, "a xacro file: expand it first (`xacro arm.urdf.xacro > arm.urdf`)".into()));
        }
        let inertials = read_inertials(&root, file)?;
        let robot = read_robot(&root, text).map_err(|(position, message)| at(position, message))?;
        let mut document = Self {
            file: file.to_owned(),
            text: text.to_owned(),
            robot,
            outline: root,
            inertials,
            index: NameIndex::default(),
        };
        document.check_structure()?;
        Ok(document)
    }

    /// The file name used in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// The text as read.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The root element `<robot>`.
    pub fn root(&self) -> &Element {
        &self.outline
    }

    /// The parsed robot.
    pub fn robot(&self) -> &UrdfRobot {
        &self.robot
    }

    /// The top-level element `<kind name="name">` of the outline.
    pub fn element(&self, kind: &str, name: &str) -> Option<&Element> {
        let index = self.index.elements.get(&(kind.to_owned(), name.to_owned()))?;
        self.outline.children.get(*index)
    }

    /// An error at the element `<kind name="name">` (or at `<robot>` if there is none).
    pub fn error_at(&self, kind: &str, name: &str, message: String) -> Error {
        let (line, column) = self.element(kind, name).map_or(self.outline.position, |e| e.position);
        Error::at_line(self.file.clone(), line as u64, column, ErrorKind::UrdfFormat { message })
    }

    /// Checks names (present, unique, joints naming defined links, one parent per link) and
    /// builds the name index.
    fn check_structure(&mut self) -> Result<(), Error> {
        let mut index = NameIndex::default();
        for (k, element) in self.outline.children.iter().enumerate() {
            let kind = element.name.as_str();
            if !matches!(kind, "link" | "joint") {
                if let Some(name) = element.attribute("name") {
                    index.elements.entry((kind.to_owned(), name.to_owned())).or_insert(k);
                }
                continue;
            }
            let Some(name) = element.attribute("name") else {
                return Err(self.at(element.position, format!("<{kind}> has no name")));
            };
            if index.elements.insert((kind.to_owned(), name.to_owned()), k).is_some() {
                return Err(self.at(element.position, format!("a second {kind} named '{name}'")));
            }
        }
        index.links = self.robot.links.iter().map(|l| l.name.clone()).collect();
        for (j, (joint, element)) in
            self.robot.joints.iter().zip(self.outline.children.iter().filter(|e| e.name == "joint")).enumerate()
        {
            for link in [&joint.parent, &joint.child] {
                if !index.links.contains(link) {
                    return Err(self.at(
                        element.position,
                        format!("joint '{}' names link '{link}', which is not defined", joint.name),
                    ));
                }
            }
            if let Some(other) = index.parent_joint.insert(joint.child.clone(), j) {
                let other = &self.robot.joints[other].name;
                return Err(self.at(
                    element.position,
                    format!("link '{}' is the child of joints '{other}' and '{}'", joint.child, joint.name),
                ));
            }
            index.child_joints.entry(joint.parent.clone()).or_default().push(j);
            index.joints.insert(joint.name.clone(), j);
        }
        self.index = index;
        Ok(())
    }

    fn at(&self, (line, column): Position, message: String) -> Error {
        Error::at_line(self.file.clone(), line as u64, column, ErrorKind::UrdfFormat { message })
    }

    /// The joint of which `link` is the child.
    fn parent_joint(&self, link: &str) -> Option<&UrdfJoint> {
        self.index.parent_joint.get(link).and_then(|&j| self.robot.joints.get(j))
    }

    fn link_exists(&self, link: &str, flag: &str) -> Result<(), Error> {
        if self.index.links.contains(link) {
            return Ok(());
        }
        let known: Vec<&str> = self.robot.links.iter().map(|l| l.name.as_str()).collect();
        Err(self.at(self.outline.position, format!("{flag}: no link named '{link}' (links: {})", known.join(", "))))
    }

    /// The chain between the links `ends` names (or the only candidates).
    pub fn chain(&self, ends: &ChainEnds) -> Result<UrdfChain, Error> {
        let (base, tip) = self.chain_ends(ends)?;
        let (steps, from_base) = self.steps_between(&base, &tip)?;
        let frames = link_frames(&steps);
        let off_chain = self.off_chain_drivers(&steps, &from_base, &base, &tip)?;
        let joints = fold(&steps, &frames, &off_chain).map_err(|refusal| {
            let name = &steps[refusal.step].joint;
            let element = self.element("joint", name);
            let (line, column) =
                element.and_then(|e| e.child("mimic")).or(element).map_or(self.outline.position, |e| e.position);
            self.at((line, column), format!("mimic joint '{name}': {}", refusal.message))
        })?;
        let (dynamics, joints_without_mass) = match chain_masses(&steps, &joints, &frames, self)? {
            ChainMasses::Known(dynamics) => (Some(dynamics), Vec::new()),
            ChainMasses::Missing(joints) => (None, joints),
        };
        Ok(UrdfChain {
            robot_name: self.robot.name.clone(),
            base_link: base,
            tip_link: tip,
            steps,
            joints,
            dynamics,
            joints_without_mass,
        })
    }

    /// The base and tip links: those `ends` names, checked, or the root and its deepest leaf.
    fn chain_ends(&self, ends: &ChainEnds) -> Result<(String, String), Error> {
        let base = match &ends.base_link {
            Some(base) => {
                self.link_exists(base, "--base-link")?;
                base.clone()
            }
            None => self.root_link()?,
        };
        let tip = match &ends.tip_link {
            Some(tip) => {
                self.link_exists(tip, "--tip-link")?;
                tip.clone()
            }
            None => self.deepest_leaf(&self.fixed_top(&base), &base)?,
        };
        Ok((base, tip))
    }

    /// `from` and its ancestors, nearest first, as a path and as a set (a loop ends the path).
    fn ancestors(&self, from: &str) -> (Vec<String>, HashSet<String>) {
        let mut path = vec![from.to_owned()];
        let mut on_path: HashSet<String> = path.iter().cloned().collect();
        while let Some(joint) = self.parent_joint(path.last().map_or("", String::as_str)) {
            if !on_path.insert(joint.parent.clone()) {
                break;
            }
            path.push(joint.parent.clone());
        }
        (path, on_path)
    }

    /// The steps from `base` up to where its ancestors meet the tip's, then down to `tip`, with
    /// the base link and its ancestors; refused when no chain joins them or none of its joints moves.
    fn steps_between(&self, base: &str, tip: &str) -> Result<(Vec<ChainStep>, Vec<String>), Error> {
        let ((from_base, _), (from_tip, tip_links)) = (self.ancestors(base), self.ancestors(tip));
        let Some(meet) = from_base.iter().position(|l| tip_links.contains(l)) else {
            return Err(self.error_at("link", tip, format!("no chain joins base link '{base}' and tip link '{tip}'")));
        };
        let down = from_tip.iter().position(|l| *l == from_base[meet]).unwrap_or(0);
        let mut steps = Vec::new();
        for link in &from_base[..meet] {
            steps.push(self.step(link, true, base, tip)?);
        }
        for link in from_tip[..down].iter().rev() {
            steps.push(self.step(link, false, base, tip)?);
        }
        if steps.iter().all(|s| s.motion == StepMotion::Fixed) {
            return Err(self.error_at(
                "link",
                tip,
                format!("no movable joint between base link '{base}' and tip link '{tip}'"),
            ));
        }
        Ok((steps, from_base))
    }

    /// The joints the chain's mimic joints follow that are defined but not on the chain, by name:
    /// above the chain (`above` are the base link and its ancestors), of a kind that drives no
    /// stage, or beside the chain, read as a step (a bad value refused at its element).
    fn off_chain_drivers(
        &self,
        steps: &[ChainStep],
        above: &[String],
        base: &str,
        tip: &str,
    ) -> Result<HashMap<String, OffChain>, Error> {
        let on_chain: HashSet<&str> = steps.iter().map(|s| s.joint.as_str()).collect();
        let above_base: HashSet<&str> =
            above.iter().filter_map(|link| self.parent_joint(link)).map(|j| j.name.as_str()).collect();
        let mut drivers = HashMap::new();
        for mimic in steps.iter().filter_map(|s| s.mimic.as_ref()) {
            let name = mimic.joint.as_str();
            if on_chain.contains(name) || drivers.contains_key(name) {
                continue;
            }
            let Some(joint) = self.index.joints.get(name).and_then(|&j| self.robot.joints.get(j)) else { continue };
            use UrdfJointType as T;
            let driver = match joint.joint_type {
                _ if above_base.contains(name) => OffChain::AboveBase,
                T::Fixed | T::Revolute | T::Continuous | T::Prismatic => {
                    OffChain::Beside(Box::new(self.step(&joint.child, false, base, tip)?))
                }
                other => OffChain::Unsupported(other.name()),
            };
            drivers.insert(name.to_owned(), driver);
        }
        Ok(drivers)
    }

    fn root_link(&self) -> Result<String, Error> {
        let roots: Vec<&str> =
            self.robot.links.iter().map(|l| l.name.as_str()).filter(|l| self.parent_joint(l).is_none()).collect();
        match roots.as_slice() {
            [root] => Ok((*root).to_owned()),
            [] => Err(self.at(self.outline.position, "no root link: every link is a joint's child (a loop)".into())),
            [_, second, ..] => Err(self.error_at(
                "link",
                second,
                format!("several root links ({}): choose the base with --base-link", roots.join(", ")),
            )),
        }
    }

    /// The highest link reached from `link` up through fixed joints: the chain may start there.
    fn fixed_top(&self, link: &str) -> String {
        let mut top = link.to_owned();
        let mut seen = HashSet::from([top.clone()]);
        while let Some(joint) = self.parent_joint(&top).filter(|j| j.joint_type == UrdfJointType::Fixed) {
            if !seen.insert(joint.parent.clone()) {
                break;
            }
            top = joint.parent.clone();
        }
        top
    }

    /// The leaf below `top` with the most movable joints on the way (`base` names the chain's
    /// base in messages).
    fn deepest_leaf(&self, top: &str, base: &str) -> Result<String, Error> {
        let mut leaves: Vec<(String, usize)> = Vec::new();
        let mut visited: HashSet<String> = HashSet::new();
        let mut stack = vec![(top.to_owned(), 0usize)];
        while let Some((link, movable)) = stack.pop() {
            // A loop of joints (no root) would otherwise be walked for ever.
            if !visited.insert(link.clone()) {
                continue;
            }
            let below = self.index.child_joints.get(&link).map_or(&[][..], Vec::as_slice);
            let children: Vec<&UrdfJoint> = below.iter().filter_map(|&j| self.robot.joints.get(j)).collect();
            if children.is_empty() {
                leaves.push((link, movable));
            }
            for joint in children.into_iter().rev() {
                let moves = usize::from(joint.joint_type != UrdfJointType::Fixed);
                stack.push((joint.child.clone(), movable + moves));
            }
        }
        let most = leaves.iter().map(|(_, m)| *m).max().unwrap_or(0);
        let best: Vec<&str> = leaves.iter().filter(|(_, m)| *m == most).map(|(l, _)| l.as_str()).collect();
        match best.as_slice() {
            _ if most == 0 => Err(self.error_at("link", base, format!("no movable joint below base link '{base}'"))),
            [tip] => Ok((*tip).to_owned()),
            _ => Err(self.error_at(
                "link",
                base,
                format!(
                    "ambiguous chain: leaves {} below base link '{base}' each have {most} movable joints; choose one with --tip-link",
                    best.join(", ")
                ),
            )),
        }
    }

    /// The step through the joint above `link`, forward (`link` is its child) or reversed.
    fn step(&self, link: &str, reversed: bool, base: &str, tip: &str) -> Result<ChainStep, Error> {
        let joint = self
            .parent_joint(link)
            .ok_or_else(|| self.error_at("link", link, format!("link '{link}' has no parent joint")))?;
        let numbers = joint.origin.xyz.iter().chain(joint.origin.rpy.iter());
        if !numbers.chain(joint.axis.iter()).all(|v| v.is_finite()) {
            return Err(self.refuse_joint(joint, "origin and axis must be finite".into()));
        }
        let has_limit = self.element("joint", &joint.name).is_some_and(|e| e.child("limit").is_some());
        let mimic = self.step_mimic(joint)?;
        let motion = self.step_motion(joint, has_limit, mimic.is_some())?;
        if motion != StepMotion::Fixed && reversed {
            return Err(self.refuse_joint(joint, format!(
                "the chain from '{base}' to '{tip}' runs through this movable joint from child to parent; choose a base link above it"
            )));
        }
        let axis = Vector3::from(joint.axis);
        if motion != StepMotion::Fixed && axis.norm() < ZERO_AXIS {
            return Err(self.refuse_joint(joint, "the axis is zero".into()));
        }
        // Each angle brought into one turn first: the rotation is the same, and an angle such as
        // 1e308 no longer overflows the exponential map into NaN (found by `cargo xtask fuzz`).
        let [roll, pitch, yaw] = joint.origin.rpy.map(|a| a.rem_euclid(std::f64::consts::TAU));
        let origin = SE3::new(SO3::from_rpy(roll, pitch, yaw), Vector3::from(joint.origin.xyz));
        let (from_link, to_link) = if reversed {
            (joint.child.clone(), joint.parent.clone())
        } else {
            (joint.parent.clone(), joint.child.clone())
        };
        Ok(ChainStep {
            joint: joint.name.clone(),
            from_link,
            to_link,
            reversed,
            motion,
            from_to: if reversed { origin.inverse() } else { origin },
            // Scaled by its largest component before normalising: `0 -1e308 1` overflowed the norm
            // into a NaN axis (found by `cargo xtask fuzz`).
            axis: if motion == StepMotion::Fixed { Vector3::z() } else { (axis / axis.amax()).normalize() },
            mimic,
        })
    }

    /// `joint`'s refusal, placed at its element.
    fn refuse_joint(&self, joint: &UrdfJoint, message: String) -> Error {
        self.error_at("joint", &joint.name, format!("joint '{}': {message}", joint.name))
    }

    /// The joint `joint` mimics, with a finite multiplier and offset; none for a fixed joint.
    fn step_mimic(&self, joint: &UrdfJoint) -> Result<Option<StepMimic>, Error> {
        match (&joint.mimic, joint.joint_type == UrdfJointType::Fixed) {
            (Some(m), false) => {
                let (multiplier, offset) = (m.multiplier.unwrap_or(1.0), m.offset.unwrap_or(0.0));
                if !(multiplier.is_finite() && offset.is_finite()) {
                    let element = self.element("joint", &joint.name).and_then(|e| e.child("mimic"));
                    return Err(self.at(
                        element.map_or(self.outline.position, |e| e.position),
                        format!(
                            "joint '{}': mimic multiplier {multiplier} and offset {offset} must be finite",
                            joint.name
                        ),
                    ));
                }
                Ok(Some(StepMimic { joint: m.joint.clone(), multiplier, offset }))
            }
            _ => Ok(None),
        }
    }

    /// How `joint` moves, with its limits; refused for a type that cannot be calibrated or
    /// limits that are missing or out of bounds.
    fn step_motion(&self, joint: &UrdfJoint, has_limit: bool, mimic: bool) -> Result<StepMotion, Error> {
        let refuse = |message: String| self.refuse_joint(joint, message);
        // A mimic joint's limits are its motor's: where it has none, it takes the followed joint's.
        let unlimited_mimic = mimic && !has_limit;
        let (lower, upper) = (joint.limit.lower, joint.limit.upper);
        let limits = || checked_limits(joint, has_limit);
        use UrdfJointType as T;
        Ok(match joint.joint_type {
            T::Fixed => StepMotion::Fixed,
            T::Continuous => StepMotion::Revolute { limits_rad: None },
            // URDF 1.2 leaves out limits to mean none: both infinite.
            T::Revolute if has_limit && lower == f64::NEG_INFINITY && upper == f64::INFINITY => {
                StepMotion::Revolute { limits_rad: None }
            }
            T::Revolute if unlimited_mimic => StepMotion::Revolute { limits_rad: None },
            T::Revolute => StepMotion::Revolute { limits_rad: Some(limits().map_err(refuse)?) },
            T::Prismatic if unlimited_mimic => StepMotion::Prismatic { limits_m: (f64::NEG_INFINITY, f64::INFINITY) },
            T::Prismatic => StepMotion::Prismatic { limits_m: limits().map_err(refuse)? },
            other => {
                return Err(refuse(format!(
                    "{} joints cannot be calibrated (only revolute, continuous, prismatic and fixed); choose the chain's ends with --base-link/--tip-link",
                    other.name()
                )));
            }
        })
    }
}

/// `joint`'s limits: given, finite, increasing and within reach of any joint of its kind.
fn checked_limits(joint: &UrdfJoint, has_limit: bool) -> Result<(f64, f64), String> {
    let (lower, upper) = (joint.limit.lower, joint.limit.upper);
    if !has_limit {
        return Err("a <limit lower=.. upper=..> is required".into());
    }
    if !(lower.is_finite() && upper.is_finite() && lower < upper) {
        return Err(format!("limits lower {lower} upper {upper} must be finite and increasing"));
    }
    let kind = if joint.joint_type == UrdfJointType::Prismatic { JointKind::Prismatic } else { JointKind::Revolute };
    let (bound, unit) = crate::description::limit_bound(kind);
    if lower.abs().max(upper.abs()) > bound {
        return Err(format!(
            "limits lower {lower:e} upper {upper:e} reach beyond ±{bound:e} {unit}, further than any joint moves"
        ));
    }
    Ok((lower, upper))
}

impl LinkTree for UrdfDocument {
    fn inertial(&self, link: &str) -> Option<LinkInertial> {
        self.inertials.get(link).copied()
    }

    fn fixed_children(&self, link: &str) -> Result<Vec<(String, SE3)>, Error> {
        let below = self.index.child_joints.get(link).map_or(&[][..], Vec::as_slice);
        let mut children = Vec::new();
        for joint in below.iter().filter_map(|&j| self.robot.joints.get(j)) {
            if joint.joint_type != UrdfJointType::Fixed {
                continue;
            }
            if !joint.origin.xyz.iter().chain(joint.origin.rpy.iter()).all(|v| v.is_finite()) {
                let message = format!("joint '{}': origin must be finite", joint.name);
                return Err(self.error_at("joint", &joint.name, message));
            }
            let [roll, pitch, yaw] = joint.origin.rpy.map(|a| a.rem_euclid(std::f64::consts::TAU));
            let origin = SE3::new(SO3::from_rpy(roll, pitch, yaw), Vector3::from(joint.origin.xyz));
            children.push((joint.child.clone(), origin));
        }
        Ok(children)
    }
}

/// The first element, depth first, that `matches`.
fn find<'a>(element: &'a Element, matches: &dyn Fn(&Element) -> bool) -> Option<&'a Element> {
    if matches(element) {
        return Some(element);
    }
    element.children.iter().find_map(|c| find(c, matches))
}

/// `base_from_link` at the zero configuration of every step's `to_link`, in chain order: the
/// actuated joints at zero, the mimic joints at their offsets.
fn link_frames(steps: &[ChainStep]) -> Vec<SE3> {
    let mut frame = SE3::identity();
    steps
        .iter()
        .map(|step| {
            frame = frame * step.from_to * step.zero_motion();
            frame
        })
        .collect()
}

impl UrdfChain {
    /// `base_from_link` at the zero configuration of every step's `to_link`, in chain order (the
    /// actuated joints at zero, the mimic joints at their offsets).
    pub fn link_frames(&self) -> Vec<SE3> {
        link_frames(&self.steps)
    }

    /// Number of joints: the movable joints but those folded into the joint they follow.
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// The chain as a robot description: each joint's axis (the summed motion's direction, with
    /// its `scale`, where mimic joints are folded in) and a point on it (its actuated joint's child
    /// link's origin) in the base link's frame at the zero configuration, the tip link as the flange.
    pub fn description(&self) -> RobotDescription {
        let frames = self.link_frames();
        let mut joints = Vec::new();
        for joint in &self.joints {
            // The kind and limits are the actuated joint's; the point its first step's child link's
            // origin, on the summed axis (revolute stages are coaxial).
            let (step, frame) = (joint.actuated(&self.steps), frames[joint.first]);
            let (kind, limits_deg, limits_m) = match step.motion {
                StepMotion::Fixed => continue,
                StepMotion::Revolute { limits_rad } => {
                    (JointKind::Revolute, limits_rad.map(|(lo, hi)| (lo.to_degrees(), hi.to_degrees())), None)
                }
                StepMotion::Prismatic { limits_m } => (JointKind::Prismatic, None, Some(limits_m)),
            };
            joints.push(JointDescription {
                kind,
                axis: joint.direction.into(),
                point: frame.translation().into(),
                limits_deg,
                limits_m,
                scale: joint.scale,
                pitch_mm: None,
            });
        }
        let folded =
            self.joints.iter().enumerate().filter_map(|(i, joint)| folded_joint(i, joint, &self.steps)).collect();
        let flange = frames.last().copied().unwrap_or_else(SE3::identity);
        let rotation = flange.rotation().matrix();
        RobotDescription {
            name: self.robot_name.clone(),
            joints,
            flange: FlangeDescription {
                position: flange.translation().into(),
                x_axis: rotation.column(0).into_owned().into(),
                z_axis: rotation.column(2).into_owned().into(),
            },
            tool: None,
            dynamics: self.dynamics.clone(),
            folded,
        }
    }
}
