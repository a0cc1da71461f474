//! Lie group algebra for rigid motion: SO(3), SE(3) and the tangent space se(3).
#![deny(missing_docs)]
