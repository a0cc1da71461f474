//! The refusals of the effects: the kinds of [`errors::Error`] this crate raises, with their messages
//! (the error adds the place a message starts with).

use robot::PITCH_BOUNDS_MM;
use std::fmt;

/// What the effects and the `--effects` parser refuse.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// An `--effects` argument that does not parse.
    ///
    /// At `--effects:1:COLUMN`, the character where the faulty item starts.
    EffectList {
        /// The faulty item.
        text: String,
        /// What is wrong with it.
        fault: EffectListFault,
    },
    /// An effect names a joint the robot does not have.
    EffectJoint {
        /// The 1-based joint named.
        joint: usize,
        /// The robot's joint count.
        joint_count: usize,
    },
    /// An effect that means nothing on the kind of joint it names (a series in a prismatic
    /// joint's "angle").
    EffectJointKind {
        /// The effect's name.
        effect: &'static str,
        /// The 1-based joint named.
        joint: usize,
    },
    /// An effect of a linear axis (a screw's or a rack's periodic error) named on a revolute joint.
    EffectNeedsPrismatic {
        /// The effect's name.
        effect: &'static str,
        /// The 1-based joint named.
        joint: usize,
    },
    /// An effect needs a column that a row lacks (e.g. `thermal` without `temp_c`).
    EffectNeedsColumn {
        /// 1-based line of the row (0 for rows made in memory).
        line: u64,
        /// The effect.
        effect: &'static str,
        /// The column it needs.
        column: &'static str,
    },
    /// An effect whose column has the same value on every training row: the effect's
    /// parameters multiply the column's deviation from its mean, zero everywhere, so they are
    /// unobservable (fitted, they would read zero and look identified).
    EffectColumnConstant {
        /// The effect.
        effect: &'static str,
        /// Its column.
        column: &'static str,
        /// The one value every row has.
        value: f64,
        /// The training rows.
        rows: usize,
        /// 1-based lines of the first and the last row (0 for rows made in memory).
        lines: [u64; 2],
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::EffectList { text, fault } => write!(f, "'{text}' {fault}"),
            ErrorKind::EffectJoint { joint, joint_count } => {
                write!(f, "effect on joint {joint}: the robot has joints 1 to {joint_count}")
            }
            ErrorKind::EffectJointKind { effect, joint } => write!(
                f,
                "{effect} on joint {joint}: joint {joint} is prismatic, and a {effect} is a function of a revolute joint's angle{}",
                if *effect == "gear_periodic" {
                    " (a linear axis's periodic error per screw or rack pitch is screw_periodic:JOINT:PITCH_MM:HARMONICS)"
                } else {
                    ""
                }
            ),
            ErrorKind::EffectNeedsPrismatic { effect, joint } => write!(
                f,
                "{effect} on joint {joint}: joint {joint} is revolute, and a {effect} is a function of a linear axis's \
                 position per screw or rack pitch (a periodic error in a revolute joint's angle is gear_periodic:JOINT:HARMONICS)"
            ),
            ErrorKind::EffectNeedsColumn { line, effect, column } => {
                write!(f, "line {line}: {effect} needs the column '{column}', which this row lacks")
            }
            ErrorKind::EffectColumnConstant { effect, column, value, rows, lines: [first, last] } => write!(
                f,
                "lines {first}-{last}: {effect} needs the column '{column}' to vary, but its values do not vary \
                 ({column} = {value} on all {rows} rows): its parameters are unobservable; leave {effect} out"
            ),
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}

/// The most harmonics a `gear_periodic` item may ask for: two parameters each, and a series of a
/// joint's own angle beyond a few dozen orders follows the noise of any campaign we know of (the
/// UR10 analysis of issue #11 found 24–32 enough). It also bounds the work a typo can ask for.
pub const MAX_HARMONICS: u32 = 256;

/// What is wrong with one item of an `--effects` list.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EffectListFault {
    /// The argument or an item is empty.
    Empty {
        /// The items `--effects` takes, as the message lists them (`joint_compliance,
        /// gear_periodic:JOINT:HARMONICS, …`): written by the effects crate from its one list of
        /// kinds, which this leaf does not know.
        items: &'static str,
    },
    /// Not one of the SPEC's effect names.
    UnknownEffect {
        /// The items `--effects` takes, as for [`EffectListFault::Empty`].
        items: &'static str,
    },
    /// An effect that takes no `:` argument was given one, or one that needs them lacks them.
    Arguments {
        /// How many `:`-separated arguments the effect takes.
        expected: usize,
        /// How many were given.
        found: usize,
    },
    /// A joint that is not a whole number of at least 1.
    Joint,
    /// A harmonic count that is not a whole number from 1 to [`MAX_HARMONICS`].
    Harmonics,
    /// A pitch that is not a number of millimetres within [`PITCH_BOUNDS_MM`].
    Pitch,
    /// The same effect (on the same joint) is named twice.
    Duplicate,
    /// `auto` together with other items.
    AutoWithOthers,
}

impl fmt::Display for EffectListFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match *self {
            EffectListFault::Empty { items } => write!(f, "is empty (expected auto, or a list of {items})"),
            EffectListFault::UnknownEffect { items } => write!(f, "is not an effect ({items})"),
            EffectListFault::Arguments { expected, found } => {
                write!(f, "takes {expected} ':' argument(s), {found} given")
            }
            EffectListFault::Joint => f.write_str("has a joint that is not a whole number from 1"),
            EffectListFault::Harmonics => {
                write!(f, "has a harmonic count that is not a whole number from 1 to {MAX_HARMONICS}")
            }
            EffectListFault::Pitch => {
                let (low, high) = PITCH_BOUNDS_MM;
                write!(f, "has a pitch that is not a number of millimetres from {low} to {high}")
            }
            EffectListFault::Duplicate => f.write_str("is named twice (the same effect on the same joint)"),
            EffectListFault::AutoWithOthers => f.write_str("stands alone: auto chooses every effect itself"),
        }
    }
}
