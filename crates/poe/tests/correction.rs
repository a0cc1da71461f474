//! Non-geometric parameters identified jointly with the kinematics.

mod common;

use common::{iiwa7, irb4400, measured_robot, random_q, rng};
use lie::Vector6;
use poe::LocalPoe;
use poe::identify::{
    IdentificationOptions, Observation, ParameterMask, PoseCorrection, Scope, Target, calibrate,
    identify_with_correction,
};

/// `δq_j = θ_0 cos(2 q_j) + θ_1 sin(2 q_j)`: a second-harmonic transmission error on joint `j`.
struct Harmonic {
    joint: usize,
    q: Vec<Vec<f64>>,
}

impl PoseCorrection for Harmonic {
    fn parameter_count(&self) -> usize {
        2
    }

    fn twists(&self, model: &LocalPoe, index: usize, out: &mut [Vector6]) {
        let q = &self.q[index];
        let xi = model.spatial_twists(q).unwrap()[self.joint].to_vector();
        out[0] = xi * (2.0 * q[self.joint]).cos();
        out[1] = xi * (2.0 * q[self.joint]).sin();
    }
}

fn with_harmonic(
    truth: &LocalPoe,
    limits: &[(f64, f64)],
    joint: usize,
    theta: [f64; 2],
    full_pose: bool,
    n: usize,
    seed: u64,
) -> Vec<Observation> {
    let mut rng = rng(seed);
    (0..n)
        .map(|_| {
            let q = random_q(&mut rng, limits);
            let mut moved = q.clone();
            moved[joint] += theta[0] * (2.0 * q[joint]).cos() + theta[1] * (2.0 * q[joint]).sin();
            let pose = truth.forward(&moved, 0).unwrap();
            let target = if full_pose { Target::Pose(pose) } else { Target::Point(pose.translation()) };
            Observation { q, tool: 0, target, stated_sigma: None }
        })
        .collect()
}

#[test]
fn a_joint_harmonic_is_recovered_jointly_with_the_kinematics() {
    for (robot, joint) in [(irb4400(), 1), (irb4400(), 4), (iiwa7(), 3)] {
        let (nominal, limits) = robot;
        for full_pose in [true, false] {
            let mut r = rng(40 + joint as u64);
            let truth = measured_robot(&nominal, &mut r);
            let theta = [4e-4, -3e-4];
            let train = with_harmonic(&truth, &limits, joint, theta, full_pose, 200, 1);
            let test = with_harmonic(&truth, &limits, joint, theta, full_pose, 100, 2);
            let options = IdentificationOptions::default();
            let start = calibrate(&nominal, &train, Scope::Full, &options).unwrap();
            let plain = poe::identify::evaluate(&start.model, &test).unwrap().rms_position_m;
            let correction = Harmonic { joint, q: train.iter().map(|o| o.q.clone()).collect() };
            let mask = ParameterMask::all(start.model.layout());
            let fit = identify_with_correction(&start.model, &train, &mask, Some(&correction), &options).unwrap();
            // The model form exp(ξ δq) T(q) equals T(q + δq) to second order in δq (~1e-7 rad here).
            for (got, want) in fit.correction.iter().zip(theta) {
                assert!((got - want).abs() < 2e-6, "joint {joint}: θ {:?} vs {theta:?}", fit.correction);
            }
            let test_correction = Harmonic { joint, q: test.iter().map(|o| o.q.clone()).collect() };
            let mut worst = 0.0_f64;
            for (i, o) in test.iter().enumerate() {
                let mut c = [Vector6::zeros(); 2];
                test_correction.twists(&fit.model, i, &mut c);
                let twist = c[0] * fit.correction[0] + c[1] * fit.correction[1];
                let pose = lie::Twist::from_vector(&twist).exp() * fit.model.forward(&o.q, 0).unwrap();
                let measured = match o.target {
                    Target::Pose(p) => p.translation(),
                    Target::Point(p) => p,
                };
                worst = worst.max((pose.translation() - measured).norm());
            }
            assert!(plain > 5e-5, "the harmonic must be visible without the correction: {plain}");
            assert!(worst < 2e-6, "joint {joint} full pose {full_pose}: held-out {worst} m with, {plain} m without");
        }
    }
}
