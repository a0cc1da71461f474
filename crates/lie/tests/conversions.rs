//! Conversions of rotations and transforms: quaternion (Hamilton, `[w, x, y, z]`), roll-pitch-yaw,
//! rotation vector, 4×4 matrix and the serialised form.

mod common;

use common::{max_diff, rot_x, rot_y, rot_z, se3, so3, unit_vector};
use lie::{Matrix3, SE3, SO3, Vector3};
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// The Hamilton product `p q` of quaternions `[w, x, y, z]`.
fn hamilton(p: [f64; 4], q: [f64; 4]) -> [f64; 4] {
    let [a, b, c, d] = p;
    let [e, f, g, h] = q;
    [
        a * e - b * f - c * g - d * h,
        a * f + b * e + c * h - d * g,
        a * g - b * h + c * e + d * f,
        a * h + b * g - c * f + d * e,
    ]
}

/// `q` or `−q`, whichever is closer to `reference`, as the largest componentwise difference.
fn quaternion_distance(q: [f64; 4], reference: [f64; 4]) -> f64 {
    let plus = q.iter().zip(reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    let minus = q.iter().zip(reference).map(|(a, b)| (a + b).abs()).fold(0.0, f64::max);
    plus.min(minus)
}

fn unit_quaternion() -> impl Strategy<Value = [f64; 4]> {
    (unit_vector(), 0.0..=PI).prop_map(|(axis, angle)| {
        let (s, c) = (0.5 * angle).sin_cos();
        [c, axis.x * s, axis.y * s, axis.z * s]
    })
}

fn rpy_away_from_gimbal_lock() -> impl Strategy<Value = (f64, f64, f64)> {
    (-PI + 1e-3..PI - 1e-3, -FRAC_PI_2 + 1e-3..FRAC_PI_2 - 1e-3, -PI + 1e-3..PI - 1e-3)
}

proptest! {
    #[test]
    fn quaternion_round_trip_reproduces_the_rotation(r in so3()) {
        let [w, x, y, z] = r.to_quaternion();
        prop_assert!(max_diff(&SO3::from_quaternion(w, x, y, z).unwrap().matrix(), &r.matrix()) < 1e-15 * 4.0);
    }

    #[test]
    fn quaternion_round_trip_reproduces_the_quaternion_up_to_sign(q in unit_quaternion()) {
        let back = SO3::from_quaternion(q[0], q[1], q[2], q[3]).unwrap().to_quaternion();
        prop_assert!(quaternion_distance(back, q) < 1e-15 * 4.0, "{q:?} came back as {back:?}");
    }

    #[test]
    fn quaternion_output_is_unit_with_nonnegative_scalar(r in so3()) {
        let q = r.to_quaternion();
        prop_assert!(q[0] >= 0.0);
        prop_assert!((q.iter().map(|v| v * v).sum::<f64>() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn quaternion_of_exp_is_half_angle_cosine_and_sine_times_axis(axis in unit_vector(), angle in 0.0..PI) {
        let (s, c) = (0.5 * angle).sin_cos();
        let expected = [c, axis.x * s, axis.y * s, axis.z * s];
        prop_assert!(quaternion_distance(SO3::exp(&(axis * angle)).to_quaternion(), expected) < 1e-15 * 4.0);
    }

    #[test]
    fn quaternion_product_is_rotation_composition(p in unit_quaternion(), q in unit_quaternion()) {
        let rp = SO3::from_quaternion(p[0], p[1], p[2], p[3]).unwrap();
        let rq = SO3::from_quaternion(q[0], q[1], q[2], q[3]).unwrap();
        let pq = hamilton(p, q);
        let product = SO3::from_quaternion(pq[0], pq[1], pq[2], pq[3]).unwrap();
        prop_assert!(max_diff(&product.matrix(), &(rp * rq).matrix()) < 1e-14);
    }

    #[test]
    fn quaternion_within_tolerance_is_normalised(q in unit_quaternion(), scale in 0.9991..1.0009f64) {
        let r = SO3::from_quaternion(q[0] * scale, q[1] * scale, q[2] * scale, q[3] * scale).unwrap();
        let exact = SO3::from_quaternion(q[0], q[1], q[2], q[3]).unwrap();
        prop_assert!(max_diff(&r.matrix(), &exact.matrix()) < 1e-15 * 4.0);
    }

    #[test]
    fn rpy_is_yaw_about_z_then_pitch_about_y_then_roll_about_x(roll in -PI..PI, pitch in -PI..PI, yaw in -PI..PI) {
        let expected = rot_z(yaw) * rot_y(pitch) * rot_x(roll);
        prop_assert!(max_diff(&SO3::from_rpy(roll, pitch, yaw).matrix(), &expected) < 1e-15 * 4.0);
    }

    #[test]
    fn rpy_round_trip_recovers_the_angles_away_from_gimbal_lock((roll, pitch, yaw) in rpy_away_from_gimbal_lock()) {
        let [r, p, y] = SO3::from_rpy(roll, pitch, yaw).to_rpy();
        prop_assert!((r - roll).abs() < 1e-12 && (p - pitch).abs() < 1e-12 && (y - yaw).abs() < 1e-12,
            "({roll}, {pitch}, {yaw}) came back as ({r}, {p}, {y})");
    }

    #[test]
    fn rpy_of_any_rotation_reproduces_it_with_pitch_in_half_range(rotation in so3()) {
        let [r, p, y] = rotation.to_rpy();
        prop_assert!((-FRAC_PI_2..=FRAC_PI_2).contains(&p));
        prop_assert!((-PI..=PI).contains(&r) && (-PI..=PI).contains(&y));
        prop_assert!(max_diff(&SO3::from_rpy(r, p, y).matrix(), &rotation.matrix()) < 1e-14);
    }

    #[test]
    fn rpy_near_gimbal_lock_reproduces_the_rotation(
        roll in -PI..PI, yaw in -PI..PI, offset in prop::sample::select(vec![0.0, 1e-12, 1e-9, 1e-7, 1e-5]),
        sign in prop::sample::select(vec![-1.0, 1.0]),
    ) {
        let rotation = SO3::from_rpy(roll, sign * (FRAC_PI_2 - offset), yaw);
        let [r, p, y] = rotation.to_rpy();
        let d = max_diff(&SO3::from_rpy(r, p, y).matrix(), &rotation.matrix());
        prop_assert!(d < 1e-14, "pitch {}π/2 − {offset:e}: error {d:e}", sign);
    }

    #[test]
    fn rotation_vector_conversions_are_exp_and_log(rotation in so3()) {
        let w = rotation.to_rotation_vector();
        prop_assert_eq!(w, rotation.log());
        prop_assert_eq!(SO3::from_rotation_vector(&w).matrix(), SO3::exp(&w).matrix());
    }

    #[test]
    fn se3_matrix_round_trip_reproduces_the_transform(t in se3()) {
        let back = SE3::from_matrix(&t.to_matrix()).unwrap();
        prop_assert!(max_diff(&back.to_matrix(), &t.to_matrix()) < 1e-15 * 4.0);
    }

    #[test]
    fn so3_matrix_round_trip_reproduces_the_rotation(r in so3()) {
        prop_assert!(max_diff(&SO3::from_matrix(r.matrix()).unwrap().matrix(), &r.matrix()) < 1e-15 * 4.0);
    }

    #[test]
    fn so3_serialises_as_its_quaternion_and_round_trips(r in so3()) {
        let json = serde_json::to_string(&r).unwrap();
        // serde_json parses floats to within an ulp (exactly only with its `float_roundtrip` feature).
        let q: [f64; 4] = serde_json::from_str(&json).unwrap();
        prop_assert!(quaternion_distance(q, r.to_quaternion()) < 1e-15);
        let back: SO3 = serde_json::from_str(&json).unwrap();
        prop_assert!(max_diff(&back.matrix(), &r.matrix()) < 1e-15 * 4.0);
    }

    #[test]
    fn a_read_rotation_is_written_as_it_was_read(r in so3()) {
        // A model file written, read and written again is the same bytes. The
        // quaternion of the matrix read differs from the one written in the last digit; the one
        // read is written back.
        let json = serde_json::to_string(&r).unwrap();
        let read: [f64; 4] = serde_json::from_str(&json).unwrap();
        let back: SO3 = serde_json::from_str(&json).unwrap();
        prop_assert_eq!(<[f64; 4]>::from(back).map(f64::to_bits), read.map(f64::to_bits));
        prop_assert_eq!(serde_json::to_string(&back).unwrap(), serde_json::to_string(&read).unwrap());
        // Anything computed from it is a new rotation, written by its matrix.
        let turned = back * SO3::exp(&Vector3::new(0.0, 0.0, 0.1));
        prop_assert!(quaternion_distance(<[f64; 4]>::from(turned), turned.to_quaternion()) == 0.0);
    }

    #[test]
    fn se3_serde_round_trip_reproduces_the_transform(t in se3()) {
        let back: SE3 = serde_json::from_str(&serde_json::to_string(&t).unwrap()).unwrap();
        prop_assert!(max_diff(&back.to_matrix(), &t.to_matrix()) < 1e-15 * 4.0);
    }
}

#[test]
fn quaternion_round_trip_is_precise_in_every_branch_of_shepperds_method() {
    // Near the identity the scalar part is largest; near π about x, y or z that component is.
    let cases = [
        Vector3::new(1e-9, -2e-9, 3e-9),
        Vector3::new(0.2, 0.1, -0.3),
        Vector3::x() * (PI - 1e-7),
        Vector3::y() * (PI - 1e-7),
        Vector3::z() * (PI - 1e-7),
        Vector3::new(1.0, 0.1, -0.1).normalize() * PI,
        Vector3::new(0.1, -1.0, 0.1).normalize() * PI,
        Vector3::new(-0.1, 0.1, 1.0).normalize() * PI,
    ];
    for w in cases {
        let r = SO3::exp(&w);
        let [qw, qx, qy, qz] = r.to_quaternion();
        let back = SO3::from_quaternion(qw, qx, qy, qz).unwrap();
        assert!(max_diff(&back.matrix(), &r.matrix()) < 1e-15 * 4.0, "ω = {w:?}");
        let (s, c) = (0.5 * w.norm()).sin_cos();
        let axis = if w.norm() > 0.0 { w.normalize() } else { Vector3::zeros() };
        let expected = [c, axis.x * s, axis.y * s, axis.z * s];
        assert!(quaternion_distance([qw, qx, qy, qz], expected) < 1e-15 * 4.0, "ω = {w:?}");
    }
}

#[test]
fn rpy_at_exact_gimbal_lock_puts_the_free_angle_in_roll() {
    // Ry(±π/2) written with exact zeros, so that only roll − yaw (or roll + yaw) is defined.
    for (pitch, ry) in [
        (FRAC_PI_2, Matrix3::new(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0)),
        (-FRAC_PI_2, Matrix3::new(0.0, 0.0, -1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0)),
    ] {
        let rotation = SO3::from_matrix_unchecked(rot_z(0.4) * ry * rot_x(-1.1));
        let [r, p, y] = rotation.to_rpy();
        assert_eq!(p, pitch);
        assert_eq!(y, 0.0);
        assert!(max_diff(&SO3::from_rpy(r, p, y).matrix(), &rotation.matrix()) < 1e-15 * 4.0);
    }
}

#[test]
fn identity_converts_to_zero_angles_and_unit_quaternion() {
    assert_eq!(SO3::identity().to_quaternion(), [1.0, 0.0, 0.0, 0.0]);
    assert_eq!(SO3::identity().to_rpy(), [0.0, 0.0, 0.0]);
    assert_eq!(SO3::from_rpy(0.0, 0.0, 0.0).matrix(), Matrix3::identity());
}
