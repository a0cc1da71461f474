//! The one error type of the calibration crates and the kinds of fault it carries (a leaf: it knows
//! no other calibration crate), and `ron_position`, which locates a field in a RON text so that a
//! refusal names its line and column.
//!
//! ```
//! use errors::Error;
//! let error = Error::EmptyFile { file: "poses.csv".into() };
//! assert!(error.to_string().contains("poses.csv"));
//! // Where a value refused after parsing sits in its file: the second line, first column.
//! let text = "(name: \"arm\",\njoints: [])";
//! assert_eq!(errors::ron_position::field_position(text, "joints", 0), (2, 1));
//! ```
#![deny(missing_docs)]

mod error;
mod faults;
pub mod ron_position;

pub use error::Error;
pub use faults::{ColumnMapFault, DecimalFault, EffectListFault, FileKind, MAX_HARMONICS};
