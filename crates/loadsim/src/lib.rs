//! Non-geometric error models of a serial robot: payload and gravity deflection through joint
//! compliance (the paper's ref. \[15\], Tao, Yang & Tomizuka 2013), a joint-2 spring balancer,
//! backlash, gear periodic error, a linear axis's screw (or rack) periodic error, thermal growth, base drift, link deflection, tracker noise, and a coupled joint
//! error that no diagnosis candidate models; measured joint torques; and a seeded dataset
//! generator that also draws the shapes of real campaigns (some joints fixed, payload runs with a
//! tool each).
//!
//! Every effect is a forward model with named parameters, usable alone or combined through
//! [`Effects`]. The pieces of them that the `effects` crate's regressors are built on are here
//! too, written as linear in their parameters: [`backlash_joint_regressor`],
//! [`periodic_joint_regressor`], [`thermal_regressor`], and [`gravity_regressor`] for the gravity
//! torque without known masses. The robot's masses, stiffness and balancer ([`RobotDynamics`]) are
//! the `dynamics` crate's, re-exported here.
//!
//! Conventions: SI units; twists `(v, ω)`; pose errors are left perturbations
//! `log(T' T⁻¹)^∨`; gravity torque `τ = −∂V/∂q` (the generalised force of gravity, so a joint
//! spring deflects by `+τ/k`); joint indices in parameters are 0-based.
//!
//! ```
//! use lie::{SE3, SO3, Vector3};
//! use loadsim::{Effects, JointComplianceModel, LinkInertia, Payload, PoseContext, RobotDynamics, SimulatedCell};
//! use poe::{JointAxis, JointKind, LocalPoe};
//!
//! // A one-joint arm: a horizontal axis, the tool 1 m out along x.
//! let axis = JointAxis { kind: JointKind::Revolute, direction: Vector3::y(), point: Vector3::zeros() };
//! let arm = LocalPoe::from_zero_configuration(&[axis], SE3::from_translation(Vector3::x())).unwrap();
//! let dynamics = RobotDynamics {
//!     links: vec![LinkInertia { mass_kg: 0.0, com_m: [0.0; 3] }],
//!     stiffness_nm_per_rad: vec![1e5],
//!     counterbalance: None,
//!     gravity_m_per_s2: loadsim::FLOOR_GRAVITY_M_PER_S2,
//! };
//! let cell = SimulatedCell::new(arm, Some(dynamics));
//! let effects = Effects { joint_compliance: Some(JointComplianceModel::default()), ..Effects::default() };
//! let context = PoseContext { payload: Payload::at_tool(10.0), ..PoseContext::default() };
//! let pose = effects.true_pose(&cell, &[0.0], &context).unwrap();
//! // 10 kg at 1 m: 98.1 N·m, 0.981 mrad, the tool sags by 0.981 mm.
//! assert!((pose.translation().z + 0.981e-3).abs() < 1e-6);
//! ```
#![deny(missing_docs)]

mod backlash;
mod base_tilt;
mod cell;
mod compliance;
mod coupling;
mod deflection;
mod drift;
mod effects;
mod error;
mod generator;
mod gravity;
mod gravity_regressor;
mod kinds;
mod periodic;
mod screw;
mod simulated;
mod singularity;
mod thermal;
mod torque_sensor;
mod tracker_noise;

pub use backlash::{BacklashModel, JointBacklash, backlash_joint_regressor};
pub use base_tilt::BaseTilt;
pub use cell::{PoseContext, SimulatedCell};
pub use compliance::{JointComplianceModel, MAX_FIXED_POINT_ITERATIONS, compliance_deflection, spring_torque};
pub use coupling::{CouplingFactor, CouplingModel, CouplingTerm};
pub use deflection::{
    BentLink, LinkBend, LinkDeflectionModel, MAX_FLEXIBILITY_PER_NM2, link_bend, link_deflection_features,
    moment_beyond,
};
pub use drift::{MAX_DRIFT_PER_S, TimeDriftModel};
// The robot's dynamics as robot files state them: their own crate, so that `robot` needs no simulator.
pub use dynamics::{Counterbalance, FLOOR_GRAVITY_M_PER_S2, LinkInertia, RobotDynamics, tilted_base_gravity};
pub use effects::{Effects, JointOffsets};
pub use error::Error;
pub use generator::{
    GeneratorConfig, JointRange, Sample, TemperatureProfile, generate, generate_each, sample_configurations,
};
pub use gravity::{
    Payload, gravity_torque, link_centres_of_mass, link_motions, payload_centre_of_mass, payload_gravity_torque,
    potential_energy, static_torque,
};
pub use gravity_regressor::gravity_regressor;
pub use kinds::EffectKind;
pub use periodic::{GearPeriodicModel, Harmonic, periodic_joint_regressor};
pub use screw::{MAX_SCREW_ERROR_M, ScrewHarmonic, ScrewPeriodicModel};
pub use simulated::{
    DynamicsNeed, EntryFault, MAX_JOINT_ERROR_RAD, MAX_ORDER, PoseInput, RobotFacts, SimulatedEffect, beyond, short,
};
pub use singularity::{smallest_singular_value, smallest_singular_value_of_joints, tool_point_jacobian};
pub use thermal::{MAX_EXPANSION_PER_K, MAX_TEMPERATURE_C, ThermalModel, thermal_regressor};
pub use torque_sensor::TorqueSensorNoise;
pub use tracker_noise::{MAX_NOISE, TrackerNoiseModel};
