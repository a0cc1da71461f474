//! The refusals of the simulated campaigns: the kinds of [`errors::Error`] this crate raises, with their
//! messages.

use std::fmt;

/// What a simulated campaign refuses.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A simulated pose that is not finite: an effect or a robot beyond any real range.
    NonFiniteSimulation {
        /// 1-based row of the simulated set.
        row: usize,
    },
    /// A simulation asked for more rows than are made (`campaign::MAX_ROWS`).
    TooManySimulatedRows {
        /// The rows asked for.
        rows: usize,
        /// The most rows made.
        max: usize,
    },
    /// A planar chain asked for what needs three dimensions (a simulated 3-D campaign).
    PlanarChain {
        /// The direction every revolute axis is parallel to.
        direction: [f64; 3],
        /// The joint count.
        joints: usize,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::NonFiniteSimulation { row } => write!(
                f,
                "simulated row {row} is not finite: an effect or the robot is beyond any real range (nothing written)"
            ),
            ErrorKind::TooManySimulatedRows { rows, max } => write!(
                f,
                "{rows} rows asked for: at most {max} are simulated (up to 280 MB of CSV and 25 s; is the count mistyped?)"
            ),
            ErrorKind::PlanarChain { direction: [a, b, c], joints } => write!(
                f,
                "the chain is planar: all {joints} joints turn about axes parallel to ({a}, {b}, {c}) (prismatic \
                 ones slide across it), so the tool moves in a plane and 3-D positions cannot be drawn for it; \
                 check the joint axes"
            ),
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}
