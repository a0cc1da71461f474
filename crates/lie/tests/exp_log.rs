//! Exponential and logarithm of SO(3) and SE(3): round trips (random and at the fixed hard cases),
//! agreement with the matrix exponential, and the logarithm at exactly π.

mod common;

use common::{MAX_ANGLE, fixed_rotation_vectors, fixed_twists, matrix_exp, max_diff, rotation_vector, se3, so3, twist};
use lie::{Matrix3, SE3, SO3, Twist, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

proptest! {
    #[test]
    fn so3_exp_of_log_is_the_rotation(r in so3()) {
        prop_assert!(max_diff(&SO3::exp(&r.log()).matrix(), &r.matrix()) < 1e-13);
    }

    #[test]
    fn so3_log_of_exp_is_the_rotation_vector_below_pi(w in rotation_vector(MAX_ANGLE)) {
        prop_assert!(max_diff(&SO3::exp(&w).log(), &w) < 1e-14);
    }

    #[test]
    fn so3_log_of_inverse_is_minus_log(r in so3()) {
        prop_assert!(max_diff(&r.inverse().log(), &-r.log()) < 1e-14);
    }

    #[test]
    fn so3_log_has_angle_at_most_pi(r in so3()) {
        prop_assert!(r.log().norm() <= PI);
    }

    #[test]
    fn so3_exp_matches_matrix_exponential_of_hat(w in rotation_vector(PI)) {
        prop_assert!(max_diff(&SO3::exp(&w).matrix(), &matrix_exp(&SO3::hat(&w))) < 1e-13);
    }

    #[test]
    fn so3_exp_of_opposite_vector_is_inverse(w in rotation_vector(PI)) {
        prop_assert!(max_diff(&SO3::exp(&-w).matrix(), &SO3::exp(&w).inverse().matrix()) < 1e-15);
    }

    #[test]
    fn so3_exp_of_split_angle_composes(w in rotation_vector(PI), s in 0.0..1.0f64) {
        // exp((s + (1 − s)) ω) = exp(s ω) exp((1 − s) ω): one-parameter subgroup.
        let product = SO3::exp(&(w * s)) * SO3::exp(&(w * (1.0 - s)));
        prop_assert!(max_diff(&product.matrix(), &SO3::exp(&w).matrix()) < 1e-13);
    }

    #[test]
    fn se3_exp_of_log_is_the_transform(t in se3()) {
        prop_assert!(max_diff(&t.log().exp().to_matrix(), &t.to_matrix()) < 1e-13);
    }

    #[test]
    fn se3_log_of_exp_is_the_twist_below_pi(xi in twist(MAX_ANGLE)) {
        prop_assert!(max_diff(&xi.exp().log().to_vector(), &xi.to_vector()) < 1e-13);
    }

    #[test]
    fn se3_log_of_inverse_is_minus_log(t in se3()) {
        prop_assert!(max_diff(&t.inverse().log().to_vector(), &-t.log().to_vector()) < 1e-13);
    }

    #[test]
    fn se3_exp_matches_matrix_exponential_of_hat(xi in twist(PI)) {
        prop_assert!(max_diff(&xi.exp().to_matrix(), &matrix_exp(&xi.hat())) < 1e-13);
    }

    #[test]
    fn se3_exp_of_opposite_twist_is_inverse(xi in twist(PI)) {
        prop_assert!(max_diff(&(-xi).exp().to_matrix(), &xi.exp().inverse().to_matrix()) < 1e-14);
    }
}

#[test]
fn exp_and_log_of_zero_are_exactly_the_identity_and_zero() {
    assert_eq!(SO3::exp(&Vector3::zeros()).matrix(), Matrix3::identity());
    assert_eq!(SO3::identity().log(), Vector3::zeros());
    assert_eq!(Twist::zero().exp(), SE3::identity());
    assert_eq!(SE3::identity().log(), Twist::zero());
}

/// The matrix-exponential reference is itself good to a few 1e-15 at angles near π.
const REFERENCE_TOL: f64 = 1e-14;

#[test]
fn so3_exp_log_round_trip_is_precise_at_fixed_hard_angles() {
    for w in fixed_rotation_vectors() {
        let r = SO3::exp(&w);
        let back = r.log();
        // A few ulps of the angle: relative near 0 (series branch), near π (symmetric-part branch).
        let d = max_diff(&back, &w);
        assert!(d <= 4.0 * f64::EPSILON * w.norm(), "|ω| = {:e}: log(exp ω) − ω = {d:e}", w.norm());
        let d = max_diff(&SO3::exp(&back).matrix(), &r.matrix());
        assert!(d <= 4.0 * f64::EPSILON, "|ω| = {:e}: exp(log R) − R = {d:e}", w.norm());
        let d = max_diff(&r.matrix(), &matrix_exp(&SO3::hat(&w)));
        assert!(d < REFERENCE_TOL, "|ω| = {:e}: exp − matrix exponential = {d:e}", w.norm());
        let d = max_diff(&r.inverse().log(), &-w);
        assert!(d <= 4.0 * f64::EPSILON * w.norm(), "|ω| = {:e}: log(R⁻¹) + ω = {d:e}", w.norm());
    }
}

#[test]
fn se3_exp_log_round_trip_is_precise_at_fixed_hard_angles() {
    for xi in fixed_twists() {
        let x = xi.to_vector();
        let tol = 8.0 * f64::EPSILON * x.norm();
        let t = xi.exp();
        let back = t.log();
        let d = max_diff(&back.to_vector(), &x);
        assert!(d <= tol, "ξ = {x:?}: log(exp ξ) − ξ = {d:e}");
        let d = max_diff(&back.exp().to_matrix(), &t.to_matrix());
        assert!(d <= 4.0 * f64::EPSILON, "ξ = {x:?}: exp(log T) − T = {d:e}");
        let d = max_diff(&t.to_matrix(), &matrix_exp(&xi.hat()));
        assert!(d < REFERENCE_TOL, "ξ = {x:?}: exp − matrix exponential = {d:e}");
        let d = max_diff(&t.inverse().log().to_vector(), &-x);
        assert!(d <= tol, "ξ = {x:?}: log(T⁻¹) + ξ = {d:e}");
    }
}

#[test]
fn so3_log_at_exactly_pi_has_angle_pi_and_the_axis_up_to_sign() {
    let axes = [
        Vector3::x(),
        Vector3::y(),
        Vector3::z(),
        -Vector3::z(),
        Vector3::new(1.0, 1.0, 0.0).normalize(),
        Vector3::new(0.3, -0.5, 0.8).normalize(),
        Vector3::new(-1.0, 2.0, 0.5).normalize(),
        Vector3::new(1.0, 1.0, 1.0).normalize(),
    ];
    for axis in axes {
        // Build R = 2 a aᵀ − I directly: the rotation by exactly π, free of sin(π) ≠ 0 rounding.
        let r = SO3::from_matrix_unchecked(axis * axis.transpose() * 2.0 - Matrix3::identity());
        for rotation in [r, SO3::exp(&(axis * PI))] {
            let w = rotation.log();
            assert!((w.norm() - PI).abs() < 1e-15, "axis {axis:?}: angle {}", w.norm());
            let along = w / PI;
            let d = max_diff(&along, &axis).min(max_diff(&along, &-axis));
            assert!(d < 1e-15, "axis {axis:?}: log gave {w:?}");
            assert!(max_diff(&SO3::exp(&w).matrix(), &rotation.matrix()) < 1e-15);
        }
    }
}

#[test]
fn so3_log_just_below_pi_keeps_the_sign_of_the_rotation() {
    let axis = Vector3::new(-1.0, 2.0, 0.5).normalize();
    for epsilon in [1e-3, 1e-6, 1e-9] {
        for signed in [axis, -axis] {
            let w = signed * (PI - epsilon);
            let back = SO3::exp(&w).log();
            assert!(max_diff(&back, &w) < 1e-14, "π − {epsilon:e}: {back:?} vs {w:?}");
        }
    }
}

#[test]
fn se3_log_at_exactly_pi_reproduces_the_transform() {
    for axis in [Vector3::z(), Vector3::new(0.3, -0.5, 0.8).normalize()] {
        let rotation = SO3::from_matrix_unchecked(axis * axis.transpose() * 2.0 - Matrix3::identity());
        let t = SE3::new(rotation, Vector3::new(0.4, -1.2, 2.0));
        let xi = t.log();
        assert!((xi.w.norm() - PI).abs() < 1e-15);
        assert!(max_diff(&xi.exp().to_matrix(), &t.to_matrix()) < 1e-14, "ξ = {:?}", xi.to_vector());
    }
}

#[test]
fn se3_exp_of_pure_translation_twist_is_that_translation() {
    let v = Vector3::new(0.5, -1.5, 2.5);
    let t = Twist::new(v, Vector3::zeros()).exp();
    assert_eq!(t.translation(), v);
    assert_eq!(t.rotation().matrix(), Matrix3::identity());
    assert_eq!(t.log(), Twist::new(v, Vector3::zeros()));
}
