//! SO(3): rotations of 3-space.

use crate::coefficients::rodrigues_coefficients;
use crate::{Error, Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::f64::consts::FRAC_PI_2;
use std::ops::Mul;

/// Below this angle `log` reads the rotation vector from the skew part by a series in θ.
const SMALL_ANGLE: f64 = 1e-4;

/// Above this angle `log` reads the rotation axis from the symmetric part of R: the errors of the
/// two readings, `~ε / sin θ` and `~ε / (1 − cos θ)`, cross at π/2.
const SYMMETRIC_BRANCH_ANGLE: f64 = FRAC_PI_2;

/// Largest `‖RᵀR − I‖_F` that [`SO3::from_matrix`] re-orthonormalises rather than refuses.
pub const ORTHONORMALITY_TOLERANCE: f64 = 1e-3;

/// A rotation, stored as its orthonormal matrix. Serialised as a unit quaternion `[w, x, y, z]`.
#[derive(Debug, Clone, Copy, Serialize, Deserialize)]
#[serde(into = "[f64; 4]", try_from = "[f64; 4]")]
pub struct SO3 {
    matrix: Matrix3,
    /// The quaternion a deserialised rotation was read as, written back as it was: the matrix's
    /// own quaternion ([`SO3::to_quaternion`]) differs from it in the last digit, so a file written,
    /// read and written again would not be the same bytes. `None` for every rotation computed; the
    /// matrix is always the rotation, and equality compares the matrices alone.
    read_as: Option<[f64; 4]>,
}

impl PartialEq for SO3 {
    fn eq(&self, other: &Self) -> bool {
        self.matrix == other.matrix
    }
}

impl SO3 {
    /// The identity rotation.
    pub fn identity() -> Self {
        Self { matrix: Matrix3::identity(), read_as: None }
    }

    /// The skew-symmetric matrix `ω^` with `ω^ x = ω × x`.
    pub fn hat(w: &Vector3) -> Matrix3 {
        Matrix3::new(0.0, -w.z, w.y, w.z, 0.0, -w.x, -w.y, w.x, 0.0)
    }

    /// The inverse of [`SO3::hat`] (reads the skew-symmetric part).
    pub fn vee(m: &Matrix3) -> Vector3 {
        Vector3::new(m[(2, 1)] - m[(1, 2)], m[(0, 2)] - m[(2, 0)], m[(1, 0)] - m[(0, 1)]) * 0.5
    }

    /// Rodrigues' formula `exp(ω^) = I + (sin θ/θ) ω^ + ((1 − cos θ)/θ²) ω^²`.
    pub fn exp(w: &Vector3) -> Self {
        let (a, b) = rodrigues_coefficients(w.norm());
        let k = Self::hat(w);
        Self { matrix: Matrix3::identity() + k * a + k * k * b, read_as: None }
    }

    /// The rotation vector `ω` with `exp(ω^) = R`, `|ω| ≤ π`; at exactly π either of `±π a`.
    ///
    /// The angle is `atan2(sin θ, cos θ)`, both read from R, precise at every angle. The axis read
    /// from the skew part `R − Rᵀ = 2 sin θ a^` carries a relative error `~ε / sin θ`, which grows
    /// without bound towards π; above π/2 the axis is therefore read from the symmetric part
    /// `(R + Rᵀ)/2 − cos θ I = (1 − cos θ) a aᵀ` (error `~ε / (1 − cos θ)`, at most `ε` there), its
    /// sign from the skew part.
    pub fn log(&self) -> Vector3 {
        let r = &self.matrix;
        let skew = Vector3::new(r[(2, 1)] - r[(1, 2)], r[(0, 2)] - r[(2, 0)], r[(1, 0)] - r[(0, 1)]);
        let cos = ((r.trace() - 1.0) * 0.5).clamp(-1.0, 1.0);
        let sin = 0.5 * skew.norm();
        let theta = sin.atan2(cos);
        if theta < SMALL_ANGLE {
            // θ / (2 sin θ) = ½ (1 + θ²/6 + O(θ⁴)).
            return skew * (0.5 * (1.0 + theta * theta / 6.0));
        }
        if theta < SYMMETRIC_BRANCH_ANGLE {
            return skew * (theta / (2.0 * sin));
        }
        // The column of (1 − cos θ) a aᵀ with the largest diagonal entry (a_k² ≥ 1/3) is a_k a,
        // well away from zero.
        let symmetric = (r + r.transpose()) * 0.5;
        let k = (0..3).max_by(|&i, &j| symmetric[(i, i)].total_cmp(&symmetric[(j, j)])).unwrap_or(0);
        let mut axis = symmetric.column(k).into_owned();
        axis[k] -= cos;
        let axis = axis.normalize();
        if axis.dot(&skew) < 0.0 { -axis * theta } else { axis * theta }
    }

    /// The rotation matrix.
    pub fn matrix(&self) -> Matrix3 {
        self.matrix
    }

    /// Wraps a matrix the caller knows to be a rotation, without checking.
    pub fn from_matrix_unchecked(matrix: Matrix3) -> Self {
        Self { matrix, read_as: None }
    }

    /// Re-orthonormalises a nearly-rotation matrix (the nearest rotation in the Frobenius norm,
    /// by SVD) and refuses one far from a rotation.
    pub fn from_matrix(matrix: Matrix3) -> Result<Self, Error> {
        let deviation = (matrix.transpose() * matrix - Matrix3::identity()).norm();
        let determinant = matrix.determinant();
        if !(deviation <= ORTHONORMALITY_TOLERANCE && determinant > 0.0) {
            return Err(Error::NotARotation { deviation, determinant });
        }
        let svd = matrix.svd(true, true);
        match (svd.u, svd.v_t) {
            (Some(u), Some(v_t)) => Ok(Self { matrix: u * v_t, read_as: None }),
            _ => Err(Error::NotARotation { deviation, determinant }),
        }
    }

    /// The inverse (transpose).
    pub fn inverse(&self) -> Self {
        Self { matrix: self.matrix.transpose(), read_as: None }
    }

    /// `self · other`.
    pub fn compose(&self, other: &Self) -> Self {
        Self { matrix: self.matrix * other.matrix, read_as: None }
    }

    /// Rotates a vector.
    pub fn act(&self, x: &Vector3) -> Vector3 {
        self.matrix * x
    }

    /// Same as [`SO3::exp`].
    pub fn from_rotation_vector(w: &Vector3) -> Self {
        Self::exp(w)
    }

    /// Same as [`SO3::log`].
    pub fn to_rotation_vector(&self) -> Vector3 {
        self.log()
    }

    /// From a quaternion `w + xi + yj + zk`; normalised, refused when its norm is off by more than
    /// 1e-3.
    pub fn from_quaternion(w: f64, x: f64, y: f64, z: f64) -> Result<Self, Error> {
        let norm = (w * w + x * x + y * y + z * z).sqrt();
        if norm.is_nan() || (norm - 1.0).abs() > 1e-3 {
            return Err(Error::NotAUnitQuaternion { norm });
        }
        let (w, x, y, z) = (w / norm, x / norm, y / norm, z / norm);
        Ok(Self {
            matrix: Matrix3::new(
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ),
            read_as: None,
        })
    }

    /// The unit quaternion `[w, x, y, z]` with `w ≥ 0` (Shepperd's method: the largest of the four
    /// candidates is computed first, for precision).
    pub fn to_quaternion(&self) -> [f64; 4] {
        let m = &self.matrix;
        let trace = m.trace();
        let candidates = [trace, m[(0, 0)], m[(1, 1)], m[(2, 2)]];
        let largest = (0..4).max_by(|&i, &j| candidates[i].total_cmp(&candidates[j])).unwrap_or(0);
        let q = match largest {
            0 => {
                let s = (1.0 + trace).sqrt() * 2.0;
                [0.25 * s, (m[(2, 1)] - m[(1, 2)]) / s, (m[(0, 2)] - m[(2, 0)]) / s, (m[(1, 0)] - m[(0, 1)]) / s]
            }
            1 => {
                let s = (1.0 + m[(0, 0)] - m[(1, 1)] - m[(2, 2)]).sqrt() * 2.0;
                [(m[(2, 1)] - m[(1, 2)]) / s, 0.25 * s, (m[(0, 1)] + m[(1, 0)]) / s, (m[(0, 2)] + m[(2, 0)]) / s]
            }
            2 => {
                let s = (1.0 - m[(0, 0)] + m[(1, 1)] - m[(2, 2)]).sqrt() * 2.0;
                [(m[(0, 2)] - m[(2, 0)]) / s, (m[(0, 1)] + m[(1, 0)]) / s, 0.25 * s, (m[(1, 2)] + m[(2, 1)]) / s]
            }
            _ => {
                let s = (1.0 - m[(0, 0)] - m[(1, 1)] + m[(2, 2)]).sqrt() * 2.0;
                [(m[(1, 0)] - m[(0, 1)]) / s, (m[(0, 2)] + m[(2, 0)]) / s, (m[(1, 2)] + m[(2, 1)]) / s, 0.25 * s]
            }
        };
        let norm = q.iter().map(|v| v * v).sum::<f64>().sqrt();
        let sign = if q[0] < 0.0 { -1.0 } else { 1.0 };
        q.map(|v| v * sign / norm)
    }

    /// From roll, pitch, yaw (radians): `R = Rz(yaw) · Ry(pitch) · Rx(roll)`.
    pub fn from_rpy(roll: f64, pitch: f64, yaw: f64) -> Self {
        Self::exp(&(Vector3::z() * yaw)) * Self::exp(&(Vector3::y() * pitch)) * Self::exp(&(Vector3::x() * roll))
    }

    /// `[roll, pitch, yaw]` with `R = Rz(yaw) Ry(pitch) Rx(roll)`, pitch in `[−π/2, π/2]`, roll and
    /// yaw in `[−π, π]`. At gimbal lock (pitch = ±π/2 exactly) yaw is 0 and roll takes the free angle.
    ///
    /// Yaw is read first, then removed, and roll and pitch are read from `Rz(−yaw) R = Ry(pitch)
    /// Rx(roll)` (M. Day, *Extracting Euler angles from a rotation matrix*, Insomniac Games, 2012):
    /// every angle comes from a well-conditioned `atan2`, so the angles reproduce R to rounding even
    /// within 1e-6 of gimbal lock, where `asin(−R₂₀)` and a lock threshold would lose half the digits.
    pub fn to_rpy(&self) -> [f64; 3] {
        let m = &self.matrix;
        // At exact lock both are ±0, and atan2(±0, −0) = ±π: pin yaw to 0 instead.
        let yaw = if m[(1, 0)] == 0.0 && m[(0, 0)] == 0.0 { 0.0 } else { m[(1, 0)].atan2(m[(0, 0)]) };
        let (s, c) = yaw.sin_cos();
        // Rows 0 and 1 of Rz(−yaw) R: [[cos p, sin p sin r, sin p cos r], [0, cos r, −sin r]].
        let cos_pitch = c * m[(0, 0)] + s * m[(1, 0)];
        let pitch = (-m[(2, 0)]).atan2(cos_pitch);
        let roll = (s * m[(0, 2)] - c * m[(1, 2)]).atan2(c * m[(1, 1)] - s * m[(0, 1)]);
        [roll, pitch, yaw]
    }
}

impl Mul for SO3 {
    type Output = SO3;

    fn mul(self, rhs: SO3) -> SO3 {
        self.compose(&rhs)
    }
}

/// The serialised form: the quaternion the rotation was read as, else its matrix's.
impl From<SO3> for [f64; 4] {
    fn from(r: SO3) -> Self {
        r.read_as.unwrap_or_else(|| r.to_quaternion())
    }
}

/// The deserialised form, which keeps the quaternion as read (see `SO3::read_as`).
impl TryFrom<[f64; 4]> for SO3 {
    type Error = Error;

    fn try_from(q: [f64; 4]) -> Result<Self, Error> {
        Ok(SO3 { read_as: Some(q), ..SO3::from_quaternion(q[0], q[1], q[2], q[3])? })
    }
}
