//! The one error type of the calibration crates, the place it names, the kinds of fault more than
//! one crate raises, and `ron_position`, which locates a field in a RON text so that a refusal
//! names its line and column.
//!
//! An [`Error`] is a [`Place`] (a file, and a line and column where known) and a [`Kind`] (what
//! is wrong, with the numbers that explain it); its message is the place, then the kind's. Each
//! crate defines the kinds it raises (its own `ErrorKind` enum, which implements [`Kind`]) beside
//! the code that raises them, so that a new refusal is written and rebuilt there; this crate keeps
//! only what several crates share: [`CommonKind`] (a file that cannot be read, RON that does not
//! parse or holds a value beyond any robot cell, the errors of `poe`, `loadsim` and `gp` carried
//! boxed) and [`OptionOutOfRange`], the one way an options struct refuses a value.
//!
//! The crate is a leaf: it knows no other crate of the workspace. Every calibration crate returns
//! this error, from the readers up to `cell` (registration, planning) and `report`.
//!
//! ```
//! use errors::{CommonKind, Error, Place};
//! let kind = CommonKind::NotFinite { field: "flange.position".into(), value: f64::NAN };
//! let error = Error::at(Place::new("arm.ron", 3, 5), kind);
//! assert_eq!(error.to_string(), "arm.ron:3:5: flange.position is NaN, a finite number is needed");
//! assert!(matches!(error.kind::<CommonKind>(), Some(CommonKind::NotFinite { field, .. }) if field == "flange.position"));
//! assert_eq!(error.position(), Some((3, 5)));
//! // Where a value refused after parsing sits in its file: the second line, first column.
//! let text = "(name: \"arm\",\njoints: [])";
//! assert_eq!(errors::ron_position::field_position(text, "joints", 0), (2, 1));
//! ```
#![deny(missing_docs)]

mod common;
mod error;
pub mod option;
mod place;
pub mod ron_position;

pub use common::CommonKind;
pub use error::{Error, Kind};
pub use option::{OptionOutOfRange, OptionValue};
pub use place::Place;
