//! Each effect switched on alone does what it says, and nothing else.

use crate::robot::{irb4400, pose_error, random_q, with_tool};
use lie::{SE3, SO3, Vector3};
use loadsim::{
    BacklashModel, EffectKind, Effects, Payload, PoseContext, SimulatedCell, ThermalModel, TrackerNoiseModel,
    static_torque,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn fixture_cell() -> SimulatedCell {
    let robot = irb4400();
    SimulatedCell::new(with_tool(&robot.model, 0.2), Some(robot.dynamics))
}

#[test]
fn no_effect_gives_the_geometric_pose_in_the_tracker_frame() {
    let mut cell = fixture_cell();
    cell.tracker_from_base = SE3::new(SO3::from_rpy(0.3, 0.1, -1.0), Vector3::new(2.0, 1.0, -0.5));
    let q = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6];
    let context = PoseContext { payload: Payload::at_tool(7.5), temp_c: 35.0, t_s: 5000.0 };
    let pose = Effects::default().true_pose(&cell, &q, &context).unwrap();
    assert!(pose_error(&pose, &(cell.tracker_from_base * cell.robot.forward(&q, 0).unwrap())).norm() < 1e-15);
}

#[test]
fn thermal_growth_alone_scales_the_tool_position_about_the_base_by_one_plus_alpha_delta_t() {
    let cell = fixture_cell();
    let alpha = 12e-6;
    let effects =
        Effects { thermal: Some(ThermalModel { expansion_per_k: alpha, ..Default::default() }), ..Default::default() };
    let mut rng = ChaCha8Rng::seed_from_u64(30);
    for _ in 0..10 {
        let q = random_q(&irb4400().ranges, &mut rng);
        let temp_c = rng.random_range(10.0..40.0);
        let nominal = cell.robot.forward(&q, 0).unwrap();
        let grown = effects.true_pose(&cell, &q, &PoseContext { temp_c, ..Default::default() }).unwrap();
        let scale = 1.0 + alpha * (temp_c - 20.0);
        assert!((grown.translation() - nominal.translation() * scale).norm() < 1e-14);
        assert!((grown.rotation().matrix() - nominal.rotation().matrix()).norm() < 1e-15, "lengths only");
    }
    let at_reference = effects.true_pose(&cell, &[0.0; 6], &PoseContext::default()).unwrap();
    assert!(pose_error(&at_reference, &cell.robot.forward(&[0.0; 6], 0).unwrap()).norm() < 1e-15);
}

#[test]
fn backlash_alone_flips_with_the_sign_of_the_joint_torque() {
    let cell = fixture_cell();
    let dynamics = cell.dynamics.clone().unwrap();
    let b = 1e-4;
    let effects = Effects { backlash: Some(BacklashModel::uniform(6, b)), ..Default::default() };
    let context = PoseContext::default();
    let mut rng = ChaCha8Rng::seed_from_u64(31);
    let (mut positive, mut negative) = (0, 0);
    for _ in 0..200 {
        let q = random_q(&irb4400().ranges, &mut rng);
        let torque = static_torque(&cell.robot, &dynamics, &q, 0, &context.payload).unwrap();
        let offsets = effects.joint_offsets(&cell, &q, &context).unwrap();
        for j in 0..6 {
            // Joint 1 is vertical: no gravity torque, the gear sits in the middle of its play.
            let side = if torque[j] == 0.0 { 0.0 } else { torque[j].signum() };
            assert_eq!(offsets.of(EffectKind::Backlash)[j], b * side, "joint {}", j + 1);
            assert_eq!(offsets.of(EffectKind::JointCompliance)[j], 0.0);
            assert_eq!(offsets.of(EffectKind::GearPeriodic)[j], 0.0);
        }
        if torque[1] > 0.0 { positive += 1 } else { negative += 1 }
    }
    assert!(positive > 10 && negative > 10, "joint 2 torque takes both signs: {positive} / {negative}");
}

#[test]
fn each_effect_alone_responds_only_to_its_own_input() {
    let cell = fixture_cell();
    let all = Effects::typical(6);
    let q = [0.3, 0.4, -0.2, 0.6, 0.8, -0.5];
    let base = PoseContext { payload: Payload::at_tool(2.0), temp_c: 20.0, t_s: 0.0 };
    let heavier = PoseContext { payload: Payload::at_tool(7.5), ..base };
    let warmer = PoseContext { temp_c: 26.0, ..base };
    let later = PoseContext { t_s: 20000.0, ..base };
    let moved = |effects: &Effects, a: &PoseContext, b: &PoseContext| {
        let pa = effects.true_pose(&cell, &q, a).unwrap();
        let pb = effects.true_pose(&cell, &q, b).unwrap();
        pose_error(&pa, &pb).norm() > 1e-9
    };
    let expect = [
        (EffectKind::JointCompliance, [true, false, false]),
        (EffectKind::GearPeriodic, [false, false, false]),
        (EffectKind::Thermal, [false, true, false]),
        (EffectKind::TimeDrift, [false, false, true]),
    ];
    for (kind, [payload, temperature, time]) in expect {
        let alone = all.only(kind);
        assert!(EffectKind::ALL.iter().all(|k| alone.is_on(*k) == (*k == kind)));
        assert_eq!(moved(&alone, &base, &heavier), payload, "{kind:?} and payload");
        assert_eq!(moved(&alone, &base, &warmer), temperature, "{kind:?} and temperature");
        assert_eq!(moved(&alone, &base, &later), time, "{kind:?} and time");
    }
    let periodic = all.only(EffectKind::GearPeriodic).true_pose(&cell, &q, &base).unwrap();
    assert!(pose_error(&periodic, &cell.robot.forward(&q, 0).unwrap()).norm() > 1e-6, "gear error moves the tool");
}

#[test]
fn tracker_noise_alone_has_the_stated_radial_transverse_and_angular_spread() {
    let mut cell = fixture_cell();
    // Tracker 3 m in front of the robot, looking back at it.
    cell.tracker_from_base = SE3::new(SO3::from_rpy(0.0, 0.0, std::f64::consts::PI), Vector3::new(3.0, 0.0, -0.5));
    let noise = TrackerNoiseModel::default();
    let effects = Effects { tracker_noise: Some(noise), ..Default::default() };
    let q = [0.0, 0.3, -0.2, 0.0, 0.5, 0.0];
    let truth = effects.true_pose(&cell, &q, &PoseContext::default()).unwrap();
    let p = truth.translation();
    let radial = p.normalize();
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let draws = 4000;
    let (mut r2, mut t2, mut w2, mut r_sum) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..draws {
        let measured = effects.measured_pose(&cell, &q, &PoseContext::default(), &mut rng).unwrap();
        let d = measured.translation() - p;
        let along = d.dot(&radial);
        r_sum += along;
        r2 += along * along;
        t2 += (d - radial * along).norm_squared() / 2.0;
        w2 += pose_error(&measured, &truth).fixed_rows::<3>(3).norm_squared() / 3.0;
    }
    let n = draws as f64;
    let radial_sigma = (r2 / n).sqrt();
    let transverse_sigma = (t2 / n).sqrt();
    let angular_sigma = (w2 / n).sqrt();
    let expected_transverse = noise.transverse_sigma_at(p.norm());
    // 4000 draws: the standard error of a standard deviation is about 1.1 %.
    assert!((radial_sigma / noise.radial_sigma_m - 1.0).abs() < 0.05, "radial {radial_sigma}");
    assert!((transverse_sigma / expected_transverse - 1.0).abs() < 0.05, "transverse {transverse_sigma}");
    assert!((angular_sigma / noise.orientation_sigma_rad - 1.0).abs() < 0.05, "angular {angular_sigma}");
    assert!((r_sum / n).abs() < 4.0 * noise.radial_sigma_m / n.sqrt(), "unbiased");
    let covariance = noise.position_covariance(&p);
    assert!((radial.dot(&(covariance * radial)) - noise.radial_sigma_m.powi(2)).abs() < 1e-20);
}
