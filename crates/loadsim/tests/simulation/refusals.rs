//! Bad configuration is refused with the numbers that explain it.

use crate::robot::{irb4400, massless};
use loadsim::{
    BacklashModel, Counterbalance, Effects, Error, GeneratorConfig, JointComplianceModel, JointRange, Payload,
    PoseContext, SimulatedCell, ThermalModel, gravity_torque, sample_configurations,
};

#[test]
fn dynamics_with_the_wrong_link_count_is_refused() {
    let robot = irb4400();
    let mut dynamics = robot.dynamics.clone();
    dynamics.links.pop();
    let refused = gravity_torque(&robot.model, &dynamics, &[0.0; 6], 0, &Payload::default()).unwrap_err();
    assert_eq!(refused, Error::from(dynamics::Error::LengthMismatch { field: "links", given: 5, expected: 6 }));
}

#[test]
fn non_positive_stiffness_is_refused() {
    let robot = irb4400();
    let dynamics = massless(vec![1e6, 1e6, -3.0, 1e5, 1e5, 1e5]);
    let refused = gravity_torque(&robot.model, &dynamics, &[0.0; 6], 0, &Payload::default()).unwrap_err();
    assert_eq!(refused, Error::from(dynamics::Error::InvalidParameter { field: "stiffness_nm_per_rad", value: -3.0 }));
}

#[test]
fn negative_payload_is_refused() {
    let robot = irb4400();
    let refused = gravity_torque(&robot.model, &robot.dynamics, &[0.0; 6], 0, &Payload::at_tool(-1.0)).unwrap_err();
    assert_eq!(refused, Error::from(dynamics::Error::InvalidParameter { field: "payload_kg", value: -1.0 }));
}

#[test]
fn backlash_on_a_joint_the_robot_lacks_is_refused() {
    let robot = irb4400();
    let cell = SimulatedCell::new(robot.model, Some(robot.dynamics));
    let mut backlash = BacklashModel::uniform(6, 1e-5);
    backlash.joints[2].joint_index = 6;
    let effects = Effects { backlash: Some(backlash), ..Effects::default() };
    let refused = effects.true_pose(&cell, &[0.0; 6], &PoseContext::default()).unwrap_err();
    assert_eq!(
        refused,
        Error::from(dynamics::Error::UnknownJoint { field: "backlash", joint_index: 6, joint_count: 6 })
    );
}

#[test]
fn compliance_without_dynamics_is_refused() {
    let cell = SimulatedCell::new(irb4400().model, None);
    let effects = Effects { joint_compliance: Some(JointComplianceModel::default()), ..Effects::default() };
    let refused = effects.true_pose(&cell, &[0.0; 6], &PoseContext::default()).unwrap_err();
    assert_eq!(refused, Error::MissingDynamics { effect: "joint compliance" });
}

#[test]
fn compliance_on_masses_without_stiffness_is_refused_and_what_needs_masses_alone_runs() {
    let robot = irb4400();
    let dynamics = loadsim::RobotDynamics { stiffness_nm_per_rad: Vec::new(), ..robot.dynamics.clone() };
    let cell = SimulatedCell::new(robot.model, Some(dynamics));
    let effects = Effects { joint_compliance: Some(JointComplianceModel::default()), ..Effects::default() };
    let q = [0.1, 0.3, -0.2, 0.0, 0.4, 0.0];
    let refused = effects.true_pose(&cell, &q, &PoseContext::default()).unwrap_err();
    assert_eq!(refused, Error::from(dynamics::Error::MissingStiffness { effect: "joint compliance" }));
    assert!(refused.to_string().contains("stiffness_nm_per_rad"), "{refused}");
    let backlash = Effects { backlash: Some(BacklashModel::uniform(6, 1e-4)), ..Effects::default() };
    let moved = backlash.true_pose(&cell, &q, &PoseContext::default()).unwrap();
    let still = Effects::default().true_pose(&cell, &q, &PoseContext::default()).unwrap();
    assert!((moved.translation() - still.translation()).norm() > 1e-5, "the backlash did not act");
}

#[test]
fn wrong_joint_count_is_refused() {
    let cell = SimulatedCell::new(irb4400().model, None);
    let refused = Effects::default().true_pose(&cell, &[0.0; 5], &PoseContext::default()).unwrap_err();
    assert_eq!(refused, Error::Kinematics { source: poe::Error::JointCountMismatch { given: 5, expected: 6 } });
}

#[test]
fn thermal_coefficients_of_the_wrong_length_are_refused() {
    let cell = SimulatedCell::new(irb4400().model, None);
    let thermal = ThermalModel { link_expansion_per_k: vec![1e-5; 6], ..Default::default() };
    let effects = Effects { thermal: Some(thermal), ..Effects::default() };
    let refused = effects.true_pose(&cell, &[0.0; 6], &PoseContext::default()).unwrap_err();
    assert_eq!(
        refused,
        Error::from(dynamics::Error::LengthMismatch { field: "thermal.link_expansion_per_k", given: 6, expected: 7 })
    );
}

#[test]
fn a_balancer_whose_spring_can_reach_zero_length_is_refused() {
    let balancer = Counterbalance {
        joint_index: 1,
        anchor_radius_m: 0.2,
        attachment_radius_m: 0.2,
        angle_at_zero_rad: 0.0,
        force_at_zero_n: 0.0,
        stiffness_n_per_m: 1e4,
    };
    assert!(matches!(
        balancer.validate(6).map_err(Error::from),
        Err(Error::Dynamics { source: dynamics::Error::InvalidParameter { .. } })
    ));
    let elsewhere = Counterbalance { joint_index: 6, anchor_radius_m: 0.3, ..balancer };
    assert_eq!(
        elsewhere.validate(6).map_err(Error::from),
        Err(Error::from(dynamics::Error::UnknownJoint { field: "counterbalance", joint_index: 6, joint_count: 6 }))
    );
}

#[test]
fn a_joint_range_narrower_than_twice_the_margin_is_refused() {
    let robot = irb4400();
    let mut ranges = robot.ranges.clone();
    ranges[2] = JointRange { lower_rad: 0.0, upper_rad: 0.1 };
    let config = GeneratorConfig { limit_margin_rad: 0.05, ..GeneratorConfig::default() };
    let refused = sample_configurations(&robot.model, 0, &ranges, &config).unwrap_err();
    assert_eq!(refused, Error::EmptyJointRange { joint_index: 2, lower_rad: 0.0, upper_rad: 0.1, margin_rad: 0.05 });
}
