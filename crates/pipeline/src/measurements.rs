//! The measurement CSV of the SPEC: one row per measured pose, columns found by name, the unit in
//! the name. Every refusal names the file, the line and the column.

use crate::Error;
use lie::{SO3, Vector3};
use std::io::{Read, Write};
use std::path::Path;

/// One measured pose, SI units.
#[derive(Debug, Clone, PartialEq)]
pub struct Measurement {
    /// 1-based line of the row in its file (0 for rows made in memory).
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
    /// Tool identifiers in order of first appearance (`""` when there is no `tool` column).
    pub tools: Vec<String>,
    /// 1-based column of `tool` in the file, if it has one.
    pub tool_column: Option<usize>,
    /// The rows, in file order.
    pub rows: Vec<Measurement>,
    /// Columns found but not used, by name.
    pub ignored_columns: Vec<String>,
    /// Whether the rows carry measured positions ([`read_configurations`] may read sets without).
    pub positions_measured: bool,
}

/// How a cell's number is turned into SI.
#[derive(Debug, Clone, Copy)]
struct Column {
    index: usize,
    scale: f64,
}

/// Where each quantity is in the header.
#[derive(Debug, Default)]
struct Layout {
    joints: Vec<Option<Column>>,
    position: [Option<Column>; 3],
    quaternion: [Option<Column>; 4],
    payload: Option<Column>,
    tool: Option<usize>,
    temp: Option<Column>,
    time: Option<Column>,
    torques: Vec<Option<Column>>,
    ignored: Vec<String>,
}

fn set_indexed(slots: &mut Vec<Option<Column>>, k: usize, column: Column) -> bool {
    if slots.len() < k {
        slots.resize(k, None);
    }
    let fresh = slots[k - 1].is_none();
    slots[k - 1] = Some(column);
    fresh
}

/// `q3_rad` → Some((3, "rad")) for the prefix "q".
fn indexed_name<'a>(name: &'a str, prefix: &str) -> Option<(usize, &'a str)> {
    let rest = name.strip_prefix(prefix)?;
    let (digits, unit) = rest.split_once('_')?;
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) || digits.starts_with('0') {
        return None;
    }
    Some((digits.parse().ok()?, unit))
}

impl Layout {
    fn from_header(header: &csv::StringRecord, file: &str) -> Result<Self, Error> {
        let mut layout = Layout::default();
        let mut names: Vec<&str> = Vec::new();
        for (index, raw) in header.iter().enumerate() {
            let name = raw.trim();
            let duplicate = |name: &str| Error::DuplicateColumn {
                file: file.to_owned(),
                line: 1,
                column: index + 1,
                name: name.to_owned(),
            };
            if names.contains(&name) {
                return Err(duplicate(name));
            }
            names.push(name);
            let col = |scale| Column { index, scale };
            let fresh = match name {
                "x_mm" | "x_m" | "y_mm" | "y_m" | "z_mm" | "z_m" => {
                    let axis = (name.as_bytes()[0] - b'x') as usize;
                    let scale = if name.ends_with("_mm") { 1e-3 } else { 1.0 };
                    layout.position[axis].replace(col(scale)).is_none()
                }
                "qw" | "qx" | "qy" | "qz" => {
                    let k = ["qw", "qx", "qy", "qz"].iter().position(|n| *n == name).unwrap_or(0);
                    layout.quaternion[k].replace(col(1.0)).is_none()
                }
                "payload_kg" => layout.payload.replace(col(1.0)).is_none(),
                "tool" => layout.tool.replace(index).is_none(),
                "temp_c" => layout.temp.replace(col(1.0)).is_none(),
                "t_s" => layout.time.replace(col(1.0)).is_none(),
                _ => match (indexed_name(name, "q"), indexed_name(name, "tau")) {
                    (Some((k, "rad")), _) => set_indexed(&mut layout.joints, k, col(1.0)),
                    (Some((k, "deg")), _) => set_indexed(&mut layout.joints, k, col(1f64.to_radians())),
                    (_, Some((k, "nm"))) => set_indexed(&mut layout.torques, k, col(1.0)),
                    _ => {
                        layout.ignored.push(name.to_owned());
                        true
                    }
                },
            };
            if !fresh {
                return Err(duplicate(name));
            }
        }
        Ok(layout)
    }

    fn check(
        &self,
        header_len: usize,
        file: &str,
        expected_joints: Option<usize>,
        positions: bool,
    ) -> Result<(), Error> {
        let missing =
            |name: String| Error::MissingColumn { file: file.to_owned(), line: 1, column: header_len + 1, name };
        let found = self.joints.len();
        if let Some(expected) = expected_joints {
            if found != expected {
                let column = if found > expected {
                    self.joints[expected].map_or(header_len + 1, |c| c.index + 1)
                } else {
                    header_len + 1
                };
                return Err(Error::JointCountMismatch { file: file.to_owned(), line: 1, column, found, expected });
            }
        }
        if found == 0 {
            return Err(missing("q1_rad".into()));
        }
        if let Some(k) = self.joints.iter().position(Option::is_none) {
            return Err(missing(format!("q{}_rad", k + 1)));
        }
        let any_position = self.position.iter().any(Option::is_some);
        for (axis, slot) in ["x_mm", "y_mm", "z_mm"].iter().zip(&self.position) {
            if slot.is_none() && (positions || any_position) {
                return Err(missing((*axis).into()));
            }
        }
        let present = self.quaternion.iter().filter(|c| c.is_some()).count();
        if present > 0 && present < 4 {
            let k = self.quaternion.iter().position(Option::is_none).unwrap_or(0);
            return Err(missing(["qw", "qx", "qy", "qz"][k].into()));
        }
        if let Some(k) = self.torques.iter().position(Option::is_none) {
            return Err(missing(format!("tau{}_nm", k + 1)));
        }
        Ok(())
    }
}

/// Reads a measurement file. `expected_joints`, when given, is the robot's joint count.
pub fn read_measurements(path: &Path, expected_joints: Option<usize>) -> Result<MeasurementSet, Error> {
    let file = path.display().to_string();
    let reader = std::fs::File::open(path).map_err(|source| Error::Io { path: file.clone(), source })?;
    parse_measurements(reader, &file, expected_joints)
}

/// Parses measurements from any reader; `file` names the source in errors.
pub fn parse_measurements<R: Read>(
    reader: R,
    file: &str,
    expected_joints: Option<usize>,
) -> Result<MeasurementSet, Error> {
    parse(reader, file, expected_joints, true)
}

/// Reads joint configurations to predict poses for: the measurement CSV in which the position
/// columns may be left out (then [`MeasurementSet::positions_measured`] is false and every
/// position is zero). Every other rule of the format holds.
pub fn read_configurations(path: &Path, expected_joints: Option<usize>) -> Result<MeasurementSet, Error> {
    let file = path.display().to_string();
    let reader = std::fs::File::open(path).map_err(|source| Error::Io { path: file.clone(), source })?;
    parse(reader, &file, expected_joints, false)
}

fn parse<R: Read>(
    reader: R,
    file: &str,
    expected_joints: Option<usize>,
    positions_required: bool,
) -> Result<MeasurementSet, Error> {
    let mut csv = csv::ReaderBuilder::new().has_headers(true).trim(csv::Trim::All).from_reader(reader);
    let syntax = |e: csv::Error| {
        let line = e.position().map_or(1, |p| p.line());
        let message = match e.kind() {
            csv::ErrorKind::UnequalLengths { expected_len, len, .. } => {
                format!("row has {len} fields, the header has {expected_len}")
            }
            _ => e.to_string(),
        };
        Error::CsvSyntax { file: file.to_owned(), line, column: 1, message }
    };
    let header = csv.headers().map_err(syntax)?.clone();
    if header.is_empty() || (header.len() == 1 && header[0].is_empty()) {
        return Err(Error::EmptyFile { file: file.to_owned() });
    }
    let layout = Layout::from_header(&header, file)?;
    layout.check(header.len(), file, expected_joints, positions_required)?;
    let positions_measured = layout.position.iter().all(Option::is_some);
    let full_pose = layout.quaternion[0].is_some();
    let mut tools: Vec<String> = Vec::new();
    let mut rows = Vec::new();
    for record in csv.records() {
        let record = record.map_err(syntax)?;
        let line = record.position().map_or(0, |p| p.line());
        let number = |column: Column| -> Result<f64, Error> {
            let text = record.get(column.index).unwrap_or("");
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v * column.scale),
                _ => Err(Error::NotANumber {
                    file: file.to_owned(),
                    line,
                    column: column.index + 1,
                    name: header[column.index].trim().to_owned(),
                    text: text.to_owned(),
                }),
            }
        };
        let all = |slots: &[Option<Column>]| -> Result<Vec<f64>, Error> {
            slots.iter().flatten().map(|&c| number(c)).collect()
        };
        let q = all(&layout.joints)?;
        let p = if positions_measured { all(&layout.position)? } else { vec![0.0; 3] };
        let orientation = if full_pose {
            let quaternion = all(&layout.quaternion)?;
            let norm = quaternion.iter().map(|v| v * v).sum::<f64>().sqrt();
            let refused = || Error::QuaternionNorm {
                file: file.to_owned(),
                line,
                column: layout.quaternion[0].map_or(1, |c| c.index + 1),
                norm,
            };
            Some(
                SO3::from_quaternion(quaternion[0], quaternion[1], quaternion[2], quaternion[3])
                    .map_err(|_| refused())?,
            )
        } else {
            None
        };
        let tool_name = layout.tool.map_or("", |i| record.get(i).unwrap_or(""));
        let tool = match tools.iter().position(|t| t == tool_name) {
            Some(t) => t,
            None => {
                tools.push(tool_name.to_owned());
                tools.len() - 1
            }
        };
        let optional = |c: Option<Column>| c.map(number).transpose();
        rows.push(Measurement {
            line,
            q,
            position: Vector3::new(p[0], p[1], p[2]),
            orientation,
            payload_kg: optional(layout.payload)?.unwrap_or(0.0),
            tool,
            temp_c: optional(layout.temp)?,
            t_s: optional(layout.time)?,
            torques_nm: if layout.torques.is_empty() { None } else { Some(all(&layout.torques)?) },
        });
    }
    if rows.is_empty() {
        return Err(Error::EmptyFile { file: file.to_owned() });
    }
    Ok(MeasurementSet {
        source: file.to_owned(),
        joint_count: layout.joints.len(),
        full_pose,
        tools,
        tool_column: layout.tool.map(|i| i + 1),
        rows,
        ignored_columns: layout.ignored,
        positions_measured,
    })
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
        }
    }

    /// Refuses a set whose joint columns do not match a robot's `joints`.
    pub fn check_joint_count(&self, joints: usize) -> Result<(), Error> {
        if self.joint_count == joints {
            return Ok(());
        }
        Err(Error::JointCountMismatch {
            file: self.source.clone(),
            line: 1,
            column: 1,
            found: self.joint_count,
            expected: joints,
        })
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
        }
    }

    /// Writes the set as SPEC CSV (joints in radians, positions in millimetres, full precision).
    pub fn write_csv<W: Write>(&self, writer: W) -> Result<(), std::io::Error> {
        let mut out = csv::Writer::from_writer(writer);
        let has = |f: &dyn Fn(&Measurement) -> bool| self.rows.iter().any(f);
        let (temp, time) = (has(&|r| r.temp_c.is_some()), has(&|r| r.t_s.is_some()));
        let torques = self.rows.first().and_then(|r| r.torques_nm.as_ref()).map_or(0, Vec::len);
        let named_tools = self.tools.iter().any(|t| !t.is_empty());
        let mut header: Vec<String> = (1..=self.joint_count).map(|k| format!("q{k}_rad")).collect();
        header.extend(["x_mm", "y_mm", "z_mm"].map(String::from));
        if self.full_pose {
            header.extend(["qw", "qx", "qy", "qz"].map(String::from));
        }
        header.push("payload_kg".into());
        if named_tools {
            header.push("tool".into());
        }
        if temp {
            header.push("temp_c".into());
        }
        if time {
            header.push("t_s".into());
        }
        header.extend((1..=torques).map(|k| format!("tau{k}_nm")));
        out.write_record(&header)?;
        for row in &self.rows {
            let mut record: Vec<String> = row.q.iter().map(|v| format!("{v:?}")).collect();
            record.extend(row.position.iter().map(|v| format!("{:?}", v * 1e3)));
            if self.full_pose {
                let q = row.orientation.map_or([1.0, 0.0, 0.0, 0.0], |r| r.to_quaternion());
                record.extend(q.iter().map(|v| format!("{v:?}")));
            }
            record.push(format!("{:?}", row.payload_kg));
            if named_tools {
                record.push(self.tools[row.tool].clone());
            }
            if temp {
                record.push(row.temp_c.map_or(String::new(), |v| format!("{v:?}")));
            }
            if time {
                record.push(row.t_s.map_or(String::new(), |v| format!("{v:?}")));
            }
            if let Some(tau) = &row.torques_nm {
                record.extend(tau.iter().map(|v| format!("{v:?}")));
            }
            out.write_record(&record)?;
        }
        out.flush()
    }
}
