//! Deflection magnitudes against independent calculations: a hand calculation at the zero
//! configuration and an energy minimisation over random poses.

use crate::robot::{irb4400, massless, random_q, with_tool};
use lie::Vector3;
use loadsim::{Effects, JointComplianceModel, Payload, PoseContext, SimulatedCell, compliance_deflection};
use poe::LocalPoe;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// The brief's set-up: k = 3e5 N·m/rad on joints 1–3, 1e5 on the wrist, 7.5 kg at a tool 0.2 m
/// out of the flange, no link masses.
const STIFFNESS: [f64; 6] = [3e5, 3e5, 3e5, 1e5, 1e5, 1e5];
const PAYLOAD_KG: f64 = 7.5;

fn tool_displacement(cell: &SimulatedCell, q: &[f64], settings: JointComplianceModel) -> Vector3 {
    let effects = Effects { joint_compliance: Some(settings), ..Effects::default() };
    let context = PoseContext { payload: Payload::at_tool(PAYLOAD_KG), ..PoseContext::default() };
    effects.true_pose(cell, q, &context).unwrap().translation() - cell.robot.forward(q, 0).unwrap().translation()
}

#[test]
fn zero_configuration_sag_matches_the_hand_lever_arm_calculation() {
    let model = with_tool(&irb4400().model, 0.2);
    let cell = SimulatedCell::new(model, Some(massless(STIFFNESS.to_vec())));
    // By hand: the tool is at (1.42, 0, 1.72); the weight W = 7.5 · 9.81 = 73.575 N hangs at
    // horizontal lever 1.22 m from joints 2 and 3 and 0.34 m from joint 5 (axes along y);
    // joints 1, 4 and 6 pass through the line of the weight. δq = W l / k, and turning about y by
    // δ moves the point (dx, 0, dz) away from the axis by δ (dz, 0, −dx).
    let w = PAYLOAD_KG * 9.81;
    let d2 = w * 1.22 / 3e5;
    let d3 = w * 1.22 / 3e5;
    let d5 = w * 0.34 / 1e5;
    let by_hand = Vector3::new(d2 * 1.04 + d3 * 0.15, 0.0, -(d2 * 1.22 + d3 * 1.22 + d5 * 0.34));
    let computed =
        tool_displacement(&cell, &[0.0; 6], JointComplianceModel { payload_only: true, ..Default::default() });
    println!("zero-configuration sag: by hand {:.4} mm, model {:.4} mm", by_hand.norm() * 1e3, computed.norm() * 1e3);
    // Second-order terms (δ² · l ≈ 1e-7 m) are all that separates them.
    assert!((computed - by_hand).norm() < 5e-7, "{computed:?} vs {by_hand:?}");
    assert!((by_hand.norm() - 0.889e-3).abs() < 1e-6);
}

/// The equilibrium by minimising `E(θ) = −m gᵀ p(θ) + ½ (θ − q)ᵀ K (θ − q)`: its stationarity
/// `θ = q − K⁻¹ ∇V(θ)` iterated with `∇V` from central differences of the forward kinematics —
/// no twists, no Jacobian, no torque formula.
fn energy_minimum(model: &LocalPoe, q: &[f64]) -> Vec<f64> {
    let g = Vector3::new(0.0, 0.0, -9.81);
    let potential = |theta: &[f64]| -PAYLOAD_KG * g.dot(&model.forward(theta, 0).unwrap().translation());
    let mut theta = q.to_vec();
    for _ in 0..20 {
        let h = 1e-6;
        let gradient: Vec<f64> = (0..q.len())
            .map(|j| {
                let mut plus = theta.clone();
                let mut minus = theta.clone();
                plus[j] += h;
                minus[j] -= h;
                (potential(&plus) - potential(&minus)) / (2.0 * h)
            })
            .collect();
        theta = (0..q.len()).map(|j| q[j] - gradient[j] / STIFFNESS[j]).collect();
    }
    theta
}

#[test]
fn mean_payload_deflection_over_random_poses_is_half_a_millimetre_and_matches_energy_minimisation() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    let cell = SimulatedCell::new(model.clone(), Some(massless(STIFFNESS.to_vec())));
    let mut rng = ChaCha8Rng::seed_from_u64(10);
    let poses = 200;
    let (mut sum_model, mut sum_energy, mut worst_relative) = (0.0, 0.0, 0.0_f64);
    for _ in 0..poses {
        let q = random_q(&robot.ranges, &mut rng);
        let first_order =
            tool_displacement(&cell, &q, JointComplianceModel { payload_only: true, ..Default::default() });
        let theta = energy_minimum(&model, &q);
        let energy = model.forward(&theta, 0).unwrap().translation() - model.forward(&q, 0).unwrap().translation();
        worst_relative = worst_relative.max((first_order - energy).norm() / energy.norm());
        sum_model += first_order.norm();
        sum_energy += energy.norm();
    }
    let (mean_model, mean_energy) = (sum_model / poses as f64 * 1e3, sum_energy / poses as f64 * 1e3);
    println!(
        "mean tool displacement, 7.5 kg, k 3e5/1e5, tool 0.2 m, {poses} poses: first-order {mean_model:.4} mm, \
         energy minimum {mean_energy:.4} mm, worst relative difference {worst_relative:.2e}"
    );
    assert!((0.3..0.8).contains(&mean_model), "about half a millimetre, got {mean_model} mm");
    assert!((mean_model - mean_energy).abs() / mean_energy < 2e-3);
    assert!(worst_relative < 1e-2);
}

#[test]
fn fixed_point_iterations_reach_the_energy_minimum() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    let dynamics = massless(STIFFNESS.to_vec());
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for _ in 0..10 {
        let q = random_q(&robot.ranges, &mut rng);
        let settings = JointComplianceModel { payload_only: true, fixed_point_iterations: 5 };
        let dq = compliance_deflection(&model, &dynamics, &q, 0, &Payload::at_tool(PAYLOAD_KG), &settings).unwrap();
        let theta = energy_minimum(&model, &q);
        for j in 0..6 {
            assert!((q[j] + dq[j] - theta[j]).abs() < 1e-8, "joint {}: {} vs {}", j + 1, q[j] + dq[j], theta[j]);
        }
    }
}

#[test]
fn deflection_is_proportional_to_payload_and_inverse_to_stiffness() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    let q = [0.4, 0.3, -0.2, 0.8, 0.9, 0.1];
    let settings = JointComplianceModel { payload_only: true, ..Default::default() };
    let soft = massless(STIFFNESS.to_vec());
    let stiff = massless(STIFFNESS.iter().map(|k| 2.0 * k).collect());
    let base = compliance_deflection(&model, &soft, &q, 0, &Payload::at_tool(5.0), &settings).unwrap();
    let heavy = compliance_deflection(&model, &soft, &q, 0, &Payload::at_tool(10.0), &settings).unwrap();
    let stiffer = compliance_deflection(&model, &stiff, &q, 0, &Payload::at_tool(5.0), &settings).unwrap();
    for j in 0..6 {
        assert!((heavy[j] - 2.0 * base[j]).abs() < 1e-15);
        assert!((stiffer[j] - 0.5 * base[j]).abs() < 1e-15);
    }
}
