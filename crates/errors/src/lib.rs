//! The one error type of the calibration crates and the kinds of fault it carries (a leaf: it knows
//! no other calibration crate), and `ron_position`, which locates a field in a RON text so that a
//! refusal names its line and column.
#![deny(missing_docs)]

mod error;
mod faults;
pub mod ron_position;

pub use error::Error;
pub use faults::{ColumnMapFault, DecimalFault, EffectListFault, FileKind, MAX_HARMONICS};
