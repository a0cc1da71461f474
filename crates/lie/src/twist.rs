//! se(3): twists, the tangent space of SE(3), ordered `(v, ω)`.

use crate::{Matrix4, Matrix6, SO3, Vector3, Vector6};
use serde::{Deserialize, Serialize};
use std::ops::{Add, Mul, Neg, Sub};

/// A twist `ξ = (v, ω)`: translation part first, rotation part second.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Twist {
    /// Translational part.
    pub v: Vector3,
    /// Rotational part.
    pub w: Vector3,
}

impl Twist {
    /// A twist from its two parts.
    pub fn new(v: Vector3, w: Vector3) -> Self {
        Self { v, w }
    }

    /// The zero twist.
    pub fn zero() -> Self {
        Self { v: Vector3::zeros(), w: Vector3::zeros() }
    }

    /// From a 6-vector `(v, ω)`.
    pub fn from_vector(x: &Vector6) -> Self {
        Self { v: Vector3::new(x[0], x[1], x[2]), w: Vector3::new(x[3], x[4], x[5]) }
    }

    /// The 6-vector `(v, ω)`.
    pub fn to_vector(&self) -> Vector6 {
        Vector6::new(self.v.x, self.v.y, self.v.z, self.w.x, self.w.y, self.w.z)
    }

    /// The 4×4 matrix `ξ^ = [[ω^, v], [0, 0]]`.
    pub fn hat(&self) -> Matrix4 {
        let mut m = Matrix4::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&SO3::hat(&self.w));
        m.fixed_view_mut::<3, 1>(0, 3).copy_from(&self.v);
        m
    }

    /// The inverse of [`Twist::hat`].
    pub fn vee(m: &Matrix4) -> Self {
        Self { v: Vector3::new(m[(0, 3)], m[(1, 3)], m[(2, 3)]), w: SO3::vee(&m.fixed_view::<3, 3>(0, 0).into_owned()) }
    }

    /// The adjoint of the Lie algebra, `ad(ξ) = [[ω^, v^], [0, ω^]]`, so that
    /// `ad(ξ) η = vee(ξ^ η^ − η^ ξ^)`.
    pub fn ad(&self) -> Matrix6 {
        let w = SO3::hat(&self.w);
        let mut m = Matrix6::zeros();
        m.fixed_view_mut::<3, 3>(0, 0).copy_from(&w);
        m.fixed_view_mut::<3, 3>(0, 3).copy_from(&SO3::hat(&self.v));
        m.fixed_view_mut::<3, 3>(3, 3).copy_from(&w);
        m
    }
}

impl Add for Twist {
    type Output = Twist;
    fn add(self, rhs: Twist) -> Twist {
        Twist::new(self.v + rhs.v, self.w + rhs.w)
    }
}

impl Sub for Twist {
    type Output = Twist;
    fn sub(self, rhs: Twist) -> Twist {
        Twist::new(self.v - rhs.v, self.w - rhs.w)
    }
}

impl Neg for Twist {
    type Output = Twist;
    fn neg(self) -> Twist {
        Twist::new(-self.v, -self.w)
    }
}

impl Mul<f64> for Twist {
    type Output = Twist;
    fn mul(self, rhs: f64) -> Twist {
        Twist::new(self.v * rhs, self.w * rhs)
    }
}
