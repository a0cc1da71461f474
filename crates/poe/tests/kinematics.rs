//! Forward kinematics against independent formulas.

mod common;

use common::{iiwa7, irb4400, random_q, rng};
use lie::{SE3, SO3, Twist, Vector3};
use poe::{DhConvention, DhRow, JointKind, LocalPoe};
use rand::Rng;

/// The textbook spatial POE, `T(q) = Π exp(ξ_i q_i) M` with `ξ_i = (−ω_i × p_i, ω_i)`, written
/// independently of the local POE code.
fn spatial_poe(axes: &[(Vector3, Vector3)], flange: SE3, q: &[f64]) -> SE3 {
    let mut pose = SE3::identity();
    for ((w, p), &value) in axes.iter().zip(q) {
        pose = pose * (Twist::new(-w.cross(p), *w) * value).exp();
    }
    pose * flange
}

#[test]
fn local_poe_from_axes_matches_the_spatial_product_of_exponentials() {
    let (model, limits) = irb4400();
    let axes = [
        (Vector3::z(), Vector3::zeros()),
        (Vector3::y(), Vector3::new(0.2, 0.0, 0.68)),
        (Vector3::y(), Vector3::new(0.2, 0.0, 1.57)),
        (Vector3::x(), Vector3::new(1.08, 0.0, 1.72)),
        (Vector3::y(), Vector3::new(1.08, 0.0, 1.72)),
        (Vector3::x(), Vector3::new(1.22, 0.0, 1.72)),
    ];
    let flange = model.forward(&[0.0; 6], 0).unwrap();
    assert!((flange.translation() - Vector3::new(1.22, 0.0, 1.72)).norm() < 1e-12);
    let mut rng = rng(1);
    for _ in 0..50 {
        let q = random_q(&mut rng, &limits);
        let expected = spatial_poe(&axes, flange, &q);
        let got = model.forward(&q, 0).unwrap();
        assert!((got.to_matrix() - expected.to_matrix()).norm() < 1e-12);
    }
}

#[test]
fn positive_joint_two_tilts_the_irb4400_forward() {
    let (model, _) = irb4400();
    let tilted = model.forward(&[0.0, 0.3, 0.0, 0.0, 0.0, 0.0], 0).unwrap();
    let straight = model.forward(&[0.0; 6], 0).unwrap();
    assert!(tilted.translation().x > straight.translation().x);
    assert!(tilted.translation().z < straight.translation().z);
}

#[test]
fn spatial_twists_pass_through_the_joint_axes() {
    let (model, limits) = iiwa7();
    let mut rng = rng(2);
    let q = random_q(&mut rng, &limits);
    let frames = model.frames(&q).unwrap();
    let twists = model.spatial_twists(&q).unwrap();
    for (frame, twist) in frames.iter().zip(&twists) {
        let axis = frame.rotation().act(&Vector3::z());
        assert!((twist.w - axis).norm() < 1e-12);
        // v = −ω × p for a point p on the axis (the frame origin).
        assert!((twist.v + axis.cross(&frame.translation())).norm() < 1e-12);
    }
}

fn rz(a: f64) -> SE3 {
    SE3::new(SO3::exp(&(Vector3::z() * a)), Vector3::zeros())
}
fn rx(a: f64) -> SE3 {
    SE3::new(SO3::exp(&(Vector3::x() * a)), Vector3::zeros())
}
fn tz(d: f64) -> SE3 {
    SE3::from_translation(Vector3::new(0.0, 0.0, d))
}
fn tx(a: f64) -> SE3 {
    SE3::from_translation(Vector3::new(a, 0.0, 0.0))
}

fn random_rows(rng: &mut rand_chacha::ChaCha8Rng, count: usize, prismatic: usize) -> Vec<DhRow> {
    (0..count)
        .map(|i| DhRow {
            kind: if i == prismatic { JointKind::Prismatic } else { JointKind::Revolute },
            a: rng.random_range(-0.6..0.6),
            alpha: rng.random_range(-3.0..3.0),
            d: rng.random_range(-0.4..0.4),
            theta: rng.random_range(-3.0..3.0),
        })
        .collect()
}

#[test]
fn standard_dh_model_matches_the_dh_product_with_a_prismatic_joint() {
    let mut rng = rng(3);
    for count in [6, 7] {
        let rows = random_rows(&mut rng, count, 2);
        let model = LocalPoe::from_dh(&rows, DhConvention::Standard);
        for _ in 0..20 {
            let q: Vec<f64> = (0..count).map(|_| rng.random_range(-3.0..3.0)).collect();
            let mut expected = SE3::identity();
            for (row, &value) in rows.iter().zip(&q) {
                let (theta, d) = match row.kind {
                    JointKind::Revolute => (row.theta + value, row.d),
                    JointKind::Prismatic => (row.theta, row.d + value),
                };
                expected = expected * rz(theta) * tz(d) * tx(row.a) * rx(row.alpha);
            }
            let got = model.forward(&q, 0).unwrap();
            assert!((got.to_matrix() - expected.to_matrix()).norm() < 1e-12);
        }
    }
}

#[test]
fn modified_dh_model_matches_the_dh_product_with_a_prismatic_joint() {
    let mut rng = rng(4);
    for count in [6, 7] {
        let rows = random_rows(&mut rng, count, 4);
        let model = LocalPoe::from_dh(&rows, DhConvention::Modified);
        for _ in 0..20 {
            let q: Vec<f64> = (0..count).map(|_| rng.random_range(-3.0..3.0)).collect();
            let mut expected = SE3::identity();
            for (row, &value) in rows.iter().zip(&q) {
                let (theta, d) = match row.kind {
                    JointKind::Revolute => (row.theta + value, row.d),
                    JointKind::Prismatic => (row.theta, row.d + value),
                };
                expected = expected * rx(row.alpha) * tx(row.a) * rz(theta) * tz(d);
            }
            let got = model.forward(&q, 0).unwrap();
            assert!((got.to_matrix() - expected.to_matrix()).norm() < 1e-12);
        }
    }
}

#[test]
fn change_of_reference_moves_every_pose_by_the_same_transform() {
    let (mut model, limits) = iiwa7();
    let before = model.clone();
    let new_from_old = (Twist::new(Vector3::new(1.0, -2.0, 0.5), Vector3::new(0.3, -0.2, 1.0))).exp();
    model.change_reference(new_from_old);
    let mut rng = rng(5);
    let q = random_q(&mut rng, &limits);
    let expected = new_from_old * before.forward(&q, 0).unwrap();
    assert!((model.forward(&q, 0).unwrap().to_matrix() - expected.to_matrix()).norm() < 1e-12);
}

#[test]
fn forward_refuses_a_wrong_joint_count_and_an_unknown_tool() {
    let (model, _) = irb4400();
    assert_eq!(model.forward(&[0.0; 5], 0), Err(poe::Error::JointCountMismatch { given: 5, expected: 6 }));
    assert_eq!(model.forward(&[0.0; 6], 1), Err(poe::Error::UnknownTool { tool: 1, tool_count: 1 }));
}

#[test]
fn from_zero_configuration_refuses_a_non_unit_axis() {
    let axis =
        poe::JointAxis { kind: JointKind::Revolute, direction: Vector3::new(0.0, 0.0, 2.0), point: Vector3::zeros() };
    assert!(matches!(
        LocalPoe::from_zero_configuration(&[axis], SE3::identity()),
        Err(poe::Error::AxisNotUnit { joint: 0, .. })
    ));
}

#[test]
fn a_scaled_joint_moves_as_the_unscaled_joint_at_the_scaled_value() {
    let (mut scaled, limits) = iiwa7();
    let (plain, _) = iiwa7();
    let scales = [1.0, 3.0, 0.5, 1.0, -2.0, 1.0, 1.25];
    for (joint, &s) in scaled.joints_mut().iter_mut().zip(&scales) {
        joint.scale = s;
    }
    let mut rng = rng(5);
    for _ in 0..20 {
        let q = random_q(&mut rng, &limits);
        let moved: Vec<f64> = q.iter().zip(&scales).map(|(q, s)| q * s).collect();
        let got = scaled.forward(&q, 0).unwrap();
        let expected = plain.forward(&moved, 0).unwrap();
        assert!((got.to_matrix() - expected.to_matrix()).norm() < 1e-12);
    }
}

#[test]
fn the_spatial_twists_of_scaled_joints_are_the_derivatives_of_the_pose() {
    let (mut model, limits) = iiwa7();
    for (joint, s) in model.joints_mut().iter_mut().zip([3.0, 1.0, 0.5, 2.0, 1.0, -1.5, 1.0]) {
        joint.scale = s;
    }
    let mut rng = rng(6);
    let q = random_q(&mut rng, &limits);
    let twists = model.spatial_twists(&q).unwrap();
    let h = 1e-6;
    for (i, twist) in twists.iter().enumerate() {
        let (mut up, mut down) = (q.clone(), q.clone());
        up[i] += h;
        down[i] -= h;
        // Spatial velocity: log(T(q + h) T(q − h)⁻¹) / 2h.
        let moved = model.forward(&up, 0).unwrap() * model.forward(&down, 0).unwrap().inverse();
        let numeric = moved.log().to_vector() / (2.0 * h);
        assert!((numeric - twist.to_vector()).norm() < 1e-7, "joint {i}: {numeric} against {}", twist.to_vector());
    }
}
