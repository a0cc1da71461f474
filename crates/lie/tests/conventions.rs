//! The conventions the crate doc states, checked one by one by central differences under the
//! stated left-perturbation derivative `Df(T) = ∂ log(f(exp(δ^) T) f(T)⁻¹)^∨ / ∂δ`. (The
//! derivatives of exp and log, `J_l` and `J_l⁻¹`, are checked in the Jacobian test files.)

mod common;

use common::{central_difference3, central_difference6, max_diff, se3, so3, vector3};
use lie::{Matrix3, Matrix6, SE3, SO3, Twist, Vector3, Vector6};
use nalgebra::SMatrix;
use proptest::prelude::*;

const H: f64 = 1e-5;
const FD_TOL: f64 = 1e-9;

fn perturb(d: &Vector6, t: &SE3) -> SE3 {
    Twist::from_vector(d).exp() * *t
}

/// The left-perturbation derivative of a map between SE(3) and SE(3).
fn se3_derivative(f: impl Fn(&SE3) -> SE3, t: &SE3) -> Matrix6 {
    let inverse = f(t).inverse();
    central_difference6(|d| (f(&perturb(d, t)) * inverse).log().to_vector(), H)
}

/// The left-perturbation derivative of a map between SO(3) and SO(3).
fn so3_derivative(f: impl Fn(&SO3) -> SO3, r: &SO3) -> Matrix3 {
    let inverse = f(r).inverse();
    central_difference3(|d| (f(&(SO3::exp(d) * *r)) * inverse).log(), H)
}

/// `[I, −p^]`, the derivative of the action on a point as the crate doc states it.
fn point_jacobian(p: &Vector3) -> SMatrix<f64, 3, 6> {
    let mut j = SMatrix::<f64, 3, 6>::zeros();
    j.fixed_view_mut::<3, 3>(0, 0).copy_from(&Matrix3::identity());
    j.fixed_view_mut::<3, 3>(0, 3).copy_from(&-SO3::hat(p));
    j
}

proptest! {
    #[test]
    fn se3_derivative_of_composition_is_identity_in_left_factor_and_adjoint_in_right(t in se3(), u in se3()) {
        let left = se3_derivative(|x| *x * u, &t);
        let right = se3_derivative(|x| t * *x, &u);
        prop_assert!(max_diff(&left, &Matrix6::identity()) < FD_TOL);
        prop_assert!(max_diff(&right, &t.adjoint()) < FD_TOL);
    }

    #[test]
    fn se3_derivative_of_inverse_is_minus_adjoint_of_inverse(t in se3()) {
        let numeric = se3_derivative(|x| x.inverse(), &t);
        prop_assert!(max_diff(&numeric, &-t.inverse().adjoint()) < FD_TOL);
    }

    #[test]
    fn se3_derivative_of_point_action_is_identity_then_minus_hat_of_image(t in se3(), x in vector3(2.0)) {
        let mut numeric = SMatrix::<f64, 3, 6>::zeros();
        for i in 0..6 {
            let mut e = Vector6::zeros();
            e[i] = H;
            let column = (perturb(&e, &t).transform_point(&x) - perturb(&-e, &t).transform_point(&x)) / (2.0 * H);
            numeric.set_column(i, &column);
        }
        prop_assert!(max_diff(&numeric, &point_jacobian(&t.transform_point(&x))) < FD_TOL);
    }

    #[test]
    fn se3_left_translation_perturbation_moves_image_points_in_the_output_frame(t in se3(), x in vector3(2.0), v in vector3(1.0)) {
        // exp((v, 0)^) T x = T x + v: δ is expressed in the frame T maps into.
        let moved = Twist::new(v, Vector3::zeros()).exp() * t;
        prop_assert!(max_diff(&moved.transform_point(&x), &(t.transform_point(&x) + v)) < 1e-14);
    }

    #[test]
    fn se3_error_of_a_left_perturbed_pose_is_the_perturbation(t in se3(), v in vector3(0.5), w in vector3(0.5)) {
        let d = Twist::new(v, w);
        let perturbed = d.exp() * t;
        prop_assert!(max_diff(&(perturbed * t.inverse()).log().to_vector(), &d.to_vector()) < 1e-12);
    }

    #[test]
    fn so3_derivative_of_composition_is_identity_in_left_factor_and_rotation_in_right(r in so3(), s in so3()) {
        prop_assert!(max_diff(&so3_derivative(|x| *x * s, &r), &Matrix3::identity()) < FD_TOL);
        prop_assert!(max_diff(&so3_derivative(|x| r * *x, &s), &r.matrix()) < FD_TOL);
    }

    #[test]
    fn so3_derivative_of_inverse_is_minus_inverse_rotation(r in so3()) {
        prop_assert!(max_diff(&so3_derivative(|x| x.inverse(), &r), &-r.inverse().matrix()) < FD_TOL);
    }

    #[test]
    fn so3_derivative_of_point_action_is_minus_hat_of_image(r in so3(), x in vector3(2.0)) {
        let numeric = central_difference3(|d| (SO3::exp(d) * r).act(&x), H);
        prop_assert!(max_diff(&numeric, &-SO3::hat(&r.act(&x))) < FD_TOL);
    }
}
