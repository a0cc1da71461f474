//! The header of a measurement file: which column holds which quantity, in which unit, checked
//! against the robot's joints before a single row is read.

use super::ColumnMap;
use super::quantity::{Quantity, quantity};
use crate::ErrorKind;
use errors::Error;
use poe::JointKind;
use std::collections::HashSet;

/// How a cell's number is turned into SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Column {
    /// 0-based field index.
    pub index: usize,
    pub scale: f64,
}

/// The orientation columns of full-pose data.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum OrientationColumns {
    Quaternion([Column; 4]),
    /// `R = Rx(rx) · Ry(ry) · Rz(rz)`.
    Euler([Column; 3]),
}

/// Where each quantity is in the header, checked.
#[derive(Debug)]
pub(crate) struct Layout {
    /// Joint `k` is `joints[k - 1]`, with the kind its unit says.
    pub joints: Vec<(Column, JointKind)>,
    /// `None` when the file has no position columns (joint files for `calib predict`).
    pub position: Option<[Column; 3]>,
    pub orientation: Option<OrientationColumns>,
    pub payload: Option<Column>,
    pub tool: Option<usize>,
    pub temp: Option<Column>,
    pub time: Option<Column>,
    pub torques: Vec<Column>,
    /// The columns of [`Expectation::inputs`], in its order.
    pub inputs: Vec<Column>,
    /// The stated standard deviations of the position, `std_x_mm` …: all three or none.
    pub position_std: Option<[Column; 3]>,
    /// The stated standard deviations of the orientation, `std_rx_mrad` …: all three or none.
    pub rotation_std: Option<[Column; 3]>,
    /// The names of the columns not used.
    pub ignored: Vec<String>,
    /// Names as the rest of the reader refers to them: the SPEC name of a mapped column.
    pub names: Vec<String>,
}

/// What the header is checked against.
pub(crate) struct Expectation<'a> {
    pub file: &'a str,
    /// The header's line (1 unless blank lines precede it): where its refusals are placed.
    pub line: u64,
    /// The robot's joints, when known.
    pub joints: Option<&'a [JointKind]>,
    /// Whether the position columns must be there.
    pub positions: bool,
    pub columns: &'a ColumnMap,
    /// The columns to keep as inputs of a model (`--inputs`), by name.
    pub inputs: &'a [String],
}

/// The SPEC name of joint `k`'s column for a joint of `kind`.
fn joint_name(k: usize, kind: JointKind) -> String {
    match kind {
        JointKind::Revolute => format!("q{k}_rad"),
        JointKind::Prismatic => format!("q{k}_m"),
    }
}

impl Layout {
    /// Reads and checks the header. Allocates only in proportion to the header's length: a column
    /// named `q99999999999_rad` is refused, never used as a size.
    pub fn from_header(header: &csv::StringRecord, expect: &Expectation<'_>) -> Result<Self, Error> {
        let width = header.len();
        let Found {
            names,
            joints,
            torques,
            position,
            quaternion,
            euler,
            payload,
            tool,
            temp,
            time,
            position_std,
            rotation_std,
            mut ignored,
        } = Found::classify(header, expect)?;
        check_mapped_headers(header, expect, width)?;

        let inputs = input_columns(&names, expect, width)?;
        if !inputs.is_empty() {
            let taken: HashSet<&str> = expect.inputs.iter().map(String::as_str).collect();
            ignored.retain(|name| !taken.contains(name.as_str()));
        }
        let joints = check_joints(joints, expect, width)?;
        let torques = check_torques(torques, joints.len(), &names, expect, width)?;

        let position = position_columns(position, expect, width)?;
        let orientation = orientation(quaternion, euler, &names, (expect.file, expect.line), width)?;
        let position_std = all_or_none(position_std, ["std_x_mm", "std_y_mm", "std_z_mm"], expect, width)?;
        let rotation_std = all_or_none(rotation_std, ["std_rx_mrad", "std_ry_mrad", "std_rz_mrad"], expect, width)?;
        Ok(Self {
            joints,
            position,
            orientation,
            payload,
            tool,
            temp,
            time,
            torques,
            inputs,
            position_std,
            rotation_std,
            ignored,
            names,
        })
    }
}

/// The header's columns by quantity, each name seen once, before they are checked against each
/// other and against the robot.
#[derive(Default)]
struct Found {
    names: Vec<String>,
    /// `(k, column, kind)` of each joint column, in header order.
    joints: Vec<(usize, Column, JointKind)>,
    /// `(k, column)` of each torque column, in header order.
    torques: Vec<(usize, Column)>,
    position: [Option<Column>; 3],
    quaternion: [Option<Column>; 4],
    euler: [Option<Column>; 3],
    payload: Option<Column>,
    tool: Option<usize>,
    temp: Option<Column>,
    time: Option<Column>,
    position_std: [Option<Column>; 3],
    rotation_std: [Option<Column>; 3],
    ignored: Vec<String>,
}

impl Found {
    /// Each header cell's quantity, by its name after `expect.columns` maps it; a name (or a
    /// quantity) seen twice is refused at its second column.
    fn classify(header: &csv::StringRecord, expect: &Expectation<'_>) -> Result<Self, Error> {
        let (file, line) = (expect.file, expect.line);
        let width = header.len();
        let mut found = Self { names: Vec::with_capacity(width), ..Self::default() };
        // Sets, not scans of the lists: a header of 400,000 columns took minutes when each name was
        // compared with every earlier one (found by `cargo xtask fuzz`).
        let mut seen: HashSet<String> = HashSet::with_capacity(width);
        let (mut joint_numbers, mut torque_numbers) = (HashSet::new(), HashSet::new());
        for (index, raw) in header.iter().enumerate() {
            let raw = raw.trim();
            let name = expect.columns.target_of(raw).unwrap_or(raw).to_owned();
            let duplicate =
                || Error::at_line(file.to_owned(), line, index + 1, ErrorKind::DuplicateColumn { name: name.clone() });
            if !seen.insert(name.clone()) {
                return Err(duplicate());
            }
            let column = |scale| Column { index, scale };
            let fresh = match quantity(&name) {
                Some(Quantity::Joint { index: k, kind, scale }) => {
                    found.joints.push((k, column(scale), kind));
                    joint_numbers.insert(k)
                }
                Some(Quantity::Torque(k)) => {
                    found.torques.push((k, column(1.0)));
                    torque_numbers.insert(k)
                }
                Some(Quantity::Position { axis, scale }) => found.position[axis].replace(column(scale)).is_none(),
                Some(Quantity::Quaternion(k)) => found.quaternion[k].replace(column(1.0)).is_none(),
                Some(Quantity::Euler { axis, scale }) => found.euler[axis].replace(column(scale)).is_none(),
                Some(Quantity::Payload) => found.payload.replace(column(1.0)).is_none(),
                Some(Quantity::Tool) => found.tool.replace(index).is_none(),
                Some(Quantity::Temperature) => found.temp.replace(column(1.0)).is_none(),
                Some(Quantity::Time) => found.time.replace(column(1.0)).is_none(),
                Some(Quantity::PositionStd { axis, scale }) => {
                    found.position_std[axis].replace(column(scale)).is_none()
                }
                Some(Quantity::RotationStd { axis, scale }) => {
                    found.rotation_std[axis].replace(column(scale)).is_none()
                }
                None => {
                    found.ignored.push(name.clone());
                    true
                }
            };
            if !fresh {
                return Err(duplicate());
            }
            found.names.push(name);
        }
        Ok(found)
    }
}

/// A column the header lacks, placed one past its last column.
fn missing_at_end(expect: &Expectation<'_>, width: usize, name: String) -> Error {
    Error::at_line(expect.file.to_owned(), expect.line, width + 1, ErrorKind::MissingColumn { name })
}

/// Every header `expect.columns` maps from must be in the file: a map that names nothing is a typo.
fn check_mapped_headers(header: &csv::StringRecord, expect: &Expectation<'_>, width: usize) -> Result<(), Error> {
    for (target, mapped) in expect.columns.entries() {
        if !header.iter().any(|h| h.trim() == mapped) {
            return Err(Error::at_line(
                expect.file.to_owned(),
                expect.line,
                width + 1,
                ErrorKind::MappedHeaderMissing { target: target.clone(), header: mapped.clone() },
            ));
        }
    }
    Ok(())
}

/// The torque columns in joint order, checked: none beyond the `n` joints, and, when there are
/// any, one for every joint.
fn check_torques(
    mut torques: Vec<(usize, Column)>,
    n: usize,
    names: &[String],
    expect: &Expectation<'_>,
    width: usize,
) -> Result<Vec<Column>, Error> {
    torques.sort_by_key(|(k, _)| *k);
    if let Some((k, c)) = torques.iter().find(|(k, _)| *k > n) {
        return Err(Error::at_line(
            expect.file.to_owned(),
            expect.line,
            c.index + 1,
            ErrorKind::ColumnBeyondJoints { name: names[c.index].clone(), index: *k, joints: n },
        ));
    }
    if !torques.is_empty()
        && let Some(k) = (1..=n).find(|k| torques.get(k - 1).is_none_or(|(j, _)| j != k))
    {
        return Err(missing_at_end(expect, width, format!("tau{k}_nm")));
    }
    Ok(torques.into_iter().map(|(_, c)| c).collect())
}

/// The three position columns, or none when the file may leave them out and has none of them.
fn position_columns(
    position: [Option<Column>; 3],
    expect: &Expectation<'_>,
    width: usize,
) -> Result<Option<[Column; 3]>, Error> {
    let any_position = position.iter().any(Option::is_some);
    match position {
        [Some(x), Some(y), Some(z)] => Ok(Some([x, y, z])),
        _ if expect.positions || any_position => {
            let k = position.iter().position(Option::is_none).unwrap_or(0);
            Err(missing_at_end(expect, width, ["x_mm", "y_mm", "z_mm"][k].into()))
        }
        _ => Ok(None),
    }
}

/// A stated uncertainty's three columns, or none. Some axes only are refused by the first name
/// missing: a row weighted on one axis and not on another would be weighted by accident.
fn all_or_none(
    columns: [Option<Column>; 3],
    names: [&str; 3],
    expect: &Expectation<'_>,
    width: usize,
) -> Result<Option<[Column; 3]>, Error> {
    match columns {
        [Some(x), Some(y), Some(z)] => Ok(Some([x, y, z])),
        [None, None, None] => Ok(None),
        _ => Err(missing_at_end(expect, width, names[columns.iter().position(Option::is_none).unwrap_or(0)].into())),
    }
}

/// The columns of the inputs `expect.inputs` names, in its order: each must be in the header, and
/// be a number that is not already an input or an output of the model. Names are looked up in a
/// map of the header, not by scanning it.
fn input_columns(names: &[String], expect: &Expectation<'_>, width: usize) -> Result<Vec<Column>, Error> {
    if expect.inputs.is_empty() {
        return Ok(Vec::new());
    }
    let file = expect.file;
    let index: std::collections::HashMap<&str, usize> =
        names.iter().enumerate().map(|(i, name)| (name.as_str(), i)).collect();
    let mut seen = HashSet::with_capacity(expect.inputs.len());
    expect
        .inputs
        .iter()
        .map(|name| {
            if !seen.insert(name.as_str()) {
                return Err(Error::at_line("--inputs", 1, 1, ErrorKind::InputList { name: name.clone() }));
            }
            let Some(&i) = index.get(name.as_str()) else {
                return Err(Error::at_line(
                    file.to_owned(),
                    1,
                    width + 1,
                    ErrorKind::MissingColumn { name: name.clone() },
                ));
            };
            let refused = match quantity(name) {
                Some(Quantity::Joint { .. }) => Some("a joint, already an input"),
                Some(Quantity::Position { .. } | Quantity::Quaternion(_) | Quantity::Euler { .. }) => {
                    Some("the measured pose, what the model predicts")
                }
                Some(Quantity::Tool) => Some("the tool, not a number"),
                Some(Quantity::Payload) => Some("the payload, an input of method poe-gp-load"),
                Some(Quantity::PositionStd { .. } | Quantity::RotationStd { .. }) => {
                    Some("the tracker's stated uncertainty, which weights its row")
                }
                _ => None,
            };
            match refused {
                Some(quantity) => Err(Error::at_line(
                    file.to_owned(),
                    1,
                    i + 1,
                    ErrorKind::NotAnInput { name: name.clone(), quantity },
                )),
                None => Ok(Column { index: i, scale: 1.0 }),
            }
        })
        .collect()
}

/// The joint columns in order, checked: numbered 1…n without gaps, n the robot's joint count
/// when known, each unit one that fits its joint's kind.
fn check_joints(
    mut found: Vec<(usize, Column, JointKind)>,
    expect: &Expectation<'_>,
    width: usize,
) -> Result<Vec<(Column, JointKind)>, Error> {
    let (file, line) = (expect.file, expect.line);
    found.sort_by_key(|(k, _, _)| *k);
    let count = found.len();
    if let Some(kinds) = expect.joints {
        let expected = kinds.len();
        let beyond = found.iter().find(|(k, _, _)| *k > expected);
        if count != expected || beyond.is_some() {
            let column = beyond.map_or(width + 1, |(_, c, _)| c.index + 1);
            return Err(Error::at_line(
                file.to_owned(),
                line,
                column,
                ErrorKind::JointCountMismatch { found: count, expected },
            ));
        }
    }
    let kind_of = |k: usize| expect.joints.and_then(|kinds| kinds.get(k - 1)).copied().unwrap_or(JointKind::Revolute);
    if count == 0 {
        return Err(Error::at_line(
            file.to_owned(),
            line,
            width + 1,
            ErrorKind::MissingColumn { name: joint_name(1, kind_of(1)) },
        ));
    }
    if let Some(k) = (1..=count).find(|&k| found[k - 1].0 != k) {
        return Err(Error::at_line(
            file.to_owned(),
            line,
            width + 1,
            ErrorKind::MissingColumn { name: joint_name(k, kind_of(k)) },
        ));
    }
    if let Some(kinds) = expect.joints {
        for ((k, column, kind), robot) in found.iter().zip(kinds) {
            if kind != robot {
                return Err(Error::at_line(
                    file.to_owned(),
                    line,
                    column.index + 1,
                    ErrorKind::JointUnit { joint: *k, kind: *robot },
                ));
            }
        }
    }
    Ok(found.into_iter().map(|(_, c, kind)| (c, kind)).collect())
}

/// The orientation columns: a full quaternion or three Euler angles, never both.
fn orientation(
    quaternion: [Option<Column>; 4],
    euler: [Option<Column>; 3],
    names: &[String],
    (file, line): (&str, u64),
    width: usize,
) -> Result<Option<OrientationColumns>, Error> {
    let missing =
        |name: &str| Error::at_line(file.to_owned(), line, width + 1, ErrorKind::MissingColumn { name: name.into() });
    let any_quaternion = quaternion.iter().flatten().next();
    let any_euler = euler.iter().flatten().next();
    if let (Some(q), Some(e)) = (any_quaternion, any_euler) {
        let later = if e.index > q.index { e } else { q };
        let earlier = if e.index > q.index { q } else { e };
        return Err(Error::at_line(
            file.to_owned(),
            line,
            later.index + 1,
            ErrorKind::OrientationTwice { name: names[later.index].clone(), other: names[earlier.index].clone() },
        ));
    }
    match (quaternion, euler) {
        ([Some(w), Some(x), Some(y), Some(z)], _) => Ok(Some(OrientationColumns::Quaternion([w, x, y, z]))),
        (_, [Some(x), Some(y), Some(z)]) => Ok(Some(OrientationColumns::Euler([x, y, z]))),
        _ if any_quaternion.is_some() => {
            let k = quaternion.iter().position(Option::is_none).unwrap_or(0);
            Err(missing(["qw", "qx", "qy", "qz"][k]))
        }
        _ if any_euler.is_some() => {
            let k = euler.iter().position(Option::is_none).unwrap_or(0);
            Err(missing(["rx_deg", "ry_deg", "rz_deg"][k]))
        }
        _ => Ok(None),
    }
}
