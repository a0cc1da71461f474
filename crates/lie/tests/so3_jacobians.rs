//! Left and right Jacobians of SO(3) and their inverses: finite differences at the identity, at a
//! tiny point and at random points; products with the inverses; the power series at the hard angles.

mod common;

use common::{
    central_difference3, fixed_rotation_vectors, jacobian_points, left_jacobian_series, max_diff, rotation_vector,
};
use lie::{Matrix3, SO3, Vector3};
use proptest::prelude::*;

/// Central-difference step: truncation error ~h², rounding ~1e-16/h, both below 1e-10.
const H: f64 = 1e-5;
/// Agreement demanded of an analytic Jacobian with its finite-difference estimate.
const FD_TOL: f64 = 1e-9;

/// `∂/∂δ log(exp(ω + δ) exp(ω)⁻¹)` at δ = 0, which is `J_l(ω)`.
fn left_fd(w: &Vector3) -> Matrix3 {
    let inverse = SO3::exp(w).inverse();
    central_difference3(|d| (SO3::exp(&(w + d)) * inverse).log(), H)
}

/// `∂/∂δ log(exp(ω)⁻¹ exp(ω + δ))` at δ = 0, which is `J_r(ω)`.
fn right_fd(w: &Vector3) -> Matrix3 {
    let inverse = SO3::exp(w).inverse();
    central_difference3(|d| (inverse * SO3::exp(&(w + d))).log(), H)
}

/// `∂/∂δ log(exp(δ) exp(ω))` at δ = 0, which is `J_l⁻¹(ω)`.
fn left_inverse_fd(w: &Vector3) -> Matrix3 {
    let r = SO3::exp(w);
    central_difference3(|d| (SO3::exp(d) * r).log(), H)
}

/// `∂/∂δ log(exp(ω) exp(δ))` at δ = 0, which is `J_r⁻¹(ω)`.
fn right_inverse_fd(w: &Vector3) -> Matrix3 {
    let r = SO3::exp(w);
    central_difference3(|d| (r * SO3::exp(d)).log(), H)
}

fn check_all_against_finite_differences(w: &Vector3, label: &str) {
    let cases: [(&str, Matrix3, Matrix3); 4] = [
        ("J_l", SO3::left_jacobian(w), left_fd(w)),
        ("J_r", SO3::right_jacobian(w), right_fd(w)),
        ("J_l⁻¹", SO3::left_jacobian_inverse(w), left_inverse_fd(w)),
        ("J_r⁻¹", SO3::right_jacobian_inverse(w), right_inverse_fd(w)),
    ];
    for (name, analytic, numeric) in cases {
        let d = max_diff(&analytic, &numeric);
        assert!(d < FD_TOL, "{name} at {label} ω = {w:?}: analytic − finite difference = {d:e}");
    }
}

#[test]
fn so3_jacobians_match_finite_differences_at_identity_tiny_and_random_points() {
    for (label, xi) in jacobian_points() {
        check_all_against_finite_differences(&xi.w, label);
    }
}

#[test]
fn so3_jacobians_at_identity_are_the_identity() {
    let zero = Vector3::zeros();
    for j in [
        SO3::left_jacobian(&zero),
        SO3::right_jacobian(&zero),
        SO3::left_jacobian_inverse(&zero),
        SO3::right_jacobian_inverse(&zero),
    ] {
        assert_eq!(j, Matrix3::identity());
    }
}

#[test]
fn so3_jacobians_match_their_power_series_at_fixed_hard_angles() {
    for w in fixed_rotation_vectors() {
        let series = left_jacobian_series(&SO3::hat(&w));
        let d = max_diff(&SO3::left_jacobian(&w), &series);
        assert!(d < 1e-15 * 4.0, "J_l at |ω| = {:e}: {d:e}", w.norm());
        let series_right = left_jacobian_series(&SO3::hat(&-w));
        let d = max_diff(&SO3::right_jacobian(&w), &series_right);
        assert!(d < 1e-15 * 4.0, "J_r at |ω| = {:e}: {d:e}", w.norm());
    }
}

#[test]
fn so3_jacobians_times_their_inverses_are_identity_at_fixed_hard_angles() {
    for w in fixed_rotation_vectors() {
        let left = SO3::left_jacobian(&w) * SO3::left_jacobian_inverse(&w);
        let right = SO3::right_jacobian(&w) * SO3::right_jacobian_inverse(&w);
        assert!(max_diff(&left, &Matrix3::identity()) < 1e-14, "left at |ω| = {:e}", w.norm());
        assert!(max_diff(&right, &Matrix3::identity()) < 1e-14, "right at |ω| = {:e}", w.norm());
    }
}

proptest! {
    #[test]
    fn so3_jacobians_match_finite_differences_at_random_points(w in rotation_vector(2.5)) {
        check_all_against_finite_differences(&w, "random");
    }

    #[test]
    fn so3_jacobians_times_their_inverses_are_identity(w in rotation_vector(common::MAX_ANGLE)) {
        let left = SO3::left_jacobian(&w) * SO3::left_jacobian_inverse(&w);
        let right = SO3::right_jacobian_inverse(&w) * SO3::right_jacobian(&w);
        prop_assert!(max_diff(&left, &Matrix3::identity()) < 1e-13);
        prop_assert!(max_diff(&right, &Matrix3::identity()) < 1e-13);
    }

    #[test]
    fn so3_left_jacobian_is_rotation_times_right_jacobian(w in rotation_vector(common::MAX_ANGLE)) {
        let rhs = SO3::exp(&w).matrix() * SO3::right_jacobian(&w);
        prop_assert!(max_diff(&SO3::left_jacobian(&w), &rhs) < 1e-14);
    }

    #[test]
    fn so3_left_jacobian_fixes_its_own_rotation_vector(w in rotation_vector(common::MAX_ANGLE)) {
        prop_assert!(max_diff(&(SO3::left_jacobian(&w) * w), &w) < 1e-14);
        prop_assert!(max_diff(&(SO3::left_jacobian_inverse(&w) * w), &w) < 1e-14);
    }

    #[test]
    fn so3_left_jacobian_matches_its_power_series(w in rotation_vector(common::MAX_ANGLE)) {
        prop_assert!(max_diff(&SO3::left_jacobian(&w), &left_jacobian_series(&SO3::hat(&w))) < 1e-14);
    }
}
