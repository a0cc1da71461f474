//! hat/vee of so(3) and se(3), and the `(v, ω)` layout of a twist.

mod common;

use common::{twist, vector3};
use lie::{Matrix3, Matrix4, SO3, Twist, Vector3, Vector6};
use proptest::prelude::*;

proptest! {
    #[test]
    fn so3_vee_of_hat_is_the_vector(w in vector3(10.0)) {
        prop_assert_eq!(SO3::vee(&SO3::hat(&w)), w);
    }

    #[test]
    fn so3_hat_of_vee_is_a_skew_matrix(w in vector3(10.0)) {
        let k = SO3::hat(&w);
        prop_assert_eq!(SO3::hat(&SO3::vee(&k)), k);
        prop_assert_eq!(k.transpose(), -k);
    }

    #[test]
    fn so3_vee_reads_the_skew_part_of_any_matrix(w in vector3(10.0), s in vector3(10.0)) {
        // A symmetric addition does not change vee.
        let symmetric = s * s.transpose();
        prop_assert!((SO3::vee(&(SO3::hat(&w) + symmetric)) - w).amax() < 1e-13);
    }

    #[test]
    fn so3_hat_times_vector_is_cross_product(w in vector3(10.0), x in vector3(10.0)) {
        prop_assert!((SO3::hat(&w) * x - w.cross(&x)).amax() < 1e-12);
    }

    #[test]
    fn se3_vee_of_hat_is_the_twist(xi in twist(10.0)) {
        prop_assert_eq!(Twist::vee(&xi.hat()), xi);
    }

    #[test]
    fn se3_hat_of_vee_is_the_algebra_element(xi in twist(10.0)) {
        let m = xi.hat();
        prop_assert_eq!(Twist::vee(&m).hat(), m);
    }

    #[test]
    fn twist_vector_round_trip_keeps_v_then_omega(xi in twist(10.0)) {
        let x = xi.to_vector();
        prop_assert_eq!(Twist::from_vector(&x), xi);
        prop_assert_eq!(Vector3::new(x[0], x[1], x[2]), xi.v);
        prop_assert_eq!(Vector3::new(x[3], x[4], x[5]), xi.w);
    }

    #[test]
    fn twist_arithmetic_matches_vector_arithmetic(a in twist(3.0), b in twist(3.0), s in -2.0..2.0f64) {
        prop_assert_eq!((a + b).to_vector(), a.to_vector() + b.to_vector());
        prop_assert_eq!((a - b).to_vector(), a.to_vector() - b.to_vector());
        prop_assert_eq!((-a).to_vector(), -a.to_vector());
        prop_assert_eq!((a * s).to_vector(), a.to_vector() * s);
    }
}

#[test]
fn se3_hat_layout_is_rotation_block_then_translation_column() {
    let xi = Twist::from_vector(&Vector6::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0));
    #[rustfmt::skip]
    let expected = Matrix4::new(
        0.0, -6.0, 5.0, 1.0,
        6.0, 0.0, -4.0, 2.0,
        -5.0, 4.0, 0.0, 3.0,
        0.0, 0.0, 0.0, 0.0,
    );
    assert_eq!(xi.hat(), expected);
    assert_eq!(SO3::hat(&Vector3::new(4.0, 5.0, 6.0)), Matrix3::new(0.0, -6.0, 5.0, 6.0, 0.0, -4.0, -5.0, 4.0, 0.0));
}
