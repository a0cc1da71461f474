//! Group axioms of SO(3) and SE(3): associativity, identity, inverse, inverse of a product, and
//! agreement of composition and action with plain matrix arithmetic.

mod common;

use common::{fixed_twists, max_diff, se3, so3, vector3};
use lie::{Matrix3, SE3, SO3};
use proptest::prelude::*;

const TOL: f64 = 1e-12;

proptest! {
    #[test]
    fn so3_composition_is_associative(a in so3(), b in so3(), c in so3()) {
        prop_assert!(max_diff(&((a * b) * c).matrix(), &(a * (b * c)).matrix()) < TOL);
    }

    #[test]
    fn so3_identity_is_neutral_on_both_sides(a in so3()) {
        prop_assert_eq!((SO3::identity() * a).matrix(), a.matrix());
        prop_assert_eq!((a * SO3::identity()).matrix(), a.matrix());
    }

    #[test]
    fn so3_inverse_composes_to_identity_on_both_sides(a in so3()) {
        prop_assert!(max_diff(&(a * a.inverse()).matrix(), &Matrix3::identity()) < TOL);
        prop_assert!(max_diff(&(a.inverse() * a).matrix(), &Matrix3::identity()) < TOL);
    }

    #[test]
    fn so3_inverse_of_product_is_product_of_inverses_reversed(a in so3(), b in so3()) {
        prop_assert!(max_diff(&(a * b).inverse().matrix(), &(b.inverse() * a.inverse()).matrix()) < TOL);
    }

    #[test]
    fn so3_compose_is_the_matrix_product(a in so3(), b in so3()) {
        prop_assert!(max_diff(&(a * b).matrix(), &(a.matrix() * b.matrix())) < TOL);
    }

    #[test]
    fn so3_action_is_a_homomorphism_and_preserves_length(a in so3(), b in so3(), x in vector3(5.0)) {
        prop_assert!(max_diff(&(a * b).act(&x), &a.act(&b.act(&x))) < TOL);
        prop_assert!((a.act(&x).norm() - x.norm()).abs() < TOL);
    }

    #[test]
    fn so3_exp_is_orthonormal_with_unit_determinant(a in so3()) {
        let m = a.matrix();
        prop_assert!(max_diff(&(m.transpose() * m), &Matrix3::identity()) < TOL);
        prop_assert!((m.determinant() - 1.0).abs() < TOL);
    }

    #[test]
    fn se3_composition_is_associative(a in se3(), b in se3(), c in se3()) {
        prop_assert!(max_diff(&((a * b) * c).to_matrix(), &(a * (b * c)).to_matrix()) < 1e-11);
    }

    #[test]
    fn se3_identity_is_neutral_on_both_sides(a in se3()) {
        prop_assert_eq!((SE3::identity() * a).to_matrix(), a.to_matrix());
        prop_assert_eq!((a * SE3::identity()).to_matrix(), a.to_matrix());
    }

    #[test]
    fn se3_inverse_composes_to_identity_on_both_sides(a in se3()) {
        prop_assert!(max_diff(&(a * a.inverse()).to_matrix(), &SE3::identity().to_matrix()) < TOL);
        prop_assert!(max_diff(&(a.inverse() * a).to_matrix(), &SE3::identity().to_matrix()) < TOL);
    }

    #[test]
    fn se3_inverse_of_product_is_product_of_inverses_reversed(a in se3(), b in se3()) {
        let lhs = (a * b).inverse().to_matrix();
        prop_assert!(max_diff(&lhs, &(b.inverse() * a.inverse()).to_matrix()) < TOL);
    }

    #[test]
    fn se3_inverse_is_the_matrix_inverse(a in se3()) {
        let inverse = a.to_matrix().try_inverse().unwrap();
        prop_assert!(max_diff(&a.inverse().to_matrix(), &inverse) < TOL);
    }

    #[test]
    fn se3_compose_is_the_homogeneous_matrix_product(a in se3(), b in se3()) {
        prop_assert!(max_diff(&(a * b).to_matrix(), &(a.to_matrix() * b.to_matrix())) < TOL);
    }

    #[test]
    fn se3_point_action_matches_homogeneous_matrix_and_composes(a in se3(), b in se3(), x in vector3(5.0)) {
        let homogeneous = a.to_matrix() * x.push(1.0);
        prop_assert!(max_diff(&a.transform_point(&x), &homogeneous.xyz()) < TOL);
        prop_assert!(max_diff(&(a * b).transform_point(&x), &a.transform_point(&b.transform_point(&x))) < 1e-11);
    }

    #[test]
    fn se3_parts_round_trip_through_new(a in se3()) {
        let rebuilt = SE3::new(a.rotation(), a.translation());
        prop_assert_eq!(rebuilt, a);
    }
}

#[test]
fn se3_pure_translation_moves_points_without_rotating() {
    let t = SE3::from_translation(lie::Vector3::new(1.0, -2.0, 3.0));
    assert_eq!(t.rotation().matrix(), Matrix3::identity());
    assert_eq!(t.transform_point(&lie::Vector3::new(0.5, 0.5, 0.5)), lie::Vector3::new(1.5, -1.5, 3.5));
}

#[test]
fn se3_group_axioms_hold_on_the_fixed_hard_examples() {
    // Sophus style: every triple of the fixed examples (identity, tiny angles, branch switches, π − 1e-6).
    let examples: Vec<SE3> = fixed_twists().iter().map(|xi| xi.exp()).collect();
    let identity = SE3::identity().to_matrix();
    for a in &examples {
        assert!(max_diff(&(*a * a.inverse()).to_matrix(), &identity) < TOL);
        assert!(max_diff(&(a.inverse() * *a).to_matrix(), &identity) < TOL);
        for b in &examples {
            let lhs = (*a * *b).inverse().to_matrix();
            assert!(max_diff(&lhs, &(b.inverse() * a.inverse()).to_matrix()) < TOL);
            for c in examples.iter().step_by(5) {
                assert!(max_diff(&((*a * *b) * *c).to_matrix(), &(*a * (*b * *c)).to_matrix()) < TOL);
            }
        }
    }
}
