//! The one writer of the measurement CSV: SPEC v1 (`,` and `.`), full precision, so that a written
//! set reads back bit for bit.

use super::{Measurement, MeasurementSet};
use poe::JointKind;
use std::io::Write;

/// The columns of a written measurement CSV, fixed by its header before the first row.
#[derive(Debug, Clone, PartialEq)]
pub struct CsvColumns {
    /// The kind of each joint (`q{k}_rad` or `q{k}_m`).
    pub joint_kinds: Vec<JointKind>,
    /// Whether `qw, qx, qy, qz` are written.
    pub full_pose: bool,
    /// Tool names by index; a `tool` column only where one is not empty.
    pub tools: Vec<String>,
    /// Whether `temp_c` is written.
    pub temp_c: bool,
    /// Whether `t_s` is written.
    pub t_s: bool,
    /// How many `tau{k}_nm` columns are written.
    pub torques: usize,
    /// The input columns written last, by name (each row's value of the name; blank where a row
    /// has none).
    pub inputs: Vec<String>,
    /// Whether the stated standard deviations `std_x_mm, std_y_mm, std_z_mm` are written (blank
    /// where a row has none), and `std_rx_mrad, std_ry_mrad, std_rz_mrad`.
    pub stated_std: [bool; 2],
}

/// The measurement CSV written one row at a time (`calib simulate` streams its rows through it).
#[derive(Debug)]
pub struct MeasurementWriter<W: Write> {
    out: csv::Writer<W>,
    columns: CsvColumns,
    named_tools: bool,
}

impl<W: Write> MeasurementWriter<W> {
    /// Writes the header of `columns`.
    pub fn new(writer: W, columns: CsvColumns) -> Result<Self, std::io::Error> {
        let mut out = csv::Writer::from_writer(writer);
        let named_tools = columns.tools.iter().any(|t| !t.is_empty());
        let mut header: Vec<String> = columns
            .joint_kinds
            .iter()
            .enumerate()
            .map(|(j, kind)| match kind {
                JointKind::Prismatic => format!("q{}_m", j + 1),
                JointKind::Revolute => format!("q{}_rad", j + 1),
            })
            .collect();
        header.extend(["x_mm", "y_mm", "z_mm"].map(String::from));
        if columns.full_pose {
            header.extend(["qw", "qx", "qy", "qz"].map(String::from));
        }
        header.push("payload_kg".into());
        if named_tools {
            header.push("tool".into());
        }
        if columns.temp_c {
            header.push("temp_c".into());
        }
        if columns.t_s {
            header.push("t_s".into());
        }
        header.extend((1..=columns.torques).map(|k| format!("tau{k}_nm")));
        header.extend(columns.inputs.iter().cloned());
        if columns.stated_std[0] {
            header.extend(["std_x_mm", "std_y_mm", "std_z_mm"].map(String::from));
        }
        if columns.stated_std[1] {
            header.extend(["std_rx_mrad", "std_ry_mrad", "std_rz_mrad"].map(String::from));
        }
        out.write_record(&header)?;
        Ok(Self { out, columns, named_tools })
    }

    /// Writes one row in full precision (`{:?}`, so that it reads back bit for bit).
    pub fn write_row(&mut self, row: &Measurement) -> Result<(), std::io::Error> {
        let columns = &self.columns;
        let mut record: Vec<String> = row.q.iter().map(|v| format!("{v:?}")).collect();
        record.extend(row.position.iter().map(|v| format!("{:?}", v * 1e3)));
        if columns.full_pose {
            let q = row.orientation.map_or([1.0, 0.0, 0.0, 0.0], |r| r.to_quaternion());
            record.extend(q.iter().map(|v| format!("{v:?}")));
        }
        record.push(format!("{:?}", row.payload_kg));
        if self.named_tools {
            record.push(columns.tools.get(row.tool).cloned().unwrap_or_default());
        }
        if columns.temp_c {
            record.push(row.temp_c.map_or(String::new(), |v| format!("{v:?}")));
        }
        if columns.t_s {
            record.push(row.t_s.map_or(String::new(), |v| format!("{v:?}")));
        }
        if let Some(tau) = &row.torques_nm {
            record.extend(tau.iter().map(|v| format!("{v:?}")));
        }
        if !columns.inputs.is_empty() {
            if row.inputs.names() == columns.inputs.as_slice() {
                record.extend(row.inputs.values().iter().map(|v| format!("{v:?}")));
            } else {
                let cell = |name: &String| row.inputs.get(name).map_or(String::new(), |v| format!("{v:?}"));
                record.extend(columns.inputs.iter().map(cell));
            }
        }
        let stated = [row.std.and_then(|s| s.position_m), row.std.and_then(|s| s.rotation_rad)];
        for (written, values) in columns.stated_std.iter().zip(stated) {
            if *written {
                match values {
                    Some(v) => record.extend(v.iter().map(|x| format!("{:?}", x * 1e3))),
                    None => record.extend(std::iter::repeat_n(String::new(), 3)),
                }
            }
        }
        Ok(self.out.write_record(&record)?)
    }

    /// Flushes what is buffered.
    pub fn finish(mut self) -> Result<(), std::io::Error> {
        self.out.flush()
    }
}

impl MeasurementSet {
    /// Writes the set as SPEC CSV: revolute joints in radians, prismatic joints in metres (the
    /// kinds the file's units said; radians for a set made in memory), positions in millimetres,
    /// the orientation as a quaternion.
    pub fn write_csv<W: Write>(&self, writer: W) -> Result<(), std::io::Error> {
        let has = |f: &dyn Fn(&Measurement) -> bool| self.rows.iter().any(f);
        let columns = CsvColumns {
            joint_kinds: (0..self.joint_count)
                .map(|j| self.joint_columns.get(j).map_or(JointKind::Revolute, |c| c.kind))
                .collect(),
            full_pose: self.full_pose,
            tools: self.tools.clone(),
            temp_c: has(&|r| r.temp_c.is_some()),
            t_s: has(&|r| r.t_s.is_some()),
            torques: self.rows.first().and_then(|r| r.torques_nm.as_ref()).map_or(0, Vec::len),
            inputs: if self.inputs.is_empty() {
                self.rows.first().map_or_else(Vec::new, |r| r.inputs.names().to_vec())
            } else {
                self.inputs.iter().map(|c| c.name.clone()).collect()
            },
            stated_std: [
                has(&|r| r.std.is_some_and(|s| s.position_m.is_some())),
                has(&|r| r.std.is_some_and(|s| s.rotation_rad.is_some())),
            ],
        };
        let mut out = MeasurementWriter::new(writer, columns)?;
        for row in &self.rows {
            out.write_row(row)?;
        }
        out.finish()
    }
}
