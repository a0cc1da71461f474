//! What went wrong, apart from where: [`ErrorKind`] holds the numbers that explain a refusal, and
//! [`Error`](crate::Error) adds the [`Place`](crate::Place) that its message starts with.

use crate::{ColumnMapFault, DecimalFault, EffectListFault, FileKind};
use std::fmt;

/// What can go wrong reading inputs, fitting or evaluating: the kind of an [`Error`](crate::Error), without its
/// place (the file, line and column a message starts with).
#[non_exhaustive]
#[derive(Debug)]
pub enum ErrorKind {
    /// A file could not be read or written.
    Io {
        /// The operating system's error.
        source: std::io::Error,
    },
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
    /// Bytes that are not UTF-8 text.
    ///
    /// At the first such byte: its field, in a CSV file; its character, in a RON file.
    InvalidUtf8,
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
        /// The robot's kind of that joint, as `poe::JointKind::name` gives it (`revolute`, `prismatic`).
        kind: &'static str,
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
    /// A value in a RON file (robot or model) that must be a finite number and is not.
    NotFinite {
        /// The field, e.g. `flange.position` or `links[2].com_m`.
        field: String,
        /// The value found.
        value: f64,
    },
    /// A model file whose parts do not fit together: a count that differs from what another
    /// part needs (an edited or corrupt file).
    ModelCount {
        /// The field, e.g. `compensation.gp`.
        field: String,
        /// What is counted, e.g. `inputs`.
        what: &'static str,
        /// The count found.
        found: usize,
        /// The count the rest of the model needs.
        expected: usize,
    },
    /// A model file with an index out of its range.
    ModelIndex {
        /// The field, e.g. `joint_compliance.terms[3].joint`.
        field: String,
        /// The index found.
        index: usize,
        /// The index must be below this.
        limit: usize,
    },
    /// A robot or model file with a finite value far outside any robot cell (an edited or corrupt
    /// file): left in, its products overflow and the model predicts NaN poses.
    ModelValue {
        /// The field, e.g. `kinematics.joints[1]`.
        field: String,
        /// The value found.
        value: f64,
        /// Its magnitude must not exceed this.
        limit: f64,
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
    /// A RON file (robot or model) that does not parse, or holds an invalid value.
    RonFormat {
        /// What is wrong.
        message: String,
    },
    /// A URDF file that does not parse, or whose kinematic chain cannot be calibrated.
    UrdfFormat {
        /// What is wrong.
        message: String,
    },
    /// A joint of the URDF written into (`export --like`) that turns where the model's slides, or
    /// the other way round: the URDF keeps its joint types, so it would be calibrated wrongly.
    ///
    /// At the URDF's `<joint>` element.
    UrdfJointKind {
        /// The joint's name in the URDF.
        joint: String,
        /// The joint's 1-based place among the chain's movable joints.
        index: usize,
        /// Its kind in the URDF, as `poe::JointKind::name` gives it.
        urdf: &'static str,
        /// The model's kind of that joint, as `poe::JointKind::name` gives it.
        model: &'static str,
    },
    /// A nominal robot description whose joints are not where a calibrated model has them, once
    /// its base is placed by joint 1: not the description the model was fitted with.
    NominalMismatch {
        /// 1-based joint that is furthest off.
        joint: usize,
        /// Distance of the model's joint frame origin from the description's axis, mm.
        offset_mm: f64,
        /// Angle between the two axes, mrad.
        angle_mrad: f64,
        /// The largest offset accepted, mm.
        limit_mm: f64,
        /// The largest angle accepted, mrad.
        limit_mrad: f64,
    },
    /// A robot description with another number of joints than a calibrated model.
    RobotJointCount {
        /// Its joints.
        robot: usize,
        /// The model's joints.
        model: usize,
    },
    /// A targets file with an orientation that cannot be used: without a position, or for a model
    /// fitted on positions only.
    ///
    /// At line 1, the orientation's column.
    TargetOrientation {
        /// Whether the position columns are missing (otherwise the model has no orientation).
        without_position: bool,
    },
    /// Targets whose meaning needs the robot description: joint targets (the nominal model) or
    /// poses in the base frame.
    ///
    /// At 1:1.
    TargetsNeedRobot {
        /// Whether the targets are poses (in the base frame) rather than joint targets.
        poses: bool,
    },
    /// A robot description that a base-and-tool fit cannot lay onto the calibrated model.
    RegistrationMismatch {
        /// RMS distance left, mm.
        rms_mm: f64,
        /// The largest accepted, mm.
        limit_mm: f64,
    },
    /// A model with parts a URDF cannot hold, exported without the training data that measure
    /// the error left without them.
    ExportNeedsData {
        /// The parts.
        parts: Vec<String>,
    },
    /// A prismatic joint exported without the limits a URDF requires (no nominal description).
    PrismaticWithoutLimits {
        /// 1-based joint.
        joint: usize,
    },
    /// A model file written by another schema version.
    ///
    /// At 1:1.
    SchemaVersion {
        /// The version found.
        found: u32,
        /// The version this build reads.
        supported: u32,
    },
    /// The kinematic model or its identification failed.
    Kinematics {
        /// The underlying error (a `poe::Error`, `loadsim::Error` or `gp::Error`, boxed: this crate
        /// knows none of them), its message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// The load and effect models refused their input.
    Load {
        /// The underlying error (a `poe::Error`, `loadsim::Error` or `gp::Error`, boxed: this crate
        /// knows none of them), its message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// The Gaussian process failed.
    Gp {
        /// The underlying error (a `poe::Error`, `loadsim::Error` or `gp::Error`, boxed: this crate
        /// knows none of them), its message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// A simulated pose that is not finite: an effect or a robot beyond any real range.
    NonFiniteSimulation {
        /// 1-based row of the simulated set.
        row: usize,
    },
    /// A diagnosis option out of its range.
    DiagnoseOption {
        /// The option.
        field: &'static str,
        /// Its value.
        value: f64,
    },
    /// A report could not be written as JSON.
    Json {
        /// What was being written.
        what: &'static str,
        /// The underlying error.
        source: serde_json::Error,
    },
    /// The diagnosis's regularised normal equations were not positive definite: the data hold a
    /// non-finite number or are degenerate beyond what the prior can hold.
    DiagnoseSolve {
        /// Folds whose rows were left out of the fit (empty: every row).
        left_out: Vec<usize>,
        /// Number of columns of the system.
        columns: usize,
        /// The pivot at which the factorisation failed.
        pivot: usize,
    },
    /// Too few rows for what was asked.
    TooFewRows {
        /// Rows available.
        rows: usize,
        /// Rows needed.
        needed: usize,
    },
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
    /// A fit produced a model that the model file's check refuses: `fit` says so rather than
    /// write a file that `eval` would refuse.
    FittedModelRefused {
        /// The method fitted.
        method: String,
        /// The check's refusal (an [`Error`](crate::Error), boxed so that the kinds stay apart
        /// from the error that carries them).
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// A model's parts in an order they cannot apply in (an effect before the geometry).
    PartOrder {
        /// The part out of place.
        part: &'static str,
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
    /// A simulation asked for more rows than are made (`campaign::MAX_ROWS`).
    TooManySimulatedRows {
        /// The rows asked for.
        rows: usize,
        /// The most rows made.
        max: usize,
    },
    /// Two consecutive joints of a robot description whose motions are one (revolute about the
    /// same line, or prismatic along the same direction): their Jacobian columns are equal.
    ///
    /// At the second joint's axis in a RON file; the file alone otherwise.
    RepeatedJointAxis {
        /// The first joint, 1-based.
        first: usize,
        /// The second joint, 1-based.
        second: usize,
        /// Whether they are revolute (otherwise prismatic).
        revolute: bool,
        /// The second joint's axis direction.
        axis: [f64; 3],
        /// A point on it.
        point: [f64; 3],
    },
    /// A planar chain asked for what needs three dimensions (a simulated 3-D campaign).
    PlanarChain {
        /// The direction every revolute axis is parallel to.
        direction: [f64; 3],
        /// The joint count.
        joints: usize,
    },
    /// Measured positions that leave a plane, for a planar chain (whose tool moves in one): the
    /// data of another robot, or a joint axis wrong in the robot file.
    PlanarChainData {
        /// The robot's name.
        robot: String,
        /// The direction every revolute axis is parallel to.
        direction: [f64; 3],
        /// The joint count.
        joints: usize,
        /// RMS distance of the measured positions from their best plane, mm.
        out_of_plane_mm: f64,
        /// RMS distance of the measured positions from their centroid, mm.
        spread_mm: f64,
        /// Refused above this ratio of the two (`PlausibilityOptions::planar_ratio`).
        ratio: f64,
    },
    /// An output path that starts a chain of more symbolic links than are followed (a loop).
    OutputSymlinkChain {
        /// How many links were followed.
        links: usize,
    },
    /// A joint value beyond the robot's limits by more than the margin
    /// (`PlausibilityOptions::limit_margin_rad`): the first in file order.
    ///
    /// At the value: line 0 and the joint's number as column for rows made in memory.
    JointBeyondLimits {
        /// 1-based joint.
        joint: usize,
        /// `revolute` (value and limits in radians) or `prismatic` (metres), as `poe::JointKind::name`
        /// gives it.
        kind: &'static str,
        /// The value, SI.
        value: f64,
        /// The robot's limits, SI.
        limits: (f64, f64),
        /// The margin allowed beyond them, SI.
        margin: f64,
        /// Whether every value of the column, read as degrees, is within the limits (and the
        /// column says `_rad`).
        degrees_under_rad: bool,
    },
    /// Measured positions whose spread is not the robot's at the same joints: a unit mistake, a
    /// scale, or another robot (`PlausibilityOptions::scale_band`).
    PositionScale {
        /// RMS distance of the measured positions from their centroid, mm (read as the columns say).
        measured_spread_mm: f64,
        /// The same of the nominal model's tool points at the same joints, the tool fitted, mm.
        robot_spread_mm: f64,
        /// Measured over robot.
        ratio: f64,
        /// The unit the position columns name (`mm` or `m`).
        column_unit: &'static str,
        /// The unit the ratio says the positions are in, where it is near a unit mistake's factor.
        likely_unit: Option<&'static str>,
        /// The accepted ratios.
        band: (f64, f64),
    },
    /// Measured positions that a mirror image of the robot fits much better than the robot: a
    /// left-handed frame (`PlausibilityOptions::reflection_ratio`).
    LeftHandedFrame {
        /// RMS residual of the best rotation of the nominal tool points onto the measured, mm.
        rotation_rms_mm: f64,
        /// RMS residual of the best reflection, mm.
        reflection_rms_mm: f64,
        /// Refused where the reflection's residual is below this fraction of the rotation's.
        reflection_ratio: f64,
    },
    /// Too few poses for what a registration re-fits: `rows` residual rows for `parameters`
    /// parameters, `needed_poses` poses wanted (or too few poses of one tool).
    TooFewPoses {
        /// What is short: `the registration` or `tool 'x'`.
        what: String,
        /// Poses given.
        poses: usize,
        /// Poses needed.
        needed_poses: usize,
        /// Residual rows given.
        rows: usize,
        /// Parameters re-fitted.
        parameters: usize,
    },
    /// Registration data that name a tool the model does not know, and tools are not re-fitted.
    ///
    /// At the first row with it, its `tool` column.
    NewToolWithoutRefit {
        /// The tool's identifier.
        tool: String,
    },
    /// Poses that do not determine what a registration re-fits (e.g. all points on a line, or
    /// one flange orientation for a tool offset and a base rotation).
    PosesUndetermined {
        /// Directions the poses determine.
        rank: usize,
        /// Parameters re-fitted.
        parameters: usize,
        /// Largest over smallest singular value of the scaled Jacobian.
        condition: f64,
    },
    /// The registration's least squares did not converge.
    RegistrationNotConverged {
        /// Iterations run.
        iterations: usize,
        /// RMS residual at the end, m.
        rms_m: f64,
    },
    /// A registration or planning option out of its range.
    OptionOutOfRange {
        /// The option's field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        expected: &'static str,
    },
    /// Fewer planning candidates than poses asked for.
    TooFewCandidates {
        /// Candidates available.
        candidates: usize,
        /// Poses asked for.
        poses: usize,
    },
    /// Planning candidates that determine no direction of the identification.
    NoIdentifiableDirection {
        /// Candidates.
        candidates: usize,
    },
    /// The pose generator refused its input while drawing planning candidates (`calib plan
    /// --generate`); the message is the generator's own.
    Generator {
        /// The underlying error (a `loadsim::Error`, boxed: this crate knows none of them), its
        /// message and `source()` chain kept.
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// A chart of the calibration report could not be drawn.
    Plot {
        /// The chart.
        figure: String,
        /// What `plotters` said.
        message: String,
    },
    /// The evaluation embedded in the calibration report could not be written as JSON.
    EvaluationJson {
        /// The underlying error.
        source: serde_json::Error,
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
            ErrorKind::Io { source } => write!(f, "{source}"),
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
            ErrorKind::InvalidUtf8 => write!(f, "the text is not UTF-8"),
            ErrorKind::DecimalMark { name, text, fault } => {
                write!(f, "column '{name}': '{text}' {fault}")
            }
            ErrorKind::NegativePayload { value } => {
                write!(f, "column 'payload_kg': {value} kg, a payload cannot be negative")
            }
            ErrorKind::JointUnit { joint, kind } => match *kind {
                "prismatic" => {
                    write!(f, "joint {joint} is prismatic: its column is q{joint}_m or q{joint}_mm, not an angle")
                }
                _ => {
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
            ErrorKind::NotFinite { field, value } => {
                write!(f, "{field} is {value}, a finite number is needed")
            }
            ErrorKind::ModelCount { field, what, found, expected } => {
                write!(f, "{field} has {found} {what}, the rest of the model needs {expected}")
            }
            ErrorKind::ModelIndex { field, index, limit } => {
                write!(f, "{field} is {index}, it must be below {limit}")
            }
            ErrorKind::ModelValue { field, value, limit } => write!(
                f,
                "{field} is {value:e}, beyond ±{limit:e}: larger than any robot cell (an edited or corrupt file)"
            ),
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
            ErrorKind::UrdfJointKind { joint, index, urdf, model } => write!(
                f,
                "joint '{joint}' (movable joint {index}) is {} in the URDF but {} in the \
                 model: refusing to write the calibration into a joint of another kind",
                urdf, model
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
            ErrorKind::RonFormat { message } | ErrorKind::UrdfFormat { message } => {
                write!(f, "{message}")
            }
            ErrorKind::NominalMismatch { joint, offset_mm, angle_mrad, limit_mm, limit_mrad } => write!(
                f,
                "joint {joint} of this robot is {offset_mm:.1} mm and {angle_mrad:.1} mrad from the model's (at most {limit_mm} mm and {limit_mrad} mrad expected): give the robot description the model was fitted with"
            ),
            ErrorKind::TargetOrientation { without_position: true } => {
                write!(f, "an orientation without x_mm, y_mm, z_mm: give the whole pose, or joint targets alone")
            }
            ErrorKind::TargetOrientation { without_position: false } => write!(
                f,
                "the model was fitted on positions only, its orientation is not calibrated: give position targets"
            ),
            ErrorKind::TargetsNeedRobot { poses: false } => write!(
                f,
                "joint targets are a program taught on the nominal model: give its robot description (--robot)"
            ),
            ErrorKind::TargetsNeedRobot { poses: true } => {
                write!(f, "poses in the base frame need the robot description (--robot) to place the base")
            }
            ErrorKind::RegistrationMismatch { rms_mm, limit_mm } => write!(
                f,
                "this robot, placed on the model by base and tool, stays {rms_mm:.1} mm from it (at most {limit_mm} mm expected): give the robot description the model was fitted with"
            ),
            ErrorKind::RobotJointCount { robot, model } => {
                write!(f, "the robot has {robot} joints, the model {model}: not the robot the model was fitted for")
            }
            ErrorKind::ExportNeedsData { parts } => write!(
                f,
                "the model has {} that a URDF cannot hold: give its training data (--data) to measure the error left without them",
                parts.join(" and ")
            ),
            ErrorKind::PrismaticWithoutLimits { joint } => write!(
                f,
                "joint {joint} is prismatic and a URDF needs its limits: give the robot description (--robot or --like)"
            ),
            ErrorKind::SchemaVersion { found, supported } => {
                write!(f, "model file has schema version {found}, this calib reads versions 1 to {supported}")
            }
            ErrorKind::Kinematics { source } => write!(f, "{source}"),
            ErrorKind::Load { source } => write!(f, "load model: {source}"),
            ErrorKind::Gp { source } => write!(f, "Gaussian process: {source}"),
            ErrorKind::NonFiniteSimulation { row } => write!(
                f,
                "simulated row {row} is not finite: an effect or the robot is beyond any real range (nothing written)"
            ),
            ErrorKind::DiagnoseOption { field, value } => {
                write!(f, "diagnose option {field} = {value} is out of range")
            }
            ErrorKind::Json { what, source } => write!(f, "{what} as JSON: {source}"),
            ErrorKind::DiagnoseSolve { left_out, columns, pivot } => write!(
                f,
                "diagnose: the regularised fit without folds {left_out:?} ({columns} columns) is not positive definite at pivot {pivot}"
            ),
            ErrorKind::TooFewRows { rows, needed } => {
                write!(f, "{rows} measurement rows, at least {needed} needed")
            }
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
            ErrorKind::FittedModelRefused { method, source } => write!(
                f,
                "the fitted {method} model fails the check every model file passes on reading, so it is not written: {source}"
            ),
            ErrorKind::PartOrder { part } => write!(f, "a model's {part} comes before its geometry"),
            ErrorKind::EffectNeedsColumn { line, effect, column } => {
                write!(f, "line {line}: {effect} needs the column '{column}', which this row lacks")
            }
            ErrorKind::EffectColumnConstant { effect, column, value, rows, lines: [first, last] } => write!(
                f,
                "lines {first}-{last}: {effect} needs the column '{column}' to vary, but its values do not vary \
                 ({column} = {value} on all {rows} rows): its parameters are unobservable; leave {effect} out"
            ),
            ErrorKind::OutputIsInput { output_option, output, input_option, input } => write!(
                f,
                "{output_option} {output} is the same file as {input_option} {input}: refusing to overwrite an input"
            ),
            ErrorKind::OutputNotRegularFile { kind } => {
                write!(f, "is {kind}, not a regular file: refusing to replace it with an output")
            }
            ErrorKind::TooManySimulatedRows { rows, max } => write!(
                f,
                "{rows} rows asked for: at most {max} are simulated (up to 280 MB of CSV and 25 s; is the count mistyped?)"
            ),
            ErrorKind::RepeatedJointAxis { first, second, revolute, axis, point } => {
                let [a, b, c] = axis;
                let [x, y, z] = point;
                if *revolute {
                    write!(
                        f,
                        "joints {first} and {second} turn about the same line (direction ({a}, {b}, {c}) through \
                         ({x}, {y}, {z}) m): no joint between them moves one off the other, so their columns in the \
                         identification Jacobian are equal at every pose and their angles cannot be told apart; \
                         correct the axis or merge the two joints"
                    )
                } else {
                    write!(
                        f,
                        "joints {first} and {second} slide along the same direction ({a}, {b}, {c}): their columns \
                         in the identification Jacobian are equal at every pose and their values cannot be told apart; \
                         correct the axis or merge the two joints"
                    )
                }
            }
            ErrorKind::PlanarChain { direction: [a, b, c], joints } => write!(
                f,
                "the chain is planar: all {joints} joints turn about axes parallel to ({a}, {b}, {c}) (prismatic \
                 ones slide across it), so the tool moves in a plane and 3-D positions cannot be drawn for it; \
                 check the joint axes"
            ),
            ErrorKind::PlanarChainData { robot, direction: [a, b, c], joints, out_of_plane_mm, spread_mm, ratio } => {
                write!(
                    f,
                    "the positions leave a plane, but {robot}'s chain is planar: all {joints} joints turn about \
                     axes parallel to ({a}, {b}, {c}), so its tool moves in a plane; the positions lie {out_of_plane_mm:.1} mm \
                     RMS off their best plane, {:.1} % of their {spread_mm:.1} mm spread (accepted: {:.1} %): the data of \
                     another robot, or a joint axis wrong in the robot file?",
                    100.0 * out_of_plane_mm / spread_mm,
                    100.0 * ratio
                )
            }
            ErrorKind::OutputSymlinkChain { links } => {
                write!(f, "more than {links} symbolic links in a row (a loop?): refusing to write there")
            }
            ErrorKind::JointBeyondLimits { joint, kind, value, limits: (lo, hi), margin, degrees_under_rad } => {
                match *kind {
                    "revolute" => write!(
                        f,
                        "joint {joint} is at {value} rad ({:.1}°), beyond its limits {:.1}° to {:.1}° by more than {:.1}°",
                        value.to_degrees(),
                        lo.to_degrees(),
                        hi.to_degrees(),
                        margin.to_degrees()
                    )?,
                    _ => write!(
                        f,
                        "joint {joint} is at {value} m, beyond its limits {lo} m to {hi} m by more than {margin} m"
                    )?,
                }
                if *degrees_under_rad {
                    write!(f, ": degrees under `_rad`? (every value of the column fits the limits read as degrees)")?;
                }
                write!(f, " (--force fits anyway)")
            }
            ErrorKind::PositionScale { measured_spread_mm, robot_spread_mm, ratio, column_unit, likely_unit, band } => {
                let spreads = format!(
                    "measured spread {measured_spread_mm:.4} mm, the robot's {robot_spread_mm:.1} mm at these joints: ratio {ratio:.4}"
                );
                match likely_unit {
                    Some(unit) => write!(
                        f,
                        "positions look like {unit} under _{column_unit} columns ({spreads}); give the columns the positions' unit (--force fits anyway)"
                    ),
                    None => write!(
                        f,
                        "the positions do not have the robot's size ({spreads}, outside {} to {}): a unit, a scale or another robot's description? (--force fits anyway)",
                        band.0, band.1
                    ),
                }
            }
            ErrorKind::LeftHandedFrame { rotation_rms_mm, reflection_rms_mm, .. } => write!(
                f,
                "the measured frame looks left-handed: two position columns swapped? (the robot turned onto the measurements leaves {rotation_rms_mm:.1} mm RMS, its mirror image {reflection_rms_mm:.1} mm) (--force fits anyway)"
            ),
            ErrorKind::TooFewPoses { what, poses, needed_poses, rows, parameters } => write!(
                f,
                "too few poses for {what}: {poses} poses ({rows} residual rows) for {parameters} re-fitted \
                 parameters; at least {needed_poses} poses are needed"
            ),
            ErrorKind::NewToolWithoutRefit { tool } => write!(
                f,
                "tool '{tool}' is not in the model; re-fit tools to add it (--refit tools or --refit base,tools)"
            ),
            ErrorKind::PosesUndetermined { rank, parameters, condition } => write!(
                f,
                "the poses determine only {rank} of the {parameters} re-fitted parameters (condition number \
                 {condition:.3e}): measure poses with more varied joint angles and flange orientations"
            ),
            ErrorKind::RegistrationNotConverged { iterations, rms_m } => write!(
                f,
                "the registration did not converge in {iterations} iterations (RMS residual {:.4} mm)",
                rms_m * 1e3
            ),
            ErrorKind::OptionOutOfRange { field, value, expected } => {
                write!(f, "option {field} = {value}: expected {expected}")
            }
            ErrorKind::TooFewCandidates { candidates, poses } => {
                write!(f, "{poses} poses asked for but only {candidates} candidates given")
            }
            ErrorKind::NoIdentifiableDirection { candidates } => {
                write!(f, "the {candidates} candidates determine no direction of the identification")
            }
            ErrorKind::Generator { source } => write!(f, "{source}"),
            ErrorKind::Plot { figure, message } => write!(f, "the chart {figure:?} could not be drawn: {message}"),
            ErrorKind::EvaluationJson { source } => {
                write!(f, "the evaluation could not be written as JSON: {source}")
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

impl ErrorKind {
    /// The error underneath, where the kind wraps one.
    pub(crate) fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            ErrorKind::Io { source } => Some(source),
            ErrorKind::Kinematics { source }
            | ErrorKind::Load { source }
            | ErrorKind::Gp { source }
            | ErrorKind::Generator { source }
            | ErrorKind::FittedModelRefused { source, .. } => Some(source.as_ref()),
            ErrorKind::Json { source, .. } | ErrorKind::EvaluationJson { source } => Some(source),
            _ => None,
        }
    }
}
