//! The one error type of the calibration crates and the kinds of fault it carries, and
//! `ron_position`, which locates a field in a RON text so that a refusal names its line and column.
//!
//! An [`Error`] is a [`Place`] (a file, and a line and column where known) and an [`ErrorKind`]
//! (what is wrong, with the numbers that explain it); its message is the place, then the kind's.
//! The crate is a leaf: it knows no other crate of the workspace. Every calibration crate returns
//! this error, from the readers up to `cell` (registration, planning) and `report`. The errors of
//! `poe`, `loadsim` and `gp` are carried boxed ([`Error::kinematics`], [`Error::load`],
//! [`Error::generator`], [`Error::gp`]), their message and `source()` chain kept.
//!
//! ```
//! use errors::{Error, ErrorKind, Place};
//! let error = Error::at(Place::new("poses.csv", 1, 5), ErrorKind::MissingColumn { name: "y_mm".into() });
//! assert_eq!(error.to_string(), "poses.csv:1:5: missing required column 'y_mm'");
//! assert!(matches!(error.kind(), ErrorKind::MissingColumn { name } if name == "y_mm"));
//! assert_eq!(error.position(), Some((1, 5)));
//! // Where a value refused after parsing sits in its file: the second line, first column.
//! let text = "(name: \"arm\",\njoints: [])";
//! assert_eq!(errors::ron_position::field_position(text, "joints", 0), (2, 1));
//! ```
#![deny(missing_docs)]

mod error;
mod faults;
mod kind;
mod place;
pub mod ron_position;

pub use error::Error;
pub use faults::{ColumnMapFault, DecimalFault, EffectListFault, FileKind, MAX_HARMONICS, PITCH_BOUNDS_MM};
pub use kind::ErrorKind;
pub use place::Place;
