//! The refusals of the measurement readers and writers: the kinds of [`errors::Error`] this crate raises,
//! with their messages (the error adds the file, line and column a message starts with).

use poe::JointKind;
use std::fmt;

/// What the measurement readers (CSV, column maps, `--inputs`) and the output writers refuse.
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A measurement file has no header or no data row.
    ///
    /// At 1:1.
    EmptyFile,
    /// The CSV layer refused a line (e.g. a row with a different number of fields).
    ///
    /// At the line, and the field where known (else column 1).
    CsvSyntax {
        /// What the CSV reader said.
        message: String,
    },
    /// A row with another number of fields than the header.
    ///
    /// At the row, the first field one of the two lacks.
    FieldCount {
        /// Fields in the row.
        found: u64,
        /// Fields in the header.
        expected: u64,
        /// The file's field separator.
        delimiter: char,
    },
    /// A number whose decimal mark does not fit the file.
    DecimalMark {
        /// The column's name.
        name: String,
        /// The cell's text.
        text: String,
        /// What is wrong with it.
        fault: DecimalFault,
    },
    /// A negative `payload_kg`.
    NegativePayload {
        /// The value, kg.
        value: f64,
    },
    /// A joint column whose unit does not fit its joint: an angle on a prismatic joint, a
    /// length on a revolute one.
    ///
    /// At the joint's column of the header.
    JointUnit {
        /// 1-based joint.
        joint: usize,
        /// The robot's kind of that joint.
        kind: JointKind,
    },
    /// A per-joint column (`tau<k>_nm`) for a joint the data does not have.
    ///
    /// At the column, in the header.
    ColumnBeyondJoints {
        /// The column's name.
        name: String,
        /// The joint it names (1-based).
        index: usize,
        /// The data's joint count.
        joints: usize,
    },
    /// The orientation given both as a quaternion and as Euler angles.
    ///
    /// At the later of the two columns, in the header.
    OrientationTwice {
        /// Its name.
        name: String,
        /// The name of the earlier one.
        other: String,
    },
    /// A column map names a header the file does not have.
    ///
    /// At the end of the header (its field count + 1).
    MappedHeaderMissing {
        /// The SPEC name it was to give.
        target: String,
        /// The header named.
        header: String,
    },
    /// A `--columns` argument that does not parse.
    ///
    /// At `--columns:1:COLUMN`, the character where the faulty item starts.
    ColumnMap {
        /// The faulty item.
        text: String,
        /// What is wrong with it.
        fault: ColumnMapFault,
    },
    /// A required column is absent.
    ///
    /// At the end of the header (its field count + 1): where the column should have been.
    MissingColumn {
        /// The missing column's name.
        name: String,
    },
    /// A column name appears twice (or a quantity twice in two units).
    ///
    /// At the second occurrence, in the header.
    DuplicateColumn {
        /// The column's name.
        name: String,
    },
    /// A cell that must be a number is not one, or is NaN or infinite.
    NotANumber {
        /// The column's name.
        name: String,
        /// The cell's text.
        text: String,
    },
    /// A number beyond any physical range for its column (e.g. a position beyond 1 km): a unit
    /// or export error, refused before it wrecks a fit.
    BeyondPhysicalRange {
        /// The column's name.
        name: String,
        /// The value, in SI units (`unit`).
        value: f64,
        /// The largest magnitude accepted, in `unit`.
        limit: f64,
        /// The SI unit of `value` and `limit`.
        unit: &'static str,
        /// What the column holds (e.g. "position", "joint angle").
        quantity: &'static str,
    },
    /// The joint columns do not match the robot's joint count.
    ///
    /// In the header, at the first extra joint column or where the missing one should be.
    JointCountMismatch {
        /// Joint columns found.
        found: usize,
        /// The robot's joint count.
        expected: usize,
    },
    /// A quaternion whose norm is off by more than 1e-3.
    ///
    /// At the row's `qw`.
    QuaternionNorm {
        /// The norm found.
        norm: f64,
    },
    /// A tool identifier the model was not fitted with.
    ///
    /// At the row's `tool`.
    UnknownTool {
        /// The identifier.
        tool: String,
        /// The identifiers the model knows.
        known: Vec<String>,
    },
    /// An output that is one of the command's own inputs (the same path, a symbolic link to it,
    /// or a hard link): refused before anything is written.
    OutputIsInput {
        /// The option that names the output (e.g. `--out`).
        output_option: &'static str,
        /// The output path as given.
        output: String,
        /// The option that names the input (e.g. `--data`).
        input_option: &'static str,
        /// The input path as given.
        input: String,
    },
    /// An output path where something other than a regular file (or a symbolic link to one)
    /// exists: a directory, a FIFO, a device node. Writing would replace it with a regular file.
    OutputNotRegularFile {
        /// What is there.
        kind: FileKind,
    },
    /// An output path that starts a chain of more symbolic links than are followed (a loop).
    OutputSymlinkChain {
        /// How many links were followed.
        links: usize,
    },
    /// A column named as an input of the model (`--inputs`) that cannot be one: a joint (already
    /// an input), the measured pose (what the model predicts), the tool (not a number) or a
    /// tracker's stated uncertainty.
    ///
    /// At the column in the header.
    NotAnInput {
        /// The column's name.
        name: String,
        /// What the column is.
        quantity: &'static str,
    },
    /// An `--inputs` list with an empty name or a name given twice.
    ///
    /// At `--inputs:1:COLUMN`, the character where the name starts.
    InputList {
        /// The name at fault (empty for an empty one).
        name: String,
    },
    /// A stated standard deviation (`std_x_mm` …) that is zero or negative: it would weight its
    /// row infinitely, or not at all.
    ///
    /// At the cell.
    NotAStandardDeviation {
        /// The column's name.
        name: String,
        /// The value as written.
        value: f64,
    },
    /// A row without a value of an input the model takes (`--inputs`): rows made in memory
    /// without it (a file without the column is refused by its header, `MissingColumn`).
    ///
    /// At the row's line.
    MissingInput {
        /// The input's name.
        name: String,
    },
}

impl fmt::Display for ErrorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ErrorKind::EmptyFile => write!(f, "the file has no header or no data row"),
            ErrorKind::CsvSyntax { message } => write!(f, "{message}"),
            ErrorKind::FieldCount { found, expected, delimiter } => {
                write!(f, "row has {found} fields, the header has {expected}")?;
                if *delimiter == ',' && found > expected {
                    write!(
                        f,
                        " (decimal commas in a ','-separated file? tracker exports with decimal commas separate fields with ';')"
                    )?;
                }
                Ok(())
            }
            ErrorKind::DecimalMark { name, text, fault } => {
                write!(f, "column '{name}': '{text}' {fault}")
            }
            ErrorKind::NegativePayload { value } => {
                write!(f, "column 'payload_kg': {value} kg, a payload cannot be negative")
            }
            ErrorKind::JointUnit { joint, kind } => match kind {
                JointKind::Prismatic => {
                    write!(f, "joint {joint} is prismatic: its column is q{joint}_m or q{joint}_mm, not an angle")
                }
                JointKind::Revolute => {
                    write!(f, "joint {joint} is revolute: its column is q{joint}_rad or q{joint}_deg, not a length")
                }
            },
            ErrorKind::ColumnBeyondJoints { name, index, joints } => {
                write!(f, "column '{name}' is for joint {index}, the data has {joints} joints")
            }
            ErrorKind::OrientationTwice { name, other } => write!(
                f,
                "column '{name}': the orientation is already given by '{other}'; give a quaternion (qw, qx, qy, qz) or Euler angles (rx, ry, rz), not both"
            ),
            ErrorKind::MappedHeaderMissing { target, header } => {
                write!(f, "--columns maps {target} to the header '{header}', which the file does not have")
            }
            ErrorKind::ColumnMap { text, fault } => write!(f, "'{text}' {fault}"),
            ErrorKind::MissingColumn { name } => {
                write!(f, "missing required column '{name}'")
            }
            ErrorKind::DuplicateColumn { name } => {
                write!(f, "column '{name}' appears more than once")
            }
            ErrorKind::NotANumber { name, text } => {
                write!(f, "column '{name}': '{text}' is not a finite number")
            }
            ErrorKind::BeyondPhysicalRange { name, value, limit, unit, quantity } => write!(
                f,
                "column '{name}': {value:e} {unit} is beyond any physical {quantity} \
                 (at most {limit:e} {unit} in magnitude): check the column's unit"
            ),
            ErrorKind::JointCountMismatch { found, expected } => {
                write!(f, "{found} joint columns, the robot has {expected} joints")
            }
            ErrorKind::QuaternionNorm { norm } => {
                write!(f, "quaternion (qw, qx, qy, qz) has norm {norm:.6}, expected 1 within 1e-3")
            }
            ErrorKind::UnknownTool { tool, known } => {
                let known: Vec<String> = known
                    .iter()
                    .map(|t| if t.is_empty() { "the default tool".to_owned() } else { format!("'{t}'") })
                    .collect();
                let known = if known.is_empty() { "none".to_owned() } else { known.join(", ") };
                if tool.is_empty() {
                    write!(
                        f,
                        "a row without a tool name is the default tool, which the model was not fitted with (it knows {known}); name the tool in a 'tool' column"
                    )
                } else {
                    write!(f, "tool '{tool}' is not in the model (it knows {known})")
                }
            }
            ErrorKind::OutputIsInput { output_option, output, input_option, input } => write!(
                f,
                "{output_option} {output} is the same file as {input_option} {input}: refusing to overwrite an input"
            ),
            ErrorKind::OutputNotRegularFile { kind } => {
                write!(f, "is {kind}, not a regular file: refusing to replace it with an output")
            }
            ErrorKind::OutputSymlinkChain { links } => {
                write!(f, "more than {links} symbolic links in a row (a loop?): refusing to write there")
            }
            ErrorKind::NotAnInput { name, quantity } => {
                write!(f, "column '{name}' is {quantity}: it cannot be an input of the model (--inputs)")
            }
            ErrorKind::InputList { name } if name.is_empty() => {
                write!(f, "an empty name in the list of inputs (NAME[,NAME…])")
            }
            ErrorKind::InputList { name } => write!(f, "the input '{name}' is named twice"),
            ErrorKind::NotAStandardDeviation { name, value } => {
                write!(f, "{name} is {value}: a stated standard deviation must be a positive number")
            }
            ErrorKind::MissingInput { name } => {
                write!(f, "no value of the input '{name}', which the model takes (the column '{name}')")
            }
        }
    }
}

impl std::error::Error for ErrorKind {}

impl errors::Kind for ErrorKind {}

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
