//! Left and right Jacobians of SO(3) and SE(3) and their inverses.
//!
//! Convention (left): `exp(ξ + δ) ≈ exp(J_l(ξ) δ) · exp(ξ)`; (right): `exp(ξ + δ) ≈ exp(ξ) · exp(J_r(ξ) δ)`;
//! `J_r(ξ) = J_l(−ξ)`.

use crate::so3::{SMALL_ANGLE, rotation_coefficients};
use crate::{Matrix3, Matrix6, SE3, SO3, Twist};

impl SO3 {
    /// `J_l(ω) = I + ((1 − cos θ)/θ²) ω^ + ((θ − sin θ)/θ³) ω^²`.
    pub fn left_jacobian(w: &crate::Vector3) -> Matrix3 {
        let (_, b, c) = rotation_coefficients(w.norm());
        let k = SO3::hat(w);
        Matrix3::identity() + k * b + k * k * c
    }

    /// `J_r(ω) = J_l(−ω)`.
    pub fn right_jacobian(w: &crate::Vector3) -> Matrix3 {
        Self::left_jacobian(&-w)
    }

    /// `J_l⁻¹(ω) = I − ½ ω^ + (1/θ²)(1 − (θ/2) cot(θ/2)) ω^²`, stable up to θ = π.
    pub fn left_jacobian_inverse(w: &crate::Vector3) -> Matrix3 {
        let theta = w.norm();
        let k = SO3::hat(w);
        let d = if theta < SMALL_ANGLE {
            let t2 = theta * theta;
            1.0 / 12.0 + t2 / 720.0 + t2 * t2 / 30240.0
        } else {
            let half = 0.5 * theta;
            (1.0 - half * half.cos() / half.sin()) / (theta * theta)
        };
        Matrix3::identity() - k * 0.5 + k * k * d
    }

    /// `J_r⁻¹(ω) = J_l⁻¹(−ω)`.
    pub fn right_jacobian_inverse(w: &crate::Vector3) -> Matrix3 {
        Self::left_jacobian_inverse(&-w)
    }
}

/// The block `Q(v, ω)` of the SE(3) left Jacobian (Barfoot, *State Estimation for Robotics*,
/// Eq. 7.86), with its coefficients' series near θ = 0.
fn q_block(xi: &Twist) -> Matrix3 {
    let theta = xi.w.norm();
    let v = SO3::hat(&xi.v);
    let w = SO3::hat(&xi.w);
    let (c1, c2, c3) = if theta < SMALL_ANGLE {
        let t2 = theta * theta;
        (1.0 / 6.0 - t2 / 120.0, 1.0 / 24.0 - t2 / 720.0, 1.0 / 120.0 - t2 / 2520.0)
    } else {
        let (s, c) = theta.sin_cos();
        let t2 = theta * theta;
        let t3 = t2 * theta;
        let t4 = t2 * t2;
        let t5 = t4 * theta;
        ((theta - s) / t3, (t2 + 2.0 * c - 2.0) / (2.0 * t4), (2.0 * theta - 3.0 * s + theta * c) / (2.0 * t5))
    };
    v * 0.5
        + (w * v + v * w + w * v * w) * c1
        + (w * w * v + v * w * w - w * v * w * 3.0) * c2
        + (w * v * w * w + w * w * v * w) * c3
}

impl SE3 {
    /// `J_l(ξ) = [[J_l(ω), Q(v, ω)], [0, J_l(ω)]]` in `(v, ω)` order.
    pub fn left_jacobian(xi: &Twist) -> Matrix6 {
        let j = SO3::left_jacobian(&xi.w);
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&j);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&q_block(xi));
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&j);
        m
    }

    /// `J_r(ξ) = J_l(−ξ)`.
    pub fn right_jacobian(xi: &Twist) -> Matrix6 {
        Self::left_jacobian(&-*xi)
    }

    /// `J_l⁻¹(ξ) = [[J_l⁻¹, −J_l⁻¹ Q J_l⁻¹], [0, J_l⁻¹]]`.
    pub fn left_jacobian_inverse(xi: &Twist) -> Matrix6 {
        let j = SO3::left_jacobian_inverse(&xi.w);
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&j);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(-j * q_block(xi) * j));
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&j);
        m
    }

    /// `J_r⁻¹(ξ) = J_l⁻¹(−ξ)`.
    pub fn right_jacobian_inverse(xi: &Twist) -> Matrix6 {
        Self::left_jacobian_inverse(&-*xi)
    }
}
