//! A URDF's masses as the load model's data (`dynamics::RobotDynamics`): each link's `<inertial>`,
//! its `<mass value>` and the `xyz` of its `<origin>` (the centre of mass in the link's frame; the
//! `rpy` turns only the inertia tensor, which the load model does not use).
//!
//! The load model has one body per joint, the body that joint moves, with its centre of mass at
//! the zero configuration in the base frame, as a RON robot file gives it. A joint's body is every
//! link that rides on it: its child link, the links below that by fixed joints (on the chain or
//! hanging off it: a collar, a sensor, a gripper), and the links of the mimic stages folded into
//! it (`urdf_mimic.rs`), summed: the total mass at the mass-weighted centre. Each link's centre is
//! placed by its frame at the chain's zero configuration (the mimics at their offsets), so a
//! stage's mass sits where the stage is at the joint's zero: exact there and for every gravity
//! torque on the folded joint itself (the force along its axis is the total mass whatever the
//! stages' positions); elsewhere a stage's centre is off by its lag behind the summed motion along
//! the column, which moves no moment about a vertical column's axis. Links below a movable joint
//! off the chain (a gripper's fingers) are left out: where they are depends on joints the
//! measurements do not carry.
//!
//! Where a joint's body has no `<inertial>` at all, the robot has no mass model (no masses are
//! invented): the chain says which joints lack one. A URDF has no joint stiffness: the dynamics
//! carry none, so joint compliance cannot be simulated on it (`loadsim` refuses and says so), while
//! what needs the masses alone (link deflection, backlash's torque sign) can. Gravity is the floor
//! mount's, base z up (REP-103's convention for a URDF's base link).

use crate::ErrorKind;
use crate::urdf_mimic::ChainJoint;
use crate::urdf_steps::{ChainStep, StepMotion};
use crate::xml_outline::{Element, Position};
use errors::Error;
use lie::{SE3, Vector3};
use std::collections::{HashMap, HashSet};

/// The heaviest link mass a URDF may state, kg: a thousand tonnes, three orders of magnitude beyond
/// the heaviest industrial arm's moving mass (about 1 t). A sanity bound on a file, not a tuning
/// constant: beyond it a mass is a wrong unit or a broken export (1e308 kg is finite, and its
/// gravity moments overflow).
pub const MAX_LINK_MASS_KG: f64 = 1.0e6;

/// One link's `<inertial>` as read: its mass and its centre of mass in the link's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct LinkInertial {
    /// Mass, kg.
    pub mass_kg: f64,
    /// Centre of mass in the link's frame, m.
    pub com_m: Vector3,
}

/// Every `<link>`'s `<inertial>` in the outline `root` of the file `file`, by link name. A mass
/// that is not a finite number in `0 ..= MAX_LINK_MASS_KG`, a missing `<mass value>`, or an
/// `<origin>` whose `xyz` or `rpy` is not three finite numbers (a centre beyond
/// [`crate::MAX_TRANSLATION_M`]) is refused at its element's line and column.
pub(crate) fn read_inertials(root: &Element, file: &str) -> Result<HashMap<String, LinkInertial>, Error> {
    let at = |(line, column): Position, message: String| {
        Error::at_line(file.to_owned(), line as u64, column, ErrorKind::UrdfFormat { message })
    };
    let mut inertials = HashMap::new();
    for link in root.children.iter().filter(|e| e.name == "link") {
        let Some(inertial) = link.child("inertial") else { continue };
        let name = link.attribute("name").unwrap_or_default();
        let Some(mass) = inertial.child("mass") else {
            return Err(at(inertial.position, format!("link '{name}': <inertial> has no <mass value=..>")));
        };
        let value = mass.attribute("value").unwrap_or_default();
        let mass_kg = match value.trim().parse::<f64>() {
            Ok(m) if m.is_finite() && (0.0..=MAX_LINK_MASS_KG).contains(&m) => m,
            _ => {
                return Err(at(
                    mass.position,
                    format!(
                        "link '{name}': <mass value=\"{value}\"> must be a number of kilograms from 0 to {MAX_LINK_MASS_KG:e}"
                    ),
                ));
            }
        };
        let mut com_m = Vector3::zeros();
        if let Some(origin) = inertial.child("origin") {
            for attribute in ["xyz", "rpy"] {
                let Some(text) = origin.attribute(attribute) else { continue };
                let Some(values) = triple(text) else {
                    return Err(at(
                        origin.position,
                        format!(
                            "link '{name}': <inertial> <origin {attribute}=\"{text}\"> must be three finite numbers \
                             separated by spaces{}",
                            if attribute == "xyz" { ", within a kilometre" } else { "" }
                        ),
                    ));
                };
                if attribute == "xyz" && values.iter().any(|v| v.abs() > crate::MAX_TRANSLATION_M) {
                    return Err(at(
                        origin.position,
                        format!(
                            "link '{name}': <inertial> <origin xyz=\"{text}\"> is beyond {} m, further than any \
                             robot reaches",
                            crate::MAX_TRANSLATION_M
                        ),
                    ));
                }
                if attribute == "xyz" {
                    com_m = Vector3::from(values);
                }
            }
        }
        inertials.insert(name.to_owned(), LinkInertial { mass_kg, com_m });
    }
    Ok(inertials)
}

/// Three finite numbers separated by white space, every word a number.
fn triple(text: &str) -> Option<[f64; 3]> {
    crate::urdf_model::numbers(text).filter(|values| values.iter().all(|v| v.is_finite()))
}

/// The masses of a chain: the load model's data, or the joints (1-based) whose body states no
/// `<inertial>`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ChainMasses {
    /// Every joint's body has a mass.
    Known(dynamics::RobotDynamics),
    /// These joints' bodies have no `<inertial>`: no mass model.
    Missing(Vec<usize>),
}

/// Where to find the links of a URDF: each link's `<inertial>`, and the links below it by fixed
/// joints with `link_from_child` at zero.
pub(crate) trait LinkTree {
    /// The link's `<inertial>`, if it has one.
    fn inertial(&self, link: &str) -> Option<LinkInertial>;
    /// The links below `link` by fixed joints, each with `link_from_child`.
    fn fixed_children(&self, link: &str) -> Result<Vec<(String, SE3)>, Error>;
}

/// The masses of the chain `steps` (the description's `joints`, `frames` each step's
/// `base_from_to_link` at the zero configuration) in `tree` (module doc).
pub(crate) fn chain_masses(
    steps: &[ChainStep],
    joints: &[ChainJoint],
    frames: &[SE3],
    tree: &dyn LinkTree,
) -> Result<ChainMasses, Error> {
    let on_chain: HashSet<&str> = steps.iter().flat_map(|s| [s.from_link.as_str(), s.to_link.as_str()]).collect();
    // Per joint: mass, mass-weighted centre, the unweighted sum of centres and how many links state one.
    let mut bodies = vec![(0.0, Vector3::zeros(), Vector3::zeros(), 0usize); joints.len()];
    let mut carrier = None;
    let mut visited: HashSet<String> = HashSet::new();
    for (k, step) in steps.iter().enumerate() {
        if step.motion != StepMotion::Fixed {
            carrier = joints.iter().position(|j| j.first == k || j.stages.contains(&k));
        }
        let Some(body) = carrier.and_then(|i| bodies.get_mut(i)) else { continue };
        let mut stack = vec![(step.to_link.clone(), frames[k])];
        while let Some((link, base_from_link)) = stack.pop() {
            // A file whose links loop would otherwise be walked for ever.
            if !visited.insert(link.clone()) {
                continue;
            }
            if let Some(inertial) = tree.inertial(&link) {
                let centre = base_from_link.transform_point(&inertial.com_m);
                body.0 += inertial.mass_kg;
                body.1 += centre * inertial.mass_kg;
                body.2 += centre;
                body.3 += 1;
            }
            for (child, link_from_child) in tree.fixed_children(&link)? {
                if !on_chain.contains(child.as_str()) {
                    stack.push((child, base_from_link * link_from_child));
                }
            }
        }
    }
    let missing: Vec<usize> = bodies.iter().enumerate().filter(|(_, b)| b.3 == 0).map(|(i, _)| i + 1).collect();
    if !missing.is_empty() {
        return Ok(ChainMasses::Missing(missing));
    }
    let links = bodies
        .iter()
        .map(|&(mass_kg, moment, centres, count)| {
            // Massless links all: the centre is never weighed; their plain mean keeps it finite.
            let com = if mass_kg > 0.0 { moment / mass_kg } else { centres / count as f64 };
            dynamics::LinkInertia { mass_kg, com_m: com.into() }
        })
        .collect();
    Ok(ChainMasses::Known(dynamics::RobotDynamics {
        links,
        stiffness_nm_per_rad: Vec::new(),
        counterbalance: None,
        gravity_m_per_s2: dynamics::FLOOR_GRAVITY_M_PER_S2,
    }))
}
