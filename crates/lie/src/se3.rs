//! SE(3): rigid transforms.

use crate::coefficients::{angle_minus_sin_over_angle3, inverse_jacobian_coefficient, rodrigues_coefficients};
use crate::{Error, Matrix3, Matrix4, Matrix6, SO3, Twist, Vector3};
use serde::{Deserialize, Serialize};
use std::ops::Mul;

/// A rigid transform `x ↦ R x + t`. Named `a_from_b` where it maps frame `b` into frame `a`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SE3 {
    rotation: SO3,
    translation: Vector3,
}

impl SE3 {
    /// The identity transform.
    pub fn identity() -> Self {
        Self { rotation: SO3::identity(), translation: Vector3::zeros() }
    }

    /// From a rotation and a translation.
    pub fn new(rotation: SO3, translation: Vector3) -> Self {
        Self { rotation, translation }
    }

    /// A pure translation.
    pub fn from_translation(translation: Vector3) -> Self {
        Self { rotation: SO3::identity(), translation }
    }

    /// The rotation part.
    pub fn rotation(&self) -> SO3 {
        self.rotation
    }

    /// The translation part.
    pub fn translation(&self) -> Vector3 {
        self.translation
    }

    /// `exp(ξ^) = [[exp(ω^), J_l(ω) v], [0, 1]]`, with `J_l` the left Jacobian of SO(3).
    pub fn exp(xi: &Twist) -> Self {
        let theta = xi.w.norm();
        let (a, b) = rodrigues_coefficients(theta);
        let c = angle_minus_sin_over_angle3(theta);
        let k = SO3::hat(&xi.w);
        let rotation = SO3::from_matrix_unchecked(Matrix3::identity() + k * a + k * k * b);
        // J_l(ω) v = v + b ω × v + c ω × (ω × v), without forming J_l.
        let wv = xi.w.cross(&xi.v);
        Self { rotation, translation: xi.v + wv * b + xi.w.cross(&wv) * c }
    }

    /// The twist `ξ` with `exp(ξ^) = T`, `|ω| ≤ π`.
    pub fn log(&self) -> Twist {
        let w = self.rotation.log();
        // J_l⁻¹(ω) t = t − ½ ω × t + d ω × (ω × t), without forming J_l⁻¹.
        let t = self.translation;
        let wt = w.cross(&t);
        Twist::new(t - wt * 0.5 + w.cross(&wt) * inverse_jacobian_coefficient(w.norm()), w)
    }

    /// The inverse transform.
    pub fn inverse(&self) -> Self {
        let r = self.rotation.inverse();
        Self { rotation: r, translation: -(r.act(&self.translation)) }
    }

    /// `self · other`.
    pub fn compose(&self, other: &Self) -> Self {
        Self {
            rotation: self.rotation * other.rotation,
            translation: self.rotation.act(&other.translation) + self.translation,
        }
    }

    /// Maps a point: `R x + t`.
    pub fn transform_point(&self, x: &Vector3) -> Vector3 {
        self.rotation.act(x) + self.translation
    }

    /// The homogeneous 4×4 matrix.
    pub fn to_matrix(&self) -> Matrix4 {
        let mut m = Matrix4::identity();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&self.rotation.matrix());
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.translation);
        m
    }

    /// From a homogeneous 4×4 matrix: the last row must be `[0, 0, 0, 1]` (to 1e-9), the
    /// translation finite and the rotation block nearly orthonormal (it is re-orthonormalised, see
    /// [`SO3::from_matrix`]).
    pub fn from_matrix(m: &Matrix4) -> Result<Self, Error> {
        let last_row = [m[(3, 0)], m[(3, 1)], m[(3, 2)], m[(3, 3)]];
        let expected = [0.0, 0.0, 0.0, 1.0];
        if last_row.iter().zip(expected).any(|(a, b)| (a - b).abs().is_nan() || (a - b).abs() > 1e-9) {
            return Err(Error::NotRigid { last_row });
        }
        let translation = Vector3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]);
        if !translation.iter().all(|x| x.is_finite()) {
            return Err(Error::NonFiniteTranslation { translation: translation.into() });
        }
        let rotation = SO3::from_matrix(m.fixed_view::<3, 3>(0, 0).into_owned())?;
        Ok(Self { rotation, translation })
    }

    /// The adjoint `Ad(T) = [[R, t^ R], [0, R]]` in `(v, ω)` order: `Ad(T) ξ = vee(T ξ^ T⁻¹)`.
    pub fn adjoint(&self) -> Matrix6 {
        let r = self.rotation.matrix();
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&r);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&(SO3::hat(&self.translation) * r));
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&r);
        m
    }
}

impl Mul for SE3 {
    type Output = SE3;

    fn mul(self, rhs: SE3) -> SE3 {
        self.compose(&rhs)
    }
}

impl Twist {
    /// The exponential map to SE(3).
    pub fn exp(&self) -> SE3 {
        SE3::exp(self)
    }
}
