//! The kinds of fault that an [`Error`](crate::Error) carries, kept beside it so that the error
//! type depends on no reader: the readers and the effects re-export the kinds they raise.

use std::fmt;

/// The most harmonics a `gear_periodic` item may ask for: two parameters each, and a series of a
/// joint's own angle beyond a few dozen orders follows the noise of any campaign we know of (the
/// UR10 analysis of issue #11 found 24–32 enough). It also bounds the work a typo can ask for.
pub const MAX_HARMONICS: u32 = 256;

/// The range of a `screw_periodic` item's pitch, mm: the finest ball-screw leads sold are 0.5 mm
/// (miniature screws, THK/NSK catalogues), and a rack's pinion turns once in well under 10 m; a
/// value outside is a unit mistake (metres for millimetres, or the reverse) or a typing error.
pub const PITCH_BOUNDS_MM: (f64, f64) = (0.01, 10_000.0);

/// Why a cell's decimal mark is refused.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DecimalFault {
    /// A decimal comma in a `,`-separated file.
    CommaInCommaFile,
    /// The other mark than the file's earlier numbers.
    Other {
        /// The file's mark.
        expected: char,
    },
}

impl fmt::Display for DecimalFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecimalFault::CommaInCommaFile => f.write_str(
                "has a decimal comma in a ','-separated file (tracker exports with decimal commas separate fields with ';')",
            ),
            DecimalFault::Other { expected } => {
                write!(f, "does not use the file's decimal mark '{expected}' (set by its first numbers)")
            }
        }
    }
}

/// What is wrong with one item of a column map.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnMapFault {
    /// The argument is empty.
    Empty,
    /// An item has no `=` between the SPEC name and the header.
    MissingEquals,
    /// The name before `=` is not a column of the SPEC (with its unit).
    UnknownTarget,
    /// Nothing after `=`.
    EmptyHeader,
    /// A `"` opens a header that no `"` closes.
    UnclosedQuote,
    /// Text follows a quoted header before the next `,`.
    TextAfterQuote,
    /// The same SPEC name is mapped twice.
    DuplicateTarget,
    /// The same header is mapped twice.
    DuplicateHeader,
}

impl fmt::Display for ColumnMapFault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            ColumnMapFault::Empty => "the column map is empty (expected NAME=HEADER,…)",
            ColumnMapFault::MissingEquals => "expected NAME=HEADER",
            ColumnMapFault::UnknownTarget => {
                "is not a SPEC column name (q1_rad…, x_mm…, qw…, rx_deg…, payload_kg, tool, temp_c, t_s, tau1_nm…)"
            }
            ColumnMapFault::EmptyHeader => "has no header after '='",
            ColumnMapFault::UnclosedQuote => "has a '\"' that is never closed",
            ColumnMapFault::TextAfterQuote => "has text after the closing '\"'",
            ColumnMapFault::DuplicateTarget => "is mapped twice",
            ColumnMapFault::DuplicateHeader => "is mapped to two names",
        })
    }
}

/// What an existing path is, where it is not a regular file.
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    /// A directory.
    Directory,
    /// A FIFO (named pipe).
    Fifo,
    /// A Unix-domain socket.
    Socket,
    /// A character device (e.g. `/dev/null`).
    CharacterDevice,
    /// A block device.
    BlockDevice,
    /// Something else the operating system knows.
    Other,
}

impl fmt::Display for FileKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FileKind::Directory => "a directory",
            FileKind::Fifo => "a FIFO (named pipe)",
            FileKind::Socket => "a socket",
            FileKind::CharacterDevice => "a character device",
            FileKind::BlockDevice => "a block device",
            FileKind::Other => "something other than a file or a folder",
        })
    }
}

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
