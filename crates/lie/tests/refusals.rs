//! Inputs that are not group members are refused with the numbers that explain why; nearly-rotation
//! matrices are accepted and re-orthonormalised to the nearest rotation.

mod common;

use common::{max_diff, se3, so3, vector3};
use lie::{Error, Matrix3, Matrix4, ORTHONORMALITY_TOLERANCE, SE3, SO3};
use proptest::prelude::*;

fn deviation(m: &Matrix3) -> f64 {
    (m.transpose() * m - Matrix3::identity()).norm()
}

/// A perturbation of size in `[1e-8, 10]` of either sign.
fn off_by() -> impl Strategy<Value = f64> {
    (-8.0..1.0f64, prop::bool::ANY).prop_map(|(exponent, negative)| {
        let size = 10f64.powf(exponent);
        if negative { -size } else { size }
    })
}

proptest! {
    #[test]
    fn se3_from_matrix_refuses_a_last_row_that_is_not_0001(t in se3(), column in 0usize..4, delta in off_by()) {
        let mut m = t.to_matrix();
        m[(3, column)] += delta;
        let expected = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)]];
        prop_assert_eq!(SE3::from_matrix(&m), Err(Error::NotRigid { last_row: expected }));
    }

    #[test]
    fn se3_from_matrix_refuses_a_rotation_block_far_from_a_rotation(t in se3(), scale in 1.01..3.0f64) {
        let mut m = t.to_matrix();
        let block = m.fixed_view::<3, 3>(0, 0) * scale;
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&block);
        let refused = matches!(SE3::from_matrix(&m), Err(Error::NotARotation { .. }));
        prop_assert!(refused);
    }

    #[test]
    fn so3_from_matrix_refuses_a_scaled_rotation_and_reports_its_deviation(r in so3(), scale in 1.01..3.0f64) {
        let m = r.matrix() * scale;
        match SO3::from_matrix(m) {
            Err(Error::NotARotation { deviation: d, determinant }) => {
                prop_assert!((d - deviation(&m)).abs() < 1e-12 && d > ORTHONORMALITY_TOLERANCE);
                prop_assert!((determinant - scale.powi(3)).abs() < 1e-12);
            }
            other => prop_assert!(false, "accepted or wrong error: {:?}", other),
        }
    }

    #[test]
    fn so3_from_matrix_refuses_a_reflection(r in so3()) {
        match SO3::from_matrix(-r.matrix()) {
            Err(Error::NotARotation { determinant, .. }) => prop_assert!((determinant + 1.0).abs() < 1e-12),
            other => prop_assert!(false, "accepted or wrong error: {:?}", other),
        }
    }

    #[test]
    fn so3_from_matrix_refuses_a_matrix_with_random_error_above_tolerance(r in so3(), noise in vector3(1.0)) {
        // A non-symmetric, non-scaling perturbation of size ≥ 0.01.
        let e = common::skew_axis() * noise.transpose() * 0.05 + Matrix3::identity() * 0.01;
        let m = r.matrix() + e;
        prop_assume!(deviation(&m) > ORTHONORMALITY_TOLERANCE);
        let refused = matches!(SO3::from_matrix(m), Err(Error::NotARotation { .. }));
        prop_assert!(refused);
    }

    #[test]
    fn so3_from_matrix_accepts_and_reorthonormalises_a_slightly_perturbed_rotation(
        r in so3(), a in vector3(1e-5), b in vector3(1e-5),
    ) {
        let m = r.matrix() + a * b.transpose() * 1e5 + Matrix3::from_diagonal(&a);
        prop_assume!(deviation(&m) <= ORTHONORMALITY_TOLERANCE);
        let fixed = SO3::from_matrix(m).unwrap().matrix();
        prop_assert!(deviation(&fixed) < 1e-14);
        prop_assert!((fixed.determinant() - 1.0).abs() < 1e-14);
        prop_assert!(max_diff(&fixed, &r.matrix()) < 1e-4);
    }

    #[test]
    fn so3_from_matrix_returns_the_nearest_rotation(r in so3(), s in vector3(1e-4), t in vector3(1e-4)) {
        // R (I + S) with S small and symmetric has polar factor R: R is the nearest rotation.
        // ‖S‖_F ≤ 3e-4, so the deviation ≈ 2‖S‖_F stays within tolerance.
        let symmetric = Matrix3::new(s.x, t.z, t.y, t.z, s.y, t.x, t.y, t.x, s.z);
        let m = r.matrix() * (Matrix3::identity() + symmetric);
        prop_assert!(max_diff(&SO3::from_matrix(m).unwrap().matrix(), &r.matrix()) < 1e-14);
    }
}

#[test]
fn se3_from_matrix_refuses_nan_in_the_last_row() {
    let mut m = Matrix4::identity();
    m[(3, 3)] = f64::NAN;
    assert!(matches!(SE3::from_matrix(&m), Err(Error::NotRigid { .. })));
}

#[test]
fn se3_from_matrix_accepts_a_last_row_within_1e9() {
    let mut m = Matrix4::identity();
    m[(3, 0)] = 5e-10;
    m[(3, 3)] = 1.0 - 5e-10;
    assert_eq!(SE3::from_matrix(&m).unwrap(), SE3::identity());
}

#[test]
fn se3_from_matrix_refuses_a_non_finite_translation() {
    for value in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut m = Matrix4::identity();
        m[(1, 3)] = value;
        match SE3::from_matrix(&m) {
            Err(Error::NonFiniteTranslation { translation }) => {
                assert!(translation[1].is_nan() || translation[1] == value)
            }
            other => panic!("translation {value}: {other:?}"),
        }
    }
}

#[test]
fn so3_from_matrix_refuses_zero_and_nan_matrices() {
    assert!(matches!(SO3::from_matrix(Matrix3::zeros()), Err(Error::NotARotation { .. })));
    let mut m = Matrix3::identity();
    m[(0, 1)] = f64::NAN;
    assert!(matches!(SO3::from_matrix(m), Err(Error::NotARotation { .. })));
}

#[test]
fn so3_from_matrix_accepts_deviation_just_below_tolerance_and_refuses_just_above() {
    // diag(1 + e) has deviation √3 ((1 + e)² − 1).
    let e_at = |deviation: f64| (1.0 + deviation / 3f64.sqrt()).sqrt() - 1.0;
    let below = Matrix3::identity() * (1.0 + e_at(0.99 * ORTHONORMALITY_TOLERANCE));
    let above = Matrix3::identity() * (1.0 + e_at(1.01 * ORTHONORMALITY_TOLERANCE));
    assert!(max_diff(&SO3::from_matrix(below).unwrap().matrix(), &Matrix3::identity()) < 1e-15);
    assert!(matches!(SO3::from_matrix(above), Err(Error::NotARotation { .. })));
}

#[test]
fn from_quaternion_refuses_a_norm_off_by_more_than_1e3() {
    for (q, norm) in [([1.002, 0.0, 0.0, 0.0], 1.002), ([0.0, 0.0, 0.0, 0.0], 0.0), ([0.5, 0.5, 0.5, 0.49], 0.995)] {
        match SO3::from_quaternion(q[0], q[1], q[2], q[3]) {
            Err(Error::NotAUnitQuaternion { norm: n }) => assert!((n - norm).abs() < 1e-3, "{q:?}: {n}"),
            other => panic!("{q:?}: {other:?}"),
        }
    }
    assert!(matches!(SO3::from_quaternion(f64::NAN, 0.0, 0.0, 0.0), Err(Error::NotAUnitQuaternion { .. })));
    assert!(SO3::try_from([1.0005, 0.0, 0.0, 0.0]).is_ok());
}

#[test]
fn errors_display_the_numbers_that_explain_them() {
    let rotation = SO3::from_matrix(Matrix3::identity() * 2.0).unwrap_err().to_string();
    assert!(rotation.contains("det = 8"), "{rotation}");
    let rigid = Error::NotRigid { last_row: [0.0, 0.0, 0.5, 1.0] }.to_string();
    assert!(rigid.contains("0.5"), "{rigid}");
    let quaternion = Error::NotAUnitQuaternion { norm: 1.5 }.to_string();
    assert!(quaternion.contains("1.5"), "{quaternion}");
}
