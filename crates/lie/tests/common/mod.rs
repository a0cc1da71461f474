//! Strategies, reference computations and fixed examples shared by the `lie` tests.
#![allow(dead_code)]

use lie::{Matrix3, Matrix6, SE3, SO3, Twist, Vector3, Vector6};
use nalgebra::SMatrix;
use proptest::prelude::*;
use std::f64::consts::{FRAC_PI_2, PI};

/// Largest rotation angle the property tests draw: "bounded below π".
pub const MAX_ANGLE: f64 = PI - 1e-3;

/// Largest absolute entry of `a − b`.
pub fn max_diff<const R: usize, const C: usize>(a: &SMatrix<f64, R, C>, b: &SMatrix<f64, R, C>) -> f64 {
    (a - b).amax()
}

/// A unit vector, drawn uniformly enough for tests (components in a cube, short draws refused).
pub fn unit_vector() -> impl Strategy<Value = Vector3> {
    (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_map(|(x, y, z)| Vector3::new(x, y, z))
        .prop_filter("too short to normalise", |v| v.norm() > 0.1)
        .prop_map(|v| v.normalize())
}

/// A rotation vector with angle in `[0, max_angle]`.
pub fn rotation_vector(max_angle: f64) -> impl Strategy<Value = Vector3> {
    (unit_vector(), 0.0..=max_angle).prop_map(|(axis, angle)| axis * angle)
}

/// A vector with components in `[-bound, bound]`.
pub fn vector3(bound: f64) -> impl Strategy<Value = Vector3> {
    (-bound..=bound, -bound..=bound, -bound..=bound).prop_map(|(x, y, z)| Vector3::new(x, y, z))
}

/// A twist with translation components in `[-2, 2]` (metres) and rotation angle at most `max_angle`.
pub fn twist(max_angle: f64) -> impl Strategy<Value = Twist> {
    (vector3(2.0), rotation_vector(max_angle)).prop_map(|(v, w)| Twist::new(v, w))
}

/// A rotation with angle at most [`MAX_ANGLE`].
pub fn so3() -> impl Strategy<Value = SO3> {
    rotation_vector(MAX_ANGLE).prop_map(|w| SO3::exp(&w))
}

/// A rigid transform with rotation angle at most [`MAX_ANGLE`].
pub fn se3() -> impl Strategy<Value = SE3> {
    twist(MAX_ANGLE).prop_map(|xi| xi.exp())
}

/// The matrix exponential by scaling and squaring of a Taylor series: a reference that shares no
/// code with the closed forms under test.
pub fn matrix_exp<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let norm = a.norm();
    let mut squarings = 0;
    while norm / f64::from(1u32 << squarings) > 0.25 {
        squarings += 1;
    }
    let scaled = a / f64::from(1u32 << squarings);
    let mut sum = SMatrix::<f64, N, N>::identity();
    let mut term = SMatrix::<f64, N, N>::identity();
    for k in 1..=20 {
        term = term * scaled / f64::from(k);
        sum += term;
    }
    for _ in 0..squarings {
        sum = sum * sum;
    }
    sum
}

/// `Σ_k A^k / (k + 1)!`, the series of `(exp(A) − I) A⁻¹`: with `A = ω^` it is the left Jacobian of
/// SO(3), with `A = ad(ξ)` the left Jacobian of SE(3) (Barfoot, *State Estimation for Robotics*,
/// Eq. 7.82 and 7.85). Converges fast for the angles of the tests (≤ π); summed to 60 terms.
pub fn left_jacobian_series<const N: usize>(a: &SMatrix<f64, N, N>) -> SMatrix<f64, N, N> {
    let mut sum = SMatrix::<f64, N, N>::identity();
    let mut term = SMatrix::<f64, N, N>::identity();
    for k in 1..=60 {
        term = term * a / f64::from(k + 1);
        sum += term;
    }
    sum
}

/// The 6×6 Jacobian, column by column, of a map from R⁶ to R⁶ by central differences with step `h`.
pub fn central_difference6(f: impl Fn(&Vector6) -> Vector6, h: f64) -> Matrix6 {
    let mut j = Matrix6::zeros();
    for i in 0..6 {
        let mut e = Vector6::zeros();
        e[i] = h;
        j.set_column(i, &((f(&e) - f(&-e)) / (2.0 * h)));
    }
    j
}

/// The 3×3 Jacobian of a map from R³ to R³ by central differences with step `h`.
pub fn central_difference3(f: impl Fn(&Vector3) -> Vector3, h: f64) -> Matrix3 {
    let mut j = Matrix3::zeros();
    for i in 0..3 {
        let mut e = Vector3::zeros();
        e[i] = h;
        j.set_column(i, &((f(&e) - f(&-e)) / (2.0 * h)));
    }
    j
}

/// A fixed rotation axis, not aligned with any coordinate axis.
pub fn skew_axis() -> Vector3 {
    Vector3::new(0.3, -0.5, 0.8).normalize()
}

/// Rotation vectors at the places where the closed forms change branch or degenerate
/// (sophus-style fixed examples): the identity, tiny angles, both sides of the series thresholds
/// (1e-4 and 1), both sides of the symmetric-part threshold of `log` (π/2), and up to `π − 1e-6`.
pub fn fixed_rotation_vectors() -> Vec<Vector3> {
    let a = skew_axis();
    let mut out = vec![Vector3::zeros()];
    let below_pi = [PI - 1e-2, PI - 1e-4];
    for angle in [1e-12, 1e-8, 0.99e-4, 1.01e-4, 1e-3, 1e-2, 0.1, 0.5, 0.999, 1.001, FRAC_PI_2 - 1e-9, FRAC_PI_2 + 1e-9]
        .into_iter()
        .chain([2.0, 3.0])
        .chain(below_pi)
    {
        out.push(a * angle);
    }
    out.push(Vector3::new(0.0, 0.0, PI - 1e-6));
    out.push(Vector3::new(1e-9, -2e-9, 0.5e-9));
    out.push(a * (PI - 1e-6));
    out.push(Vector3::new(-1.0, 2.0, 0.5).normalize() * (PI - 1e-6));
    out
}

/// Twists over [`fixed_rotation_vectors`], each with a pure-rotation and a general translation part.
pub fn fixed_twists() -> Vec<Twist> {
    let mut out = Vec::new();
    for w in fixed_rotation_vectors() {
        out.push(Twist::new(Vector3::zeros(), w));
        out.push(Twist::new(Vector3::new(0.7, -1.3, 0.4), w));
    }
    out.push(Twist::new(Vector3::new(1e-8, 0.0, -1e-8), Vector3::zeros()));
    out
}

/// The three points at which every Jacobian is checked by finite differences (manif style):
/// the identity, a tiny point (|ω| ~ 1e−8) and an ordinary one.
pub fn jacobian_points() -> [(&'static str, Twist); 3] {
    [
        ("identity", Twist::zero()),
        ("tiny", Twist::new(Vector3::new(3e-9, -7e-9, 2e-9), Vector3::new(-4e-9, 6e-9, 5e-9))),
        ("random", Twist::new(Vector3::new(0.42, -1.1, 0.73), Vector3::new(0.61, -0.29, 1.37))),
    ]
}

/// Rz(angle), written out (an independent reference for the RPY convention).
pub fn rot_z(angle: f64) -> Matrix3 {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0)
}

/// Ry(angle), written out.
pub fn rot_y(angle: f64) -> Matrix3 {
    let (s, c) = angle.sin_cos();
    Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c)
}

/// Rx(angle), written out.
pub fn rot_x(angle: f64) -> Matrix3 {
    let (s, c) = angle.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}
