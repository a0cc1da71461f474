//! Robots and random perturbations shared by the poe tests.
#![allow(dead_code)]

use lie::{Matrix3, SE3, SO3, Twist, Vector3};
use poe::identify::{Observation, Target};
use poe::{JointAxis, JointKind, LocalPoe};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

pub fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

fn revolute(direction: [f64; 3], point: [f64; 3]) -> JointAxis {
    JointAxis { kind: JointKind::Revolute, direction: Vector3::from(direction), point: Vector3::from(point) }
}

/// ABB IRB 4400/60 at the zero configuration, from the project SPEC table. Limits in radians.
pub fn irb4400() -> (LocalPoe, Vec<(f64, f64)>) {
    let axes = [
        revolute([0.0, 0.0, 1.0], [0.0, 0.0, 0.0]),
        revolute([0.0, 1.0, 0.0], [0.2, 0.0, 0.68]),
        revolute([0.0, 1.0, 0.0], [0.2, 0.0, 1.57]),
        revolute([1.0, 0.0, 0.0], [1.08, 0.0, 1.72]),
        revolute([0.0, 1.0, 0.0], [1.08, 0.0, 1.72]),
        revolute([1.0, 0.0, 0.0], [1.22, 0.0, 1.72]),
    ];
    // Flange z along +x, y along +y, so x = y × z = -z of the base.
    let r = Matrix3::from_columns(&[-Vector3::z(), Vector3::y(), Vector3::x()]);
    let flange = SE3::new(SO3::from_matrix_unchecked(r), Vector3::new(1.22, 0.0, 1.72));
    let limits = [(-165.0, 165.0), (-70.0, 95.0), (-60.0, 65.0), (-200.0, 200.0), (-120.0, 120.0), (-400.0, 400.0)]
        .map(|(a, b): (f64, f64)| (a.to_radians(), b.to_radians()));
    (LocalPoe::from_zero_configuration(&axes, flange).unwrap(), limits.to_vec())
}

/// KUKA LBR iiwa 7 R800 at the zero configuration, from the project SPEC.
pub fn iiwa7() -> (LocalPoe, Vec<(f64, f64)>) {
    let z = [0.0, 0.0, 1.0];
    let y = [0.0, 1.0, 0.0];
    let my = [0.0, -1.0, 0.0];
    let axes = [
        revolute(z, [0.0, 0.0, 0.0]),
        revolute(y, [0.0, 0.0, 0.34]),
        revolute(z, [0.0, 0.0, 0.34]),
        revolute(my, [0.0, 0.0, 0.74]),
        revolute(z, [0.0, 0.0, 0.74]),
        revolute(y, [0.0, 0.0, 1.14]),
        revolute(z, [0.0, 0.0, 1.14]),
    ];
    let flange = SE3::from_translation(Vector3::new(0.0, 0.0, 1.266));
    let limits = [170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 175.0].map(|l: f64| (-l.to_radians(), l.to_radians()));
    (LocalPoe::from_zero_configuration(&axes, flange).unwrap(), limits.to_vec())
}

pub fn random_twist(rng: &mut ChaCha8Rng, translation: f64, rotation: f64) -> Twist {
    let mut v = || Vector3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
    let a = v();
    let b = v();
    Twist::new(a * translation, b * rotation)
}

/// Every local transform and the tool moved by up to `translation` metres and `rotation` radians
/// per axis.
pub fn perturb(model: &LocalPoe, rng: &mut ChaCha8Rng, translation: f64, rotation: f64) -> LocalPoe {
    let mut out = model.clone();
    for joint in out.joints_mut() {
        joint.previous_from_joint_zero =
            random_twist(rng, translation, rotation).exp() * joint.previous_from_joint_zero;
    }
    let tools = model.tools().iter().map(|t| random_twist(rng, translation, rotation).exp() * *t).collect();
    out.set_tools(tools);
    out
}

pub fn random_q(rng: &mut ChaCha8Rng, limits: &[(f64, f64)]) -> Vec<f64> {
    limits.iter().map(|&(lo, hi)| rng.random_range(lo * 0.9..hi * 0.9)).collect()
}

/// A ground-truth robot as measured: perturbed kinematics, a tracker far from the base and turned
/// arbitrarily, and a tool up to 0.5 m from the flange.
pub fn measured_robot(nominal: &LocalPoe, rng: &mut ChaCha8Rng) -> LocalPoe {
    let mut truth = perturb(nominal, rng, 0.002, 0.002);
    let tool_offset = SE3::new(SO3::exp(&(random_twist(rng, 0.0, 1.0).w)), random_twist(rng, 0.5 / 3f64.sqrt(), 0.0).v);
    truth.set_tools(vec![truth.tools()[0] * tool_offset]);
    let tracker_from_base = SE3::new(
        SO3::exp(&random_twist(rng, 0.0, 3.0).w),
        Vector3::new(rng.random_range(-5.0..5.0), rng.random_range(-5.0..5.0), rng.random_range(-2.0..2.0)),
    );
    truth.change_reference(tracker_from_base);
    truth
}

/// Standard normal sample by Box–Muller (keeps the tests free of rand_distr).
pub fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    let u1: f64 = rng.random_range(f64::EPSILON..1.0);
    let u2: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

/// Measurements of `truth` at random poses with isotropic Gaussian noise.
pub fn observe(
    truth: &LocalPoe,
    limits: &[(f64, f64)],
    count: usize,
    full_pose: bool,
    position_noise_m: f64,
    rotation_noise_rad: f64,
    rng: &mut ChaCha8Rng,
) -> Vec<Observation> {
    (0..count)
        .map(|_| {
            let q = random_q(rng, limits);
            let pose = truth.forward(&q, 0).unwrap();
            let dp = Vector3::new(gaussian(rng), gaussian(rng), gaussian(rng)) * position_noise_m;
            let dr = Vector3::new(gaussian(rng), gaussian(rng), gaussian(rng)) * rotation_noise_rad;
            let target = if full_pose {
                Target::Pose(SE3::new(SO3::exp(&dr) * pose.rotation(), pose.translation() + dp))
            } else {
                Target::Point(pose.translation() + dp)
            };
            Observation { q, tool: 0, target, stated_sigma: None }
        })
        .collect()
}

/// Mean distance between measured and modelled tool points, metres.
pub fn mean_position_error(model: &LocalPoe, observations: &[Observation]) -> f64 {
    observations
        .iter()
        .map(|o| {
            let p = model.forward(&o.q, o.tool).unwrap().translation();
            let m = match o.target {
                Target::Pose(t) => t.translation(),
                Target::Point(p) => p,
            };
            (m - p).norm()
        })
        .sum::<f64>()
        / observations.len() as f64
}
