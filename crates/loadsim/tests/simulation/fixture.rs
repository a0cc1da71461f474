//! The IRB 4400/60 load data in `fixtures/robots/irb4400.ron`: plausible, and what the comments
//! claim.

use crate::robot::{iiwa7, irb4400, random_q, with_tool};
use loadsim::{Effects, JointComplianceModel, Payload, PoseContext, RobotDynamics, SimulatedCell, gravity_torque};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

#[test]
fn irb4400_dynamics_parse_validate_and_weigh_about_seven_hundred_kilograms_moving() {
    let robot = irb4400();
    robot.dynamics.validate(6).unwrap();
    assert_eq!(robot.dynamics.moving_mass_kg(), 680.0);
    assert_eq!(robot.dynamics.gravity_m_per_s2, [0.0, 0.0, -9.81]);
}

#[test]
fn iiwa7_dynamics_parse_validate_and_weigh_what_the_toolbox_and_kukas_data_sheet_say() {
    let robot = iiwa7();
    robot.dynamics.validate(7).unwrap();
    // 19.43 kg moving of KUKA's 23.9 kg arm: the fixed base keeps the rest.
    assert!((robot.dynamics.moving_mass_kg() - 19.4348).abs() < 1e-9);
    assert_eq!(robot.dynamics.counterbalance, None);
    assert_eq!(robot.dynamics.gravity_m_per_s2, [0.0, 0.0, -9.81]);
}

#[test]
fn iiwa7_joint_2_deflection_under_five_kilograms_is_reported() {
    // A record of what the fixture implies, not a sourced bound: joints 1 and 2 moving, the arm
    // straight beyond them, 5 kg at a 0.1 m tool; the tool displacement from joint 2's compliance.
    let robot = iiwa7();
    let mut dynamics = robot.dynamics.clone();
    for (j, k) in dynamics.stiffness_nm_per_rad.iter_mut().enumerate() {
        if j != 1 {
            *k = 1e15;
        }
    }
    let cell = SimulatedCell::new(with_tool(&robot.model, 0.1), Some(dynamics));
    let effects = Effects { joint_compliance: Some(JointComplianceModel::default()), ..Effects::default() };
    let context = PoseContext { payload: Payload::at_tool(5.0), ..PoseContext::default() };
    let q = [0.0, std::f64::consts::FRAC_PI_2, 0.0, 0.0, 0.0, 0.0, 0.0];
    let moved = effects.true_pose(&cell, &q, &context).unwrap().translation();
    let nominal = cell.robot.forward(&q, 0).unwrap().translation();
    let sag_mm = (moved - nominal).norm() * 1e3;
    println!("iiwa 7, arm horizontal, 5 kg: joint 2 compliance moves the tool {sag_mm:.2} mm");
    assert!((1.0..20.0).contains(&sag_mm));
}

#[test]
fn irb4400_balancer_cancels_85_percent_of_the_arms_sin_q2_gravity_torque() {
    let robot = irb4400();
    let balancer = robot.dynamics.counterbalance.unwrap();
    let arm_only = RobotDynamics { counterbalance: None, ..robot.dynamics.clone() };
    // With the other joints at zero, τ2 = A sin q2 + B cos q2: the odd part gives A.
    let q2 = 0.5_f64;
    let tau = |q: f64| {
        gravity_torque(&robot.model, &arm_only, &[0.0, q, 0.0, 0.0, 0.0, 0.0], 0, &Payload::default()).unwrap()[1]
    };
    let gravity_sin = (tau(q2) - tau(-q2)) / (2.0 * q2.sin());
    let balancer_sin = (balancer.torque_nm(q2) - balancer.torque_nm(-q2)) / (2.0 * q2.sin());
    println!("joint 2: gravity {gravity_sin:.0} N·m · sin q2, balancer {balancer_sin:.0} N·m · sin q2");
    assert!((gravity_sin - 2831.0).abs() < 1.0);
    assert!((balancer_sin / gravity_sin + 0.848).abs() < 0.005);
}

#[test]
fn irb4400_compliance_deflection_magnitudes_are_reported() {
    // Not a bound from a source but a record of the numbers the fixture implies: mean tool
    // displacement over random poses, tool 0.2 m, 7.5 kg, from the payload alone and from
    // arm + payload + balancer.
    let robot = irb4400();
    let cell = SimulatedCell::new(with_tool(&robot.model, 0.2), Some(robot.dynamics.clone()));
    let context = PoseContext { payload: Payload::at_tool(7.5), ..PoseContext::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(40);
    let (mut payload_only, mut everything) = (0.0, 0.0);
    let poses = 200;
    for _ in 0..poses {
        let q = random_q(&robot.ranges, &mut rng);
        let nominal = cell.robot.forward(&q, 0).unwrap().translation();
        for (settings, sum) in [
            (JointComplianceModel { payload_only: true, ..Default::default() }, &mut payload_only),
            (JointComplianceModel::default(), &mut everything),
        ] {
            let effects = Effects { joint_compliance: Some(settings), ..Effects::default() };
            *sum += (effects.true_pose(&cell, &q, &context).unwrap().translation() - nominal).norm();
        }
    }
    let (payload_only, everything) = (payload_only / poses as f64 * 1e3, everything / poses as f64 * 1e3);
    println!(
        "IRB 4400 fixture, 7.5 kg: payload only {payload_only:.3} mm, arm + payload + balancer {everything:.3} mm"
    );
    assert!(payload_only > 0.05 && payload_only < 0.5);
    assert!(everything > payload_only);
}

#[test]
fn dynamics_without_the_optional_fields_reads_with_floor_gravity_and_no_balancer() {
    let text = "(links: [(mass_kg: 2.0, com_m: (0.0, 0.0, 0.1))], stiffness_nm_per_rad: [1e4])";
    let dynamics: RobotDynamics = ron::from_str(text).unwrap();
    assert_eq!(dynamics.counterbalance, None);
    assert_eq!(dynamics.gravity_m_per_s2, loadsim::FLOOR_GRAVITY_M_PER_S2);
}

#[test]
fn effects_round_trip_through_ron_and_missing_effects_read_as_off() {
    let typical = Effects::typical(6);
    let text = ron::ser::to_string_pretty(&typical, ron::ser::PrettyConfig::default()).unwrap();
    assert_eq!(ron::from_str::<Effects>(&text).unwrap(), typical);
    let sparse: Effects = ron::from_str("(thermal: Some((expansion_per_k: 2.3e-5)))").unwrap();
    assert_eq!(sparse.thermal.as_ref().unwrap().reference_temp_c, 20.0);
    assert!(sparse.joint_compliance.is_none() && sparse.tracker_noise.is_none());
}
