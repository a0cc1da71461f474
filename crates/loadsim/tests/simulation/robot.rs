//! The robots the tests run on: the IRB 4400 and iiwa 7 fixtures read with a mirror of the robot RON schema
//! (the reader proper lives in `pipeline`, which depends on this crate), and small helpers.

use lie::{Matrix3, SE3, SO3, Vector3};
use loadsim::{JointRange, LinkInertia, RobotDynamics};
use poe::{JointAxis, JointKind, LocalPoe};
use rand::Rng;
use serde::Deserialize;

#[derive(Deserialize)]
struct JointRow {
    kind: JointKind,
    axis: [f64; 3],
    point: [f64; 3],
    limits_deg: (f64, f64),
}

#[derive(Deserialize)]
struct Flange {
    position: [f64; 3],
    x_axis: [f64; 3],
    z_axis: [f64; 3],
}

#[derive(Deserialize)]
#[allow(dead_code)]
struct Robot {
    name: String,
    joints: Vec<JointRow>,
    flange: Flange,
    dynamics: Option<RobotDynamics>,
}

/// A robot fixture: its nominal model (flange = tool 0), joint ranges and dynamics.
pub struct FixtureRobot {
    pub model: LocalPoe,
    pub ranges: Vec<JointRange>,
    pub dynamics: RobotDynamics,
}

/// The IRB 4400/60 fixture.
pub fn irb4400() -> FixtureRobot {
    fixture("irb4400.ron")
}

/// The LBR iiwa 7 R800 fixture.
pub fn iiwa7() -> FixtureRobot {
    fixture("iiwa7.ron")
}

fn fixture(name: &str) -> FixtureRobot {
    let path = format!("{}/../../fixtures/robots/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("fixture present");
    let robot: Robot = ron::from_str(&text).expect("fixture parses");
    let axes: Vec<JointAxis> = robot
        .joints
        .iter()
        .map(|j| JointAxis { kind: j.kind, direction: Vector3::from(j.axis), point: Vector3::from(j.point) })
        .collect();
    let x = Vector3::from(robot.flange.x_axis);
    let z = Vector3::from(robot.flange.z_axis);
    let flange = SE3::new(
        SO3::from_matrix_unchecked(Matrix3::from_columns(&[x, z.cross(&x), z])),
        Vector3::from(robot.flange.position),
    );
    FixtureRobot {
        model: LocalPoe::from_zero_configuration(&axes, flange).unwrap(),
        ranges: robot
            .joints
            .iter()
            .map(|j| JointRange { lower_rad: j.limits_deg.0.to_radians(), upper_rad: j.limits_deg.1.to_radians() })
            .collect(),
        dynamics: robot.dynamics.expect("the fixture carries dynamics"),
    }
}

/// The model with its only tool `offset_m` along the flange z axis.
pub fn with_tool(model: &LocalPoe, offset_m: f64) -> LocalPoe {
    let mut m = model.clone();
    m.set_tools(vec![model.tools()[0] * SE3::from_translation(Vector3::new(0.0, 0.0, offset_m))]);
    m
}

/// Dynamics with massless links and the given stiffness.
pub fn massless(stiffness: Vec<f64>) -> RobotDynamics {
    RobotDynamics {
        links: vec![LinkInertia { mass_kg: 0.0, com_m: [0.0; 3] }; stiffness.len()],
        stiffness_nm_per_rad: stiffness,
        counterbalance: None,
        gravity_m_per_s2: loadsim::FLOOR_GRAVITY_M_PER_S2,
    }
}

/// Joint values drawn uniformly inside the ranges (5° from each limit).
pub fn random_q<R: Rng>(ranges: &[JointRange], rng: &mut R) -> Vec<f64> {
    let margin = 5f64.to_radians();
    ranges.iter().map(|r| rng.random_range(r.lower_rad + margin..r.upper_rad - margin)).collect()
}

/// `log(a · b⁻¹)^∨`, the left-perturbation pose error.
pub fn pose_error(a: &SE3, b: &SE3) -> lie::Vector6 {
    (*a * b.inverse()).log().to_vector()
}
