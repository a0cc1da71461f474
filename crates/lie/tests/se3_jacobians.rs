//! Left and right Jacobians of SE(3) in `(v, ω)` order and their inverses: finite differences at the
//! identity, at a tiny point and at random points; products with the inverses; the power series
//! `Σ ad(ξ)^k / (k + 1)!` at the hard angles, where the closed forms switch to series.

mod common;

use common::{
    MAX_ANGLE, central_difference6, fixed_twists, jacobian_points, left_jacobian_series, max_diff, rotation_vector,
    twist, vector3,
};
use lie::{Matrix6, SE3, Twist};
use proptest::prelude::*;

/// Central-difference step: truncation error ~h², rounding ~1e-16/h, both below 1e-10.
const H: f64 = 1e-5;
/// Agreement demanded of an analytic Jacobian with its finite-difference estimate.
const FD_TOL: f64 = 1e-9;

fn add(xi: &Twist, d: &lie::Vector6) -> Twist {
    Twist::from_vector(&(xi.to_vector() + d))
}

/// `∂/∂δ log(exp(ξ + δ) exp(ξ)⁻¹)` at δ = 0, which is `J_l(ξ)`.
fn left_fd(xi: &Twist) -> Matrix6 {
    let inverse = xi.exp().inverse();
    central_difference6(|d| (add(xi, d).exp() * inverse).log().to_vector(), H)
}

/// `∂/∂δ log(exp(ξ)⁻¹ exp(ξ + δ))` at δ = 0, which is `J_r(ξ)`.
fn right_fd(xi: &Twist) -> Matrix6 {
    let inverse = xi.exp().inverse();
    central_difference6(|d| (inverse * add(xi, d).exp()).log().to_vector(), H)
}

/// `∂/∂δ log(exp(δ) exp(ξ))` at δ = 0, which is `J_l⁻¹(ξ)`.
fn left_inverse_fd(xi: &Twist) -> Matrix6 {
    let t = xi.exp();
    central_difference6(|d| (Twist::from_vector(d).exp() * t).log().to_vector(), H)
}

/// `∂/∂δ log(exp(ξ) exp(δ))` at δ = 0, which is `J_r⁻¹(ξ)`.
fn right_inverse_fd(xi: &Twist) -> Matrix6 {
    let t = xi.exp();
    central_difference6(|d| (t * Twist::from_vector(d).exp()).log().to_vector(), H)
}

fn check_all_against_finite_differences(xi: &Twist, label: &str) {
    let cases: [(&str, Matrix6, Matrix6); 4] = [
        ("J_l", SE3::left_jacobian(xi), left_fd(xi)),
        ("J_r", SE3::right_jacobian(xi), right_fd(xi)),
        ("J_l⁻¹", SE3::left_jacobian_inverse(xi), left_inverse_fd(xi)),
        ("J_r⁻¹", SE3::right_jacobian_inverse(xi), right_inverse_fd(xi)),
    ];
    for (name, analytic, numeric) in cases {
        let d = max_diff(&analytic, &numeric);
        assert!(d < FD_TOL, "{name} at {label} ξ = {:?}: analytic − finite difference = {d:e}", xi.to_vector());
    }
}

#[test]
fn se3_jacobians_match_finite_differences_at_identity_tiny_and_random_points() {
    for (label, xi) in jacobian_points() {
        check_all_against_finite_differences(&xi, label);
    }
}

#[test]
fn se3_jacobians_at_identity_are_the_identity() {
    let zero = Twist::zero();
    for j in [
        SE3::left_jacobian(&zero),
        SE3::right_jacobian(&zero),
        SE3::left_jacobian_inverse(&zero),
        SE3::right_jacobian_inverse(&zero),
    ] {
        assert_eq!(j, Matrix6::identity());
    }
}

#[test]
fn se3_jacobians_match_their_power_series_at_fixed_hard_angles() {
    for xi in fixed_twists() {
        let d = max_diff(&SE3::left_jacobian(&xi), &left_jacobian_series(&xi.ad()));
        assert!(d < 1e-14, "J_l at ξ = {:?}: {d:e}", xi.to_vector());
        let d = max_diff(&SE3::right_jacobian(&xi), &left_jacobian_series(&(-xi).ad()));
        assert!(d < 1e-14, "J_r at ξ = {:?}: {d:e}", xi.to_vector());
    }
}

#[test]
fn se3_jacobians_times_their_inverses_are_identity_at_fixed_hard_angles() {
    for xi in fixed_twists() {
        let left = SE3::left_jacobian(&xi) * SE3::left_jacobian_inverse(&xi);
        let right = SE3::right_jacobian(&xi) * SE3::right_jacobian_inverse(&xi);
        assert!(max_diff(&left, &Matrix6::identity()) < 1e-14, "left at ξ = {:?}", xi.to_vector());
        assert!(max_diff(&right, &Matrix6::identity()) < 1e-14, "right at ξ = {:?}", xi.to_vector());
    }
}

proptest! {
    #[test]
    fn se3_jacobians_match_finite_differences_at_random_points(xi in twist(2.5)) {
        check_all_against_finite_differences(&xi, "random");
    }

    #[test]
    fn se3_jacobians_times_their_inverses_are_identity(xi in twist(MAX_ANGLE)) {
        let left = SE3::left_jacobian(&xi) * SE3::left_jacobian_inverse(&xi);
        let right = SE3::right_jacobian_inverse(&xi) * SE3::right_jacobian(&xi);
        prop_assert!(max_diff(&left, &Matrix6::identity()) < 1e-13);
        prop_assert!(max_diff(&right, &Matrix6::identity()) < 1e-13);
    }

    #[test]
    fn se3_left_jacobian_is_adjoint_times_right_jacobian(xi in twist(MAX_ANGLE)) {
        let rhs = xi.exp().adjoint() * SE3::right_jacobian(&xi);
        prop_assert!(max_diff(&SE3::left_jacobian(&xi), &rhs) < 1e-13);
    }

    #[test]
    fn se3_left_jacobian_fixes_its_own_twist(xi in twist(MAX_ANGLE)) {
        let x = xi.to_vector();
        prop_assert!(max_diff(&(SE3::left_jacobian(&xi) * x), &x) < 1e-13);
        prop_assert!(max_diff(&(SE3::left_jacobian_inverse(&xi) * x), &x) < 1e-13);
    }

    #[test]
    fn se3_left_jacobian_matches_its_power_series(xi in twist(MAX_ANGLE)) {
        prop_assert!(max_diff(&SE3::left_jacobian(&xi), &left_jacobian_series(&xi.ad())) < 1e-13);
    }

    #[test]
    fn se3_left_jacobian_maps_twist_perturbations_to_left_perturbations(
        xi in twist(2.5), v in vector3(1e-3), w in rotation_vector(1e-3),
    ) {
        // First order: exp(ξ + δ) = exp(J_l(ξ) δ) exp(ξ) up to O(|δ|²).
        let d = Twist::new(v, w);
        let lhs = (xi + d).exp();
        let rhs = Twist::from_vector(&(SE3::left_jacobian(&xi) * d.to_vector())).exp() * xi.exp();
        let size = d.to_vector().norm();
        prop_assert!(max_diff(&lhs.to_matrix(), &rhs.to_matrix()) < 10.0 * size * size + 1e-15);
    }
}
