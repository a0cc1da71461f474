//! The group adjoint `Ad(T)` and the algebra adjoint `ad(ξ)` of SE(3) in `(v, ω)` order.

mod common;

use common::{fixed_twists, matrix_exp, max_diff, se3, twist};
use lie::{Matrix6, SE3, Twist, Vector3};
use proptest::prelude::*;
use std::f64::consts::PI;

/// `vee(T ξ^ T⁻¹)`, the definition the adjoint must match.
fn conjugate(t: &SE3, xi: &Twist) -> Twist {
    Twist::vee(&(t.to_matrix() * xi.hat() * t.inverse().to_matrix()))
}

proptest! {
    #[test]
    fn adjoint_times_twist_is_vee_of_conjugated_hat(t in se3(), xi in twist(PI)) {
        let lhs = t.adjoint() * xi.to_vector();
        prop_assert!(max_diff(&lhs, &conjugate(&t, &xi).to_vector()) < 1e-13);
    }

    #[test]
    fn adjoint_columns_are_conjugated_basis_twists(t in se3()) {
        // Sophus' check: column i of Ad(T) is vee(T hat(e_i) T⁻¹).
        let ad = t.adjoint();
        for i in 0..6 {
            let e = Twist::from_vector(&Matrix6::identity().column(i).into_owned());
            prop_assert!(max_diff(&ad.column(i).into_owned(), &conjugate(&t, &e).to_vector()) < 1e-12);
        }
    }

    #[test]
    fn adjoint_moves_a_right_perturbation_to_the_left(t in se3(), xi in twist(1.0)) {
        let lhs = t * xi.exp();
        let rhs = Twist::from_vector(&(t.adjoint() * xi.to_vector())).exp() * t;
        prop_assert!(max_diff(&lhs.to_matrix(), &rhs.to_matrix()) < 1e-11);
    }

    #[test]
    fn adjoint_is_a_homomorphism(a in se3(), b in se3()) {
        prop_assert!(max_diff(&(a * b).adjoint(), &(a.adjoint() * b.adjoint())) < 1e-11);
    }

    #[test]
    fn adjoint_of_inverse_is_inverse_of_adjoint(t in se3()) {
        prop_assert!(max_diff(&(t.inverse().adjoint() * t.adjoint()), &Matrix6::identity()) < 1e-12);
    }

    #[test]
    fn algebra_adjoint_is_the_lie_bracket(xi in twist(PI), eta in twist(PI)) {
        let (a, b) = (xi.hat(), eta.hat());
        let bracket = Twist::vee(&(a * b - b * a));
        prop_assert!(max_diff(&(xi.ad() * eta.to_vector()), &bracket.to_vector()) < 1e-12);
    }

    #[test]
    fn algebra_adjoint_is_antisymmetric(xi in twist(PI), eta in twist(PI)) {
        let lhs = xi.ad() * eta.to_vector();
        prop_assert!(max_diff(&lhs, &-(eta.ad() * xi.to_vector())) < 1e-14);
    }

    #[test]
    fn adjoint_of_exp_is_exp_of_algebra_adjoint(xi in twist(PI)) {
        prop_assert!(max_diff(&xi.exp().adjoint(), &matrix_exp(&xi.ad())) < 1e-13);
    }

    #[test]
    fn twist_is_fixed_by_adjoint_of_its_own_exponential(xi in twist(PI)) {
        // ad(ξ) ξ = 0, hence Ad(exp ξ) ξ = ξ.
        prop_assert!(max_diff(&(xi.exp().adjoint() * xi.to_vector()), &xi.to_vector()) < 1e-12);
    }
}

#[test]
fn adjoint_of_exp_is_exp_of_algebra_adjoint_at_fixed_hard_twists() {
    for xi in fixed_twists() {
        let d = max_diff(&xi.exp().adjoint(), &matrix_exp(&xi.ad()));
        assert!(d < 1e-13, "ξ = {:?}: {d:e}", xi.to_vector());
    }
}

#[test]
fn adjoint_of_identity_is_identity_and_of_translation_has_hat_block() {
    assert_eq!(SE3::identity().adjoint(), Matrix6::identity());
    let t = SE3::from_translation(Vector3::new(1.0, 2.0, 3.0));
    let ad = t.adjoint();
    // A pure rotation about the origin, seen from a frame translated by t, acquires v = t × ω.
    let w = Vector3::new(0.0, 0.0, 1.0);
    let moved = Twist::from_vector(&(ad * Twist::new(Vector3::zeros(), w).to_vector()));
    assert_eq!(moved.w, w);
    assert_eq!(moved.v, Vector3::new(1.0, 2.0, 3.0).cross(&w));
}
