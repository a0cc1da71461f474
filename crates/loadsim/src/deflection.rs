//! Link deflection: a long link (a lifting column, a boom) bends elastically under the gravity
//! wrench of everything beyond it, and the rest of the arm turns with its far end.
//!
//! The link of joint `j` runs from joint `j`'s axis point at its zero (where the link is clamped:
//! a column's foot) to joint `j + 1`'s (or to the tool for the last joint), length `L(q)`: for a
//! prismatic joint it grows with the extension. Euler–Bernoulli beam (Gere & Timoshenko,
//! *Mechanics of Materials*, cantilever table): under a tip moment `M` the tip turns by
//! `M L / EI` and moves by `M L² / 2EI`, exactly a rotation by `M L / EI` about the link's
//! midpoint; under a tip force `F` across the link the tip turns by `F L² / 2EI`, which is again
//! `L · M_mid / EI` with `M_mid = F L / 2` the moment about the midpoint (the tip then moves by
//! `F L³ / 4EI` instead of `F L³ / 3EI`: the one approximation). So the far end turns by
//!
//! `θ_a = f_a · L(q) · (e_a · M_mid(q))`, `a ∈ {x, y}`,
//!
//! about the midpoint `m(q)`, with `M_mid = Σ_{k > j} m_k (c_k − m) × g` (the links beyond and the
//! payload), `e_x, e_y` the x and y axes of joint `j`'s frame (perpendicular to its axis, turning
//! with the link) and `f_a = 1 / EI_a` the link's flexibility about each. The left twist of the
//! pose is `(m × ω, ω)`, `ω = Σ_a θ_a e_a`, linear in the flexibilities: [`link_bend`] gives the
//! twist per unit of `θ_a`, [`link_deflection_features`] the factor `L (e_a · M_mid)`.
//!
//! Bending about joint `j`'s own axis is left out: for a revolute joint it is joint compliance (a
//! beam under an end moment turning by `θ` about its midpoint is, to first order, joints `j` and
//! `j + 1` turning by `θ/2` each), and the second-order change of the moment as the arm turns is
//! neglected, as in joint compliance's first-order model.

use crate::{DynamicsNeed, EntryFault, PoseInput, RobotFacts, SimulatedCell, SimulatedEffect, beyond};
use crate::{Error, Payload, RobotDynamics, gravity::link_centres_of_mass, gravity::payload_centre_of_mass};
use lie::{Vector3, Vector6};
use poe::LocalPoe;
use serde::{Deserialize, Serialize};

/// One bending link.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BentLink {
    /// 0-based joint whose link bends (the body it moves, up to the next joint).
    pub joint_index: usize,
    /// `1 / EI` about the x and y axes of the joint's frame, 1/(N·m²). A steel tube of 200 mm
    /// diameter and 8 mm wall has `EI ≈ 4.6e6 N·m²`: 2e-7 1/(N·m²).
    pub flexibility_per_nm2: [f64; 2],
}

/// Link deflection of some links (module doc).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct LinkDeflectionModel {
    /// The links that bend.
    pub links: Vec<BentLink>,
}

/// Where link `j` is at one configuration: its midpoint, its bending axes and its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinkBend {
    /// The link's midpoint, reference frame, m.
    pub midpoint: Vector3,
    /// The x and y axes of the joint's frame after its motion, reference frame.
    pub axes: [Vector3; 2],
    /// The link's length, m.
    pub length_m: f64,
}

impl LinkBend {
    /// The left twist of a unit rotation of the link's far end about `axes[axis]` through the
    /// midpoint: `(m × e, e)`.
    pub fn unit_twist(&self, axis: usize) -> Vector6 {
        let e = self.axes[axis.min(1)];
        let v = self.midpoint.cross(&e);
        Vector6::new(v.x, v.y, v.z, e.x, e.y, e.z)
    }
}

/// The geometry of joint `joint`'s link (0-based) at `q` under `model` with tool `tool` (the far
/// end of the last joint's link).
pub fn link_bend(model: &LocalPoe, q: &[f64], tool: usize, joint: usize) -> Result<LinkBend, Error> {
    let n = model.joint_count();
    if joint >= n {
        return Err(Error::from(dynamics::Error::UnknownJoint {
            field: "link_deflection",
            joint_index: joint,
            joint_count: n,
        }));
    }
    let frames = model.frames(q)?;
    let joints = model.joints();
    let start = match joint {
        0 => joints[0].previous_from_joint_zero.translation(),
        _ => (frames[joint - 1] * joints[joint].previous_from_joint_zero).translation(),
    };
    let end = if joint + 1 < n {
        (frames[joint] * joints[joint + 1].previous_from_joint_zero).translation()
    } else {
        model.forward(q, tool)?.translation()
    };
    let rotation = frames[joint].rotation().matrix();
    Ok(LinkBend {
        midpoint: (start + end) * 0.5,
        axes: [rotation.column(0).into_owned(), rotation.column(1).into_owned()],
        length_m: (end - start).norm(),
    })
}

/// The gravity moment about `about` of the links beyond joint `joint` and the payload, N·m.
pub fn moment_beyond(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
    joint: usize,
    about: &Vector3,
) -> Result<Vector3, Error> {
    let g = Vector3::from(dynamics.gravity_m_per_s2);
    let centres = link_centres_of_mass(model, dynamics, q)?;
    let links: Vector3 =
        centres.iter().zip(&dynamics.links).skip(joint + 1).map(|(c, link)| (c - about).cross(&g) * link.mass_kg).sum();
    let carried = (payload_centre_of_mass(model, q, tool, payload)? - about).cross(&g) * payload.mass_kg;
    Ok(links + carried)
}

/// `L(q) · (e_a · M_mid(q))` for `a = x, y`, N·m²: the rotations of joint `joint`'s link end per
/// unit of its flexibilities (module doc).
pub fn link_deflection_features(
    model: &LocalPoe,
    dynamics: &RobotDynamics,
    q: &[f64],
    tool: usize,
    payload: &Payload,
    joint: usize,
) -> Result<[f64; 2], Error> {
    let bend = link_bend(model, q, tool, joint)?;
    let moment = moment_beyond(model, dynamics, q, tool, payload, joint, &bend.midpoint)?;
    Ok(bend.axes.map(|e| bend.length_m * e.dot(&moment)))
}

impl LinkDeflectionModel {
    /// Checks the links against a robot with `joint_count` joints: indices inside it,
    /// flexibilities finite and not negative.
    pub fn validate(&self, joint_count: usize) -> Result<(), Error> {
        for link in &self.links {
            if link.joint_index >= joint_count {
                return Err(Error::from(dynamics::Error::UnknownJoint {
                    field: "deflection",
                    joint_index: link.joint_index,
                    joint_count,
                }));
            }
            if let Some(&value) = link.flexibility_per_nm2.iter().find(|f| !(f.is_finite() && **f >= 0.0)) {
                return Err(Error::from(dynamics::Error::InvalidParameter {
                    field: "deflection.flexibility_per_nm2",
                    value,
                }));
            }
        }
        Ok(())
    }

    /// The left twist the bending adds to the pose at `q`, reference frame (module doc).
    pub fn twist(
        &self,
        model: &LocalPoe,
        dynamics: &RobotDynamics,
        q: &[f64],
        tool: usize,
        payload: &Payload,
    ) -> Result<Vector6, Error> {
        let mut total = Vector6::zeros();
        for link in &self.links {
            let bend = link_bend(model, q, tool, link.joint_index)?;
            let features = link_deflection_features(model, dynamics, q, tool, payload, link.joint_index)?;
            for (a, (flexibility, feature)) in link.flexibility_per_nm2.iter().zip(features).enumerate() {
                total += bend.unit_twist(a) * (flexibility * feature);
            }
        }
        Ok(total)
    }
}

/// Largest link flexibility `1/EI`, 1/(N·m²) (link deflection): an aluminium tube of 20 mm
/// diameter and 1 mm wall, too thin to carry any arm, has `EI ≈ 220 N·m²` (4.5e-3); an industrial
/// column or boom has `EI` of 1e5 to 1e7 N·m². Beyond the bound the bend is no longer small.
pub const MAX_FLEXIBILITY_PER_NM2: f64 = 1e-2;

impl SimulatedEffect for LinkDeflectionModel {
    fn validate(&self, cell: &SimulatedCell) -> Result<(), Error> {
        let n = cell.robot.joint_count();
        LinkDeflectionModel::validate(self, n)?;
        Ok(cell.dynamics_for("link deflection")?.validate(n)?)
    }

    fn needs_dynamics(&self) -> DynamicsNeed {
        DynamicsNeed::Masses
    }

    fn check_entries(&self, robot: &RobotFacts<'_>) -> Result<(), EntryFault> {
        for (k, link) in self.links.iter().enumerate() {
            let alone = LinkDeflectionModel { links: vec![*link] };
            let bounds: Vec<_> =
                link.flexibility_per_nm2.iter().map(|&f| ("flexibility_per_nm2", f, MAX_FLEXIBILITY_PER_NM2)).collect();
            let fault = LinkDeflectionModel::validate(&alone, robot.joints.len())
                .err()
                .map(|e| e.to_string())
                .or_else(|| beyond(&bounds));
            if let Some(fault) = fault {
                return Err(EntryFault::entry(k, format!("link {}: {fault}", k + 1)));
            }
        }
        Ok(())
    }

    fn pose_twist(&self, at: &PoseInput<'_>) -> Result<Option<Vector6>, Error> {
        match &at.cell.dynamics {
            Some(dynamics) => Ok(Some(self.twist(at.model, dynamics, at.q, at.cell.tool, &at.context.payload)?)),
            None => Ok(None),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Effects, LinkInertia, PoseContext, SimulatedCell};
    use lie::SE3;
    use poe::{JointAxis, JointKind};

    /// A lifting column (prismatic along z, foot at the origin, arm 1.5 m up at zero lift) with
    /// a revolute arm on it reaching 1 m out along x.
    fn column() -> (LocalPoe, RobotDynamics) {
        let axis = |kind, d: [f64; 3], p: [f64; 3]| JointAxis { kind, direction: d.into(), point: p.into() };
        let model = LocalPoe::from_zero_configuration(
            &[
                axis(JointKind::Prismatic, [0.0, 0.0, 1.0], [0.0, 0.0, 0.0]),
                axis(JointKind::Revolute, [0.0, 0.0, 1.0], [0.0, 0.0, 1.5]),
                axis(JointKind::Revolute, [0.0, 1.0, 0.0], [0.2, 0.0, 1.6]),
            ],
            SE3::from_translation(Vector3::new(1.0, 0.0, 1.6)),
        )
        .unwrap();
        let dynamics = RobotDynamics {
            links: vec![
                LinkInertia { mass_kg: 50.0, com_m: [0.0, 0.0, 0.8] },
                LinkInertia { mass_kg: 10.0, com_m: [0.1, 0.0, 1.55] },
                LinkInertia { mass_kg: 20.0, com_m: [0.6, 0.05, 1.6] },
            ],
            stiffness_nm_per_rad: vec![1e7, 1e6, 1e6],
            counterbalance: None,
            gravity_m_per_s2: crate::FLOOR_GRAVITY_M_PER_S2,
        };
        (model, dynamics)
    }

    #[test]
    fn a_column_leans_towards_its_load_and_its_lever_grows_with_the_lift() {
        let (model, dynamics) = column();
        let payload = Payload::at_tool(5.0);
        let low = link_bend(&model, &[0.0, 0.0, 0.0], 0, 0).unwrap();
        let high = link_bend(&model, &[1.0, 0.0, 0.0], 0, 0).unwrap();
        assert!((low.length_m - 1.5).abs() < 1e-12 && (high.length_m - 2.5).abs() < 1e-12);
        assert!((high.midpoint - Vector3::new(0.0, 0.0, 1.25)).norm() < 1e-12);
        // The load hangs out along +x: the moment about the column is about +y, and a positive
        // rotation about y turns the column's top towards +x, the load's side.
        let deflection =
            LinkDeflectionModel { links: vec![BentLink { joint_index: 0, flexibility_per_nm2: [2e-7, 2e-7] }] };
        let cell = SimulatedCell::new(model.clone(), Some(dynamics.clone()));
        let effects = Effects { link_deflection: Some(deflection), ..Effects::default() };
        let context = PoseContext { payload, ..PoseContext::default() };
        let sag = |lift: f64| {
            let q = [lift, 0.0, 0.0];
            let bent = effects.true_pose(&cell, &q, &context).unwrap().translation();
            bent - model.forward(&q, 0).unwrap().translation()
        };
        let (low, high) = (sag(0.0), sag(1.0));
        assert!(low.x > 0.0 && high.x > 0.0, "{low} {high}");
        // The same moment over a longer column: the top turns by L M / EI, the tool (above the
        // midpoint by more) moves further; the ratio exceeds the lengths' 2.5 / 1.5.
        assert!(high.x / low.x > 2.5 / 1.5, "{low} {high}");
    }

    #[test]
    fn the_moment_is_the_derivative_of_the_potential_in_a_rotation_about_the_midpoint() {
        // τ = −∂V/∂θ for a rotation by θ of everything beyond the link about the axis e through
        // the midpoint m: the points move by e × (c − m), so −∂V/∂θ = Σ m_k gᵀ (e × (c_k − m))
        // = e · Σ m_k (c_k − m) × g, the moment's component along e.
        let (model, dynamics) = column();
        let payload = Payload::at_tool(3.0);
        let q = [0.4, 0.7, -0.3];
        let bend = link_bend(&model, &q, 0, 0).unwrap();
        let moment = moment_beyond(&model, &dynamics, &q, 0, &payload, 0, &bend.midpoint).unwrap();
        let g = Vector3::from(dynamics.gravity_m_per_s2);
        let energy = |theta: f64, e: &Vector3| {
            let turn = SE3::from_translation(bend.midpoint)
                * SE3::new(lie::SO3::exp(&(e * theta)), Vector3::zeros())
                * SE3::from_translation(-bend.midpoint);
            let centres = link_centres_of_mass(&model, &dynamics, &q).unwrap();
            let links: f64 = centres
                .iter()
                .zip(&dynamics.links)
                .skip(1)
                .map(|(c, l)| -l.mass_kg * g.dot(&turn.transform_point(c)))
                .sum();
            let p = payload_centre_of_mass(&model, &q, 0, &payload).unwrap();
            links - payload.mass_kg * g.dot(&turn.transform_point(&p))
        };
        let h = 1e-6;
        for e in bend.axes {
            let numeric = -(energy(h, &e) - energy(-h, &e)) / (2.0 * h);
            assert!((numeric - e.dot(&moment)).abs() < 1e-6 * (1.0 + moment.norm()), "{numeric} {moment}");
        }
    }

    #[test]
    fn the_twist_is_the_derivative_of_the_pose_in_each_flexibility() {
        let (model, dynamics) = column();
        let cell = SimulatedCell::new(model.clone(), Some(dynamics.clone()));
        let context = PoseContext { payload: Payload::at_tool(4.0), ..PoseContext::default() };
        let q = [0.6, -1.1, 0.4];
        let bend = link_bend(&model, &q, 0, 0).unwrap();
        let features = link_deflection_features(&model, &dynamics, &q, 0, &context.payload, 0).unwrap();
        let rigid = model.forward(&q, 0).unwrap();
        let h = 1e-9;
        for a in 0..2 {
            let mut flexibility = [0.0; 2];
            flexibility[a] = h;
            let effects = Effects {
                link_deflection: Some(LinkDeflectionModel {
                    links: vec![BentLink { joint_index: 0, flexibility_per_nm2: flexibility }],
                }),
                ..Effects::default()
            };
            let bent = effects.true_pose(&cell, &q, &context).unwrap();
            let numeric = (bent * rigid.inverse()).log().to_vector() / h;
            let analytic = bend.unit_twist(a) * features[a];
            assert!((numeric - analytic).norm() < 1e-5 * (1.0 + analytic.norm()), "{a}: {numeric} {analytic}");
        }
    }

    #[test]
    fn a_link_beyond_the_robot_or_a_negative_flexibility_is_refused() {
        let bad_joint = LinkDeflectionModel { links: vec![BentLink { joint_index: 3, flexibility_per_nm2: [0.0; 2] }] };
        assert!(matches!(
            bad_joint.validate(3),
            Err(Error::Dynamics { source: dynamics::Error::UnknownJoint { joint_index: 3, .. } })
        ));
        let negative =
            LinkDeflectionModel { links: vec![BentLink { joint_index: 0, flexibility_per_nm2: [1e-7, -1.0] }] };
        assert!(matches!(
            negative.validate(3),
            Err(Error::Dynamics { source: dynamics::Error::InvalidParameter { .. } })
        ));
        let nan =
            LinkDeflectionModel { links: vec![BentLink { joint_index: 0, flexibility_per_nm2: [f64::NAN, 0.0] }] };
        assert!(nan.validate(3).is_err());
        let (model, _) = column();
        assert!(link_bend(&model, &[0.0; 3], 0, 3).is_err());
    }
}
