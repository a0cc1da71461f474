//! The measurement CSV of the SPEC: one row per measured pose, columns found by name, the unit in
//! the name. Every refusal names the file, the line and the column.
//!
//! `layout` reads the header, `dialect` the numbers (`,`/`.` or a tracker's `;`/`,`),
//! `column_map` the `--columns` renaming, `row` the cells of one row, `writer` writes a set back
//! as SPEC CSV.
//!
//! A set meets a model only bound to it: [`BoundSet`] holds the rows with each one's model tool
//! index, made once by the constructor that checks the joints and maps the tools, and is what
//! every function that applies a model or an effect to rows takes.
//!
//! ```
//! use measurements::{ReadOptions, parse_measurements};
//! let csv = "q1_rad,q2_rad,x_mm,y_mm,z_mm\n0.1,0.2,1000,0,500\n0.3,-0.1,990,12,510\n";
//! let data = parse_measurements(csv.as_bytes(), "poses.csv", &ReadOptions::default())?;
//! assert_eq!(data.rows.len(), 2);
//! assert!((data.rows[0].position.x - 1.0).abs() < 1e-12); // SI inside: metres
//! let bad = "q1_rad,x_mm,y_mm,z_mm\n0.1,abc,0,0\n";
//! let error = parse_measurements(bad.as_bytes(), "poses.csv", &ReadOptions::default()).unwrap_err();
//! assert!(error.to_string().starts_with("poses.csv:2:2:"), "{error}");
//! # Ok::<(), errors::Error>(())
//! ```
#![deny(missing_docs)]

mod bound;
mod column_map;
mod dialect;
mod error_kind;
mod file_lines;
mod input_files;
mod inputs;
mod layout;
mod outliers;
mod output_file;
mod quantity;
mod row;
mod writer;
pub use bound::{BoundSet, model_tool};
pub use error_kind::ErrorKind;
pub use input_files::InputFiles;
pub use inputs::{INPUT_UNITS, InputColumn, InputNames, Inputs, input_unit};
pub use outliers::{OutlierLine, list_lines, without};
pub use output_file::{FileKind, MAX_SYMLINKS, OutputFile, output_target, write_file};
/// A row's stated standard deviations (`std_x_mm` …), as the identification weighs them.
pub use poe::identify::StatedSigma;

pub use column_map::{ColumnMap, ColumnMapFault};
pub use dialect::{Decimal, DecimalFault, Delimiter, Dialect};
pub use writer::{CsvColumns, MeasurementWriter};

use errors::Error;
use file_lines::LineCounter;
use layout::{Expectation, Layout, OrientationColumns};
use lie::{SO3, Vector3};
use poe::JointKind;
use row::{JOINT_ANGLE_RANGE, JOINT_TRAVEL_RANGE, POSITION_RANGE, Row, syntax_error};
use serde::{Deserialize, Serialize};
use std::collections::HashMap;
use std::fmt;
use std::io::Read;
use std::path::Path;

/// One measured pose, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// The row's line in its file as an editor counts it (0 for rows made in memory): the header
    /// is line 1, and blank lines and the lines of a quoted field with a line break count.
    pub line: u64,
    /// Joint values, radians (metres for a prismatic joint).
    pub q: Vec<f64>,
    /// Measured tool point, tracker frame, metres.
    pub position: Vector3,
    /// Measured tool orientation, tracker frame (full-pose data only).
    pub orientation: Option<SO3>,
    /// Payload carried at the tool, kg.
    pub payload_kg: f64,
    /// Index into [`MeasurementSet::tools`].
    pub tool: usize,
    /// Temperature, °C.
    pub temp_c: Option<f64>,
    /// Time, seconds from any origin.
    pub t_s: Option<f64>,
    /// Measured joint torques, N·m.
    pub torques_nm: Option<Vec<f64>>,
    /// The values of the columns read as inputs of a model (`--inputs`), by name, as written.
    pub inputs: Inputs,
    /// The tracker's stated standard deviations of this row (`std_x_mm` …, `std_rx_mrad` …; SI),
    /// where the file has them.
    pub std: Option<StatedSigma>,
}

impl Measurement {
    /// A row made in memory (a test's, or a configuration to predict at): joints `q` and the
    /// position `position` (tracker frame, m), every other field at its neutral value: line 0, no
    /// orientation, no payload, tool 0, no temperature, time or torques. Set the others with
    /// struct update syntax, e.g. `Measurement { payload_kg: 5.0, ..Measurement::at(q, p) }`.
    pub fn at(q: Vec<f64>, position: Vector3) -> Self {
        Self {
            line: 0,
            q,
            position,
            orientation: None,
            payload_kg: 0.0,
            tool: 0,
            temp_c: None,
            t_s: None,
            torques_nm: None,
            inputs: Inputs::default(),
            std: None,
        }
    }
}

/// A joint column as the file names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct JointColumn {
    /// 1-based column in the file.
    pub column: usize,
    /// The kind of joint its unit fits: revolute for `_rad`/`_deg`, prismatic for `_m`/`_mm`.
    pub kind: JointKind,
    /// The unit its name gives: `rad`, `deg`, `m` or `mm` (the plausibility check's hint
    /// "degrees under `_rad`?" needs it).
    pub unit: &'static str,
}

/// How a file was written, as the reader found it (reported by the CLI in one line).
#[derive(Debug, Clone, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct FileFormat {
    /// Field separator and decimal mark.
    pub dialect: Dialect,
    /// Whether the orientation came from Euler angles (`R = Rx·Ry·Rz`) rather than a quaternion.
    pub euler_angles: bool,
    /// Columns renamed by a column map: `(SPEC name, header)`.
    pub mapped_columns: Vec<(String, String)>,
}

impl fmt::Display for FileFormat {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.dialect)?;
        if self.euler_angles {
            write!(f, "; orientation from Euler angles (R = Rx·Ry·Rz)")?;
        }
        if !self.mapped_columns.is_empty() {
            write!(f, "; {} columns named by --columns", self.mapped_columns.len())?;
        }
        Ok(())
    }
}

/// The rows of one measurement file.
#[derive(Debug, Clone, PartialEq)]
pub struct MeasurementSet {
    /// Where the rows come from (a path), for messages.
    pub source: String,
    /// Number of joint columns.
    pub joint_count: usize,
    /// Whether every row has an orientation.
    pub full_pose: bool,
    /// Tool identifiers in order of first appearance. `""` is the default tool: every row of a
    /// file without a `tool` column, and every blank `tool` cell (SPEC v2).
    pub tools: Vec<String>,
    /// 1-based column of `tool` in the file, if it has one.
    pub tool_column: Option<usize>,
    /// The rows, in file order.
    pub rows: Vec<Measurement>,
    /// Columns found but not used, by name.
    pub ignored_columns: Vec<String>,
    /// Whether the rows carry measured positions ([`read_configurations`] may read sets without).
    pub positions_measured: bool,
    /// The joint columns, base first, as the file names them (empty for sets made in memory).
    pub joint_columns: Vec<JointColumn>,
    /// The unit the position columns name, `mm` or `m` (`None` for sets made in memory).
    pub position_unit: Option<&'static str>,
    /// How the file was written.
    pub format: FileFormat,
    /// The columns read as inputs of a model ([`ReadOptions::inputs`]), in that order (empty for
    /// sets made in memory).
    pub inputs: Vec<InputColumn>,
    /// The header's line in the file (1 unless blank lines precede it; 1 for sets made in
    /// memory): where a refusal of the header is placed.
    pub header_line: u64,
}

/// What a measurement file is read against.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReadOptions {
    /// The robot's joints, base first: their count is checked against the joint columns, and
    /// each column's unit against its joint's kind (an angle unit on a prismatic joint is
    /// refused). `None` reads any number of joints.
    pub joints: Option<Vec<JointKind>>,
    /// Other headers mapped onto the SPEC's names (`--columns`).
    pub columns: ColumnMap,
    /// Columns kept as inputs of a model (`--inputs`, or the inputs a fitted model takes), by
    /// their name after `columns`: a file without one is refused by its name, and a cell that is
    /// not a finite number at its line and column.
    pub inputs: Vec<String>,
}

impl ReadOptions {
    /// Reading for a robot with these joints.
    pub fn for_joints(joints: Vec<JointKind>) -> Self {
        Self { joints: Some(joints), ..Self::default() }
    }

    /// The same, with a column map.
    pub fn with_columns(self, columns: ColumnMap) -> Self {
        Self { columns, ..self }
    }

    /// The same, keeping the columns `inputs` as inputs of a model.
    pub fn with_inputs(self, inputs: Vec<String>) -> Self {
        Self { inputs, ..self }
    }
}

/// Reads a measurement file.
pub fn read_measurements(path: &Path, options: &ReadOptions) -> Result<MeasurementSet, Error> {
    let file = path.display().to_string();
    let reader = std::fs::File::open(path).map_err(|source| Error::io(file.clone(), source))?;
    parse(reader, &file, options, true)
}

/// Parses measurements from any reader; `file` names the source in errors.
pub fn parse_measurements<R: Read>(reader: R, file: &str, options: &ReadOptions) -> Result<MeasurementSet, Error> {
    parse(reader, file, options, true)
}

/// Reads joint configurations to predict poses for: the measurement CSV in which the position
/// columns may be left out (then [`MeasurementSet::positions_measured`] is false and every
/// position is zero). Every other rule of the format holds.
pub fn read_configurations(path: &Path, options: &ReadOptions) -> Result<MeasurementSet, Error> {
    let file = path.display().to_string();
    let reader = std::fs::File::open(path).map_err(|source| Error::io(file.clone(), source))?;
    parse(reader, &file, options, false)
}

/// The cells of a file as written (trimmed), header and rows, beside its parsed rows: what a
/// command that passes unused columns on needs (`calib compensate`).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Cells {
    /// The header's names.
    pub header: Vec<String>,
    /// Each row's cells, in the order of [`MeasurementSet::rows`].
    pub rows: Vec<Vec<String>>,
}

/// [`read_configurations`], with every cell as written.
pub fn read_configurations_with_cells(path: &Path, options: &ReadOptions) -> Result<(MeasurementSet, Cells), Error> {
    let file = path.display().to_string();
    let reader = std::fs::File::open(path).map_err(|source| Error::io(file.clone(), source))?;
    let mut cells = Cells::default();
    let set = parse_keeping(reader, &file, options, false, Some(&mut cells))?;
    Ok((set, cells))
}

fn parse<R: Read>(
    reader: R,
    file: &str,
    options: &ReadOptions,
    positions_required: bool,
) -> Result<MeasurementSet, Error> {
    parse_keeping(reader, file, options, positions_required, None)
}

fn parse_keeping<R: Read>(
    mut reader: R,
    file: &str,
    options: &ReadOptions,
    positions_required: bool,
    mut cells: Option<&mut Cells>,
) -> Result<MeasurementSet, Error> {
    let mut bytes = Vec::new();
    reader.read_to_end(&mut bytes).map_err(|source| Error::io(file.to_owned(), source))?;
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(&bytes);
    let mut dialect = Dialect::from_header_line(body);
    let mut csv = csv::ReaderBuilder::new()
        .has_headers(true)
        .delimiter(dialect.delimiter.byte())
        .trim(csv::Trim::All)
        .from_reader(body);
    let delimiter = dialect.delimiter;
    // Every row by the line an editor shows it on (module `file_lines`): the header's, 1 unless
    // blank lines precede it, then each record's from the same counter.
    let mut lines = LineCounter::new(body);
    let header = read_header(&mut csv, &mut lines, (file, body, delimiter), options, positions_required)?;
    if let Some(cells) = cells.as_deref_mut() {
        cells.header = header.record.iter().map(str::to_owned).collect();
    }
    let input_names: std::sync::Arc<[String]> = options.inputs.clone().into();
    let mut tools = Tools::default();
    let mut rows = Vec::new();
    let mut record = csv::StringRecord::new();
    loop {
        match csv.read_record(&mut record) {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) => return Err(syntax_error(&e, file, delimiter, body)),
        }
        let line = record.position().map_or(0, |p| lines.record_line(p.byte()));
        let mut row = Row { record: &record, line, file, names: &header.layout.names, dialect: &mut dialect };
        rows.push(read_measurement(&mut row, &header.layout, &input_names, &mut tools)?);
        if let Some(cells) = cells.as_deref_mut() {
            cells.rows.push(record.iter().map(str::to_owned).collect());
        }
    }
    if rows.is_empty() {
        return Err(Error::at_line(file.to_owned(), 1, 1, ErrorKind::EmptyFile));
    }
    Ok(measurement_set(file, header, options, dialect, tools.names, rows))
}

/// A file's header: its cells, its line and the layout they give.
struct Header {
    record: csv::StringRecord,
    line: u64,
    layout: Layout,
}

/// Reads the header and checks it against what the caller expects.
fn read_header(
    csv: &mut csv::Reader<&[u8]>,
    lines: &mut LineCounter<'_>,
    (file, body, delimiter): (&str, &[u8], Delimiter),
    options: &ReadOptions,
    positions_required: bool,
) -> Result<Header, Error> {
    let record = csv.headers().map_err(|e| syntax_error(&e, file, delimiter, body))?.clone();
    if record.is_empty() || (record.len() == 1 && record[0].is_empty()) {
        return Err(Error::at_line(file.to_owned(), 1, 1, ErrorKind::EmptyFile));
    }
    let line = record.position().map_or(1, |p| lines.record_line(p.byte()));
    let expect = Expectation {
        file,
        line,
        joints: options.joints.as_deref(),
        positions: positions_required,
        columns: &options.columns,
        inputs: &options.inputs,
    };
    let layout = Layout::from_header(&record, &expect)?;
    Ok(Header { record, line, layout })
}

/// The tools rows name, each once, in the order they first appear.
#[derive(Default)]
struct Tools {
    names: Vec<String>,
    /// Each tool's index by name: a file whose every row names another tool stays linear.
    index: HashMap<String, usize>,
}

impl Tools {
    /// The index of the tool named `name`, added when new.
    fn index_of(&mut self, name: &str) -> usize {
        *self.index.entry(name.to_owned()).or_insert_with(|| {
            self.names.push(name.to_owned());
            self.names.len() - 1
        })
    }
}

/// One row's measurement, its cells read in the order of the fields (joints first), so that the
/// first bad cell in that order is the one refused.
fn read_measurement(
    row: &mut Row<'_>,
    layout: &Layout,
    input_names: &std::sync::Arc<[String]>,
    tools: &mut Tools,
) -> Result<Measurement, Error> {
    let q = layout
        .joints
        .iter()
        .map(|&(c, kind)| {
            let range = match kind {
                JointKind::Revolute => JOINT_ANGLE_RANGE,
                JointKind::Prismatic => JOINT_TRAVEL_RANGE,
            };
            row.bounded_numbers(&[c], range).map(|v| v[0])
        })
        .collect::<Result<Vec<f64>, Error>>()?;
    let position = match layout.position {
        Some(c) => {
            let p = row.bounded_numbers(&c, POSITION_RANGE)?;
            Vector3::new(p[0], p[1], p[2])
        }
        None => Vector3::zeros(),
    };
    let orientation = layout.orientation.as_ref().map(|c| row.orientation(c)).transpose()?;
    let payload_kg = payload_kg(row, layout.payload)?;
    let temp_c = layout.temp.map(|c| row.number(c)).transpose()?;
    let t_s = layout.time.map(|c| row.number(c)).transpose()?;
    let torques_nm = if layout.torques.is_empty() { None } else { Some(row.numbers(&layout.torques)?) };
    let inputs = Inputs::new(input_names.clone(), row.numbers(&layout.inputs)?);
    let std = match (layout.position_std, layout.rotation_std) {
        (None, None) => None,
        (p, r) => Some(StatedSigma {
            position_m: p.map(|c| row.standard_deviations(&c)).transpose()?,
            rotation_rad: r.map(|c| row.standard_deviations(&c)).transpose()?,
        }),
    };
    let tool = tools.index_of(layout.tool.and_then(|i| row.record.get(i)).unwrap_or(""));
    Ok(Measurement { line: row.line, q, position, orientation, payload_kg, tool, temp_c, t_s, torques_nm, inputs, std })
}

/// The row's payload, kg: 0 without a payload column, never negative.
fn payload_kg(row: &mut Row<'_>, column: Option<layout::Column>) -> Result<f64, Error> {
    match column {
        Some(c) => {
            let value = row.number(c)?;
            if value < 0.0 {
                return Err(Error::at_line(
                    row.file.to_owned(),
                    row.line,
                    c.index + 1,
                    ErrorKind::NegativePayload { value },
                ));
            }
            Ok(value)
        }
        None => Ok(0.0),
    }
}

/// The set the rows make, with what the header says of the file's format.
fn measurement_set(
    file: &str,
    header: Header,
    options: &ReadOptions,
    dialect: Dialect,
    tools: Vec<String>,
    rows: Vec<Measurement>,
) -> MeasurementSet {
    let Header { record: header, line: header_line, layout } = header;
    MeasurementSet {
        header_line,
        source: file.to_owned(),
        joint_count: layout.joints.len(),
        full_pose: layout.orientation.is_some(),
        tools,
        tool_column: layout.tool.map(|i| i + 1),
        rows,
        ignored_columns: layout.ignored,
        positions_measured: layout.position.is_some(),
        joint_columns: layout
            .joints
            .iter()
            .map(|(c, kind)| JointColumn { column: c.index + 1, kind: *kind, unit: joint_unit(*kind, c.scale) })
            .collect(),
        position_unit: layout.position.map(|[x, _, _]| if x.scale == 1.0 { "m" } else { "mm" }),
        inputs: options
            .inputs
            .iter()
            .zip(&layout.inputs)
            .map(|(name, c)| InputColumn { name: name.clone(), unit: input_unit(name), column: c.index + 1 })
            .collect(),
        format: FileFormat {
            dialect,
            euler_angles: matches!(layout.orientation, Some(OrientationColumns::Euler(_))),
            mapped_columns: options
                .columns
                .entries()
                .iter()
                .filter(|(_, h)| header.iter().any(|c| c.trim() == h))
                .cloned()
                .collect(),
        },
    }
}

/// The unit a joint column's name gives, from the factor that turns it into SI.
fn joint_unit(kind: JointKind, scale: f64) -> &'static str {
    match (kind, scale == 1.0) {
        (JointKind::Revolute, true) => "rad",
        (JointKind::Revolute, false) => "deg",
        (JointKind::Prismatic, true) => "m",
        (JointKind::Prismatic, false) => "mm",
    }
}

impl MeasurementSet {
    /// A set made in memory (simulation, splits); `source` names it in messages.
    pub fn from_rows(source: &str, rows: Vec<Measurement>, tools: Vec<String>) -> Self {
        let joint_count = rows.first().map_or(0, |r| r.q.len());
        let full_pose = !rows.is_empty() && rows.iter().all(|r| r.orientation.is_some());
        let tools = if tools.is_empty() { vec![String::new()] } else { tools };
        Self {
            source: source.to_owned(),
            joint_count,
            full_pose,
            tools,
            tool_column: None,
            rows,
            ignored_columns: vec![],
            positions_measured: true,
            joint_columns: vec![],
            position_unit: None,
            format: FileFormat::default(),
            inputs: Vec::new(),
            header_line: 1,
        }
    }

    /// One line saying what the reader found: rows, separators, orientation, mapped and ignored
    /// columns (the CLI prints it).
    pub fn read_summary(&self) -> String {
        let mut line = format!("read {}: {} rows, {}", self.source, self.rows.len(), self.format);
        if !self.inputs.is_empty() {
            let inputs: Vec<String> = self
                .inputs
                .iter()
                .map(|c| c.unit.map_or_else(|| c.name.clone(), |unit| format!("{} ({unit})", c.name)))
                .collect();
            line.push_str(&format!("; inputs: {}", inputs.join(", ")));
        }
        if self.rows.iter().any(|r| r.std.is_some()) {
            line.push_str("; the tracker's stated uncertainty of each row (std_…)");
        }
        if !self.ignored_columns.is_empty() {
            line.push_str(&format!("; ignored columns: {}", self.ignored_columns.join(", ")));
        }
        line
    }

    /// Refuses a set whose joint columns do not match a robot's `joints`.
    pub fn check_joint_count(&self, joints: usize) -> Result<(), Error> {
        if self.joint_count == joints {
            return Ok(());
        }
        Err(Error::at_line(
            self.source.clone(),
            self.header_line,
            1,
            ErrorKind::JointCountMismatch { found: self.joint_count, expected: joints },
        ))
    }

    /// Refuses a set whose joint columns do not match a robot's joints: their count, and each
    /// column's unit against its joint's kind (for sets read from a file).
    pub fn check_joints(&self, kinds: &[JointKind]) -> Result<(), Error> {
        self.check_joint_count(kinds.len())?;
        for (k, (column, kind)) in self.joint_columns.iter().zip(kinds).enumerate() {
            if column.kind != *kind {
                return Err(Error::at_line(
                    self.source.clone(),
                    self.header_line,
                    column.column,
                    ErrorKind::JointUnit { joint: k + 1, kind: *kind },
                ));
            }
        }
        Ok(())
    }

    /// Refuses the first row without a value of one of the inputs `names` (a set read from a file
    /// with them has them all: the reader refused a file without the column): at its line, and
    /// the input's column where the set has one.
    pub fn require_inputs(&self, names: &[String]) -> Result<(), Error> {
        if names.is_empty() {
            return Ok(());
        }
        let mut known: Option<&std::sync::Arc<[String]>> = None;
        for row in &self.rows {
            // The rows of a file share one list of names: checked once per list.
            if known.is_some_and(|k| std::sync::Arc::ptr_eq(k, row.inputs.shared_names())) {
                continue;
            }
            let have: std::collections::HashSet<&str> = row.inputs.names().iter().map(String::as_str).collect();
            if let Some(name) = names.iter().find(|n| !have.contains(n.as_str())) {
                let column = self.inputs.iter().find(|c| &c.name == name).map_or(1, |c| c.column);
                return Err(Error::at_line(
                    self.source.clone(),
                    row.line,
                    column,
                    ErrorKind::MissingInput { name: name.clone() },
                ));
            }
            known = Some(row.inputs.shared_names());
        }
        Ok(())
    }

    /// The rows at `indices`, as a set of their own (same tools).
    pub fn subset(&self, indices: &[usize]) -> Self {
        Self { rows: indices.iter().map(|&i| self.rows[i].clone()).collect(), ..self.clone_empty() }
    }

    fn clone_empty(&self) -> Self {
        Self {
            source: self.source.clone(),
            joint_count: self.joint_count,
            full_pose: self.full_pose,
            tools: self.tools.clone(),
            tool_column: self.tool_column,
            rows: Vec::new(),
            ignored_columns: self.ignored_columns.clone(),
            positions_measured: self.positions_measured,
            joint_columns: self.joint_columns.clone(),
            position_unit: self.position_unit,
            format: self.format.clone(),
            inputs: self.inputs.clone(),
            header_line: self.header_line,
        }
    }
}
