//! Each effect's forward model against its linearisation: the pose error the forward model
//! produces is, to first order (exactly for thermal growth and drift), the sum over the joints of
//! each joint's spatial twist `S_j(q)` times its joint-space offset (Lynch & Park, *Modern
//! Robotics*, §5.1.1), or the thermal columns times the coefficients.

use crate::robot::{irb4400, pose_error, random_q, with_tool};
use lie::{SE3, SO3, Twist, Vector3, Vector6};
use loadsim::{
    BacklashModel, Effects, GearPeriodicModel, Harmonic, JointComplianceModel, Payload, PoseContext, RobotDynamics,
    SimulatedCell, ThermalModel, TimeDriftModel, backlash_joint_regressor, periodic_joint_regressor, static_torque,
    thermal_regressor,
};
use poe::LocalPoe;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// `Σ_j S_j(q) δq_j`: the first-order pose error of the joint offsets `dq`.
fn joint_offsets_twist(model: &LocalPoe, q: &[f64], dq: &[f64]) -> Vector6 {
    let twists = model.spatial_twists(q).unwrap();
    assert_eq!(twists.len(), dq.len());
    twists.iter().zip(dq).fold(Vector6::zeros(), |sum, (s, d)| sum + s.to_vector() * *d)
}

/// Forward-model pose error of `effects` against the plain geometric model, base frame.
fn forward_error(cell: &SimulatedCell, effects: &Effects, q: &[f64], context: &PoseContext) -> Vector6 {
    let measured = effects.true_pose(cell, q, context).unwrap();
    pose_error(&measured, &(cell.tracker_from_base * cell.robot.forward(q, cell.tool).unwrap()))
}

fn stiff(dynamics: &RobotDynamics, factor: f64) -> RobotDynamics {
    RobotDynamics {
        stiffness_nm_per_rad: dynamics.stiffness_nm_per_rad.iter().map(|k| k * factor).collect(),
        ..dynamics.clone()
    }
}

#[test]
fn the_compliance_pose_error_is_its_joint_offsets_to_first_order() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    // 100× stiffer than the fixture so that the second-order remainder is 1e-5 of the effect.
    let dynamics = stiff(&robot.dynamics, 100.0);
    let cell = SimulatedCell::new(model.clone(), Some(dynamics.clone()));
    let effects = Effects { joint_compliance: Some(JointComplianceModel::default()), ..Effects::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(20);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let context = PoseContext { payload: Payload::at_tool(rng.random_range(0.0..60.0)), ..PoseContext::default() };
        let torque = static_torque(&model, &dynamics, &q, 0, &context.payload).unwrap();
        let dq: Vec<f64> = dynamics.stiffness_nm_per_rad.iter().zip(&torque).map(|(k, t)| t / k).collect();
        let predicted = joint_offsets_twist(&model, &q, &dq);
        let actual = forward_error(&cell, &effects, &q, &context);
        assert!((predicted - actual).norm() < 1e-3 * actual.norm(), "{predicted:?} vs {actual:?}");
    }
}

#[test]
fn the_backlash_pose_error_is_its_joint_offsets_to_first_order() {
    let robot = irb4400();
    let cell = SimulatedCell::new(robot.model.clone(), Some(robot.dynamics.clone()));
    let half_bands = [3e-6, 5e-6, 4e-6, 8e-6, 6e-6, 7e-6];
    let backlash = BacklashModel {
        joints: half_bands
            .iter()
            .enumerate()
            .map(|(joint_index, &half_band_rad)| loadsim::JointBacklash { joint_index, half_band_rad })
            .collect(),
    };
    let effects = Effects { backlash: Some(backlash), ..Effects::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let context = PoseContext::default();
        let torque = static_torque(&robot.model, &robot.dynamics, &q, 0, &context.payload).unwrap();
        let signs = backlash_joint_regressor(&torque);
        let dq: Vec<f64> = signs.iter().zip(&half_bands).map(|(s, b)| s * b).collect();
        let predicted = joint_offsets_twist(&robot.model, &q, &dq);
        let actual = forward_error(&cell, &effects, &q, &context);
        assert!((predicted - actual).norm() < 1e-3 * actual.norm(), "{predicted:?} vs {actual:?}");
    }
}

#[test]
fn the_gear_error_pose_error_is_its_joint_offsets_to_first_order() {
    let robot = irb4400();
    let cell = SimulatedCell::new(robot.model.clone(), None);
    let harmonics = vec![
        Harmonic { joint_index: 1, order: 1.0, amplitude_rad: 2e-5, phase_rad: 0.4 },
        Harmonic { joint_index: 1, order: 3.0, amplitude_rad: 1e-5, phase_rad: -1.1 },
        Harmonic { joint_index: 4, order: 2.0, amplitude_rad: 3e-5, phase_rad: 2.0 },
    ];
    let effects =
        Effects { gear_periodic: Some(GearPeriodicModel { harmonics: harmonics.clone() }), ..Effects::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(22);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let mut dq = vec![0.0; q.len()];
        for h in &harmonics {
            let [c, s] = periodic_joint_regressor(q[h.joint_index], h.order);
            let [a, b] = h.cos_sin_coefficients();
            dq[h.joint_index] += a * c + b * s;
        }
        let predicted = joint_offsets_twist(&robot.model, &q, &dq);
        let actual = forward_error(&cell, &effects, &q, &PoseContext::default());
        assert!((predicted - actual).norm() < 1e-3 * actual.norm(), "{predicted:?} vs {actual:?}");
    }
}

#[test]
fn thermal_regressor_is_exact_per_link() {
    let robot = irb4400();
    let model = with_tool(&robot.model, 0.2);
    let cell = SimulatedCell::new(model.clone(), None);
    let alphas = vec![11e-6, 12e-6, 23e-6, 13e-6, 17e-6, 9e-6, 20e-6];
    let thermal = ThermalModel { reference_temp_c: 20.0, expansion_per_k: 0.0, link_expansion_per_k: alphas.clone() };
    let effects = Effects { thermal: Some(thermal), ..Effects::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(23);
    for _ in 0..20 {
        let q = random_q(&robot.ranges, &mut rng);
        let context = PoseContext { temp_c: rng.random_range(5.0..40.0), ..PoseContext::default() };
        let columns = thermal_regressor(&model, &q, 0, context.temp_c - 20.0).unwrap();
        assert_eq!(columns.len(), 7);
        let predicted = columns.iter().zip(&alphas).fold(Vector6::zeros(), |sum, (c, a)| sum + c * *a);
        // Exactly linear: the pose error is a pure translation and the log of a pure translation
        // is that translation.
        let actual = forward_error(&cell, &effects, &q, &context);
        assert!((predicted - actual).norm() < 1e-12, "{predicted:?} vs {actual:?}");
    }
}

#[test]
fn drift_is_the_twist_rate_times_the_time_exactly_in_the_tracker_frame() {
    let robot = irb4400();
    let mut cell = SimulatedCell::new(robot.model.clone(), None);
    cell.tracker_from_base = SE3::new(SO3::from_rpy(0.1, -0.2, 2.5), Vector3::new(3.0, -1.0, 0.4));
    let drift = TimeDriftModel { twist_per_s: [3e-9, -1e-9, 2e-9, 1e-9, -2e-9, 4e-9] };
    let effects = Effects { time_drift: Some(drift), ..Effects::default() };
    let q = [0.2, 0.3, -0.1, 0.5, 0.6, -0.7];
    for t_s in [0.0, 600.0, 7200.0, 36000.0] {
        let predicted = Vector6::from(drift.twist_per_s) * t_s;
        let actual = forward_error(&cell, &effects, &q, &PoseContext { t_s, ..PoseContext::default() });
        assert!((predicted - actual).norm() < 1e-12, "t {t_s}: {predicted:?} vs {actual:?}");
        assert!((Twist::from_vector(&predicted).exp().to_matrix() - drift.motion_at(t_s).to_matrix()).norm() < 1e-15);
    }
}

#[test]
fn backlash_takes_no_side_where_the_joint_carries_no_torque() {
    assert_eq!(backlash_joint_regressor(&[2.0, -0.5, 0.0, -0.0]), vec![1.0, -1.0, 0.0, 0.0]);
}
