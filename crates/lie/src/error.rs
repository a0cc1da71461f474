//! The errors of the `lie` crate.

use std::fmt;

/// A matrix or quaternion that is not (close enough to) a member of the group.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Error {
    /// `‖RᵀR − I‖_F` or the determinant says the matrix is far from a rotation.
    NotARotation {
        /// `‖RᵀR − I‖_F`.
        deviation: f64,
        /// The determinant.
        determinant: f64,
    },
    /// A quaternion whose norm is far from 1.
    NotAUnitQuaternion {
        /// Its norm.
        norm: f64,
    },
    /// A 4×4 matrix whose last row is not `[0, 0, 0, 1]`.
    NotRigid {
        /// The last row found.
        last_row: [f64; 4],
    },
    /// A 4×4 matrix whose translation column holds a NaN or an infinity.
    NonFiniteTranslation {
        /// The translation found.
        translation: [f64; 3],
    },
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::NotARotation { deviation, determinant } => {
                write!(f, "matrix is not a rotation: |RᵀR − I| = {deviation:.3e}, det = {determinant:.6}")
            }
            Error::NotAUnitQuaternion { norm } => {
                write!(f, "quaternion norm is {norm}, expected 1")
            }
            Error::NotRigid { last_row } => {
                write!(f, "last row of a rigid transform must be [0, 0, 0, 1], found {last_row:?}")
            }
            Error::NonFiniteTranslation { translation } => {
                write!(f, "translation of a rigid transform must be finite, found {translation:?}")
            }
        }
    }
}

impl std::error::Error for Error {}
