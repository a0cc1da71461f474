//! Left and right Jacobians of SO(3) and SE(3) and their inverses, in the convention of the crate
//! doc.

use crate::coefficients::{
    angle_minus_sin_over_angle3, inverse_jacobian_coefficient, q_coefficient_2, q_coefficient_3, rodrigues_coefficients,
};
use crate::{Matrix3, Matrix6, SE3, SO3, Twist, Vector3};

impl SO3 {
    /// `J_l(ω) = I + ((1 − cos θ)/θ²) ω^ + ((θ − sin θ)/θ³) ω^²` (Barfoot, *State Estimation for
    /// Robotics*, 2017, §7.1.5).
    pub fn left_jacobian(w: &Vector3) -> Matrix3 {
        let theta = w.norm();
        let k = SO3::hat(w);
        let (_, b) = rodrigues_coefficients(theta);
        Matrix3::identity() + k * b + k * k * angle_minus_sin_over_angle3(theta)
    }

    /// `J_r(ω) = J_l(−ω)`.
    pub fn right_jacobian(w: &Vector3) -> Matrix3 {
        Self::left_jacobian(&-w)
    }

    /// `J_l⁻¹(ω) = I − ½ ω^ + (1/θ²)(1 − (θ/2) cot(θ/2)) ω^²` (ibid.), stable up to θ = π.
    pub fn left_jacobian_inverse(w: &Vector3) -> Matrix3 {
        let k = SO3::hat(w);
        Matrix3::identity() - k * 0.5 + k * k * inverse_jacobian_coefficient(w.norm())
    }

    /// `J_r⁻¹(ω) = J_l⁻¹(−ω)`.
    pub fn right_jacobian_inverse(w: &Vector3) -> Matrix3 {
        Self::left_jacobian_inverse(&-w)
    }
}

/// The block `Q(v, ω)` of the SE(3) left Jacobian (Barfoot, *State Estimation for Robotics*,
/// Eq. 7.86), with coefficients precise at every angle (see `coefficients`).
fn q_block(xi: &Twist) -> Matrix3 {
    let theta = xi.w.norm();
    let v = SO3::hat(&xi.v);
    let w = SO3::hat(&xi.w);
    let wv = w * v;
    let vw = v * w;
    let wvw = wv * w;
    let ww = w * w;
    v * 0.5
        + (wv + vw + wvw) * angle_minus_sin_over_angle3(theta)
        + (ww * v + vw * w - wvw * 3.0) * q_coefficient_2(theta)
        + (wvw * w + w * wvw) * q_coefficient_3(theta)
}

impl SE3 {
    /// `J_l(ξ) = [[J_l(ω), Q(v, ω)], [0, J_l(ω)]]` in `(v, ω)` order (Barfoot §7.1.5).
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

    /// `J_l⁻¹(ξ) = [[J_l⁻¹, −J_l⁻¹ Q J_l⁻¹], [0, J_l⁻¹]]` (block inverse of the above).
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
