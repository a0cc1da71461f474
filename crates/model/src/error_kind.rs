//! The refusals of the model file: the kinds of [`errors::Error`] this crate raises, with their messages.

use std::fmt;

/// What the model file's reader refuses beyond what every RON file may be refused for.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A model file written by another schema version.
    ///
    /// At 1:1.
    SchemaVersion {
        /// The version found.
        found: u32,
        /// The version this build reads.
        supported: u32,
    },
    /// A model's parts in an order they cannot apply in (an effect before the geometry).
    PartOrder {
        /// The part out of place.
        part: &'static str,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::SchemaVersion { found, supported } => {
                write!(f, "model file has schema version {found}, this calib reads versions 1 to {supported}")
            }
            ErrorKind::PartOrder { part } => write!(f, "a model's {part} comes before its geometry"),
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}
