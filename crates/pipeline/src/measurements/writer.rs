//! The one writer of the measurement CSV: SPEC v1 (`,` and `.`), full precision, so that a written
//! set reads back bit for bit.

use super::{Measurement, MeasurementSet};
use poe::JointKind;
use std::io::Write;

impl MeasurementSet {
    /// Writes the set as SPEC CSV: revolute joints in radians, prismatic joints in metres (the
    /// kinds the file's units said; radians for a set made in memory), positions in millimetres,
    /// the orientation as a quaternion.
    pub fn write_csv<W: Write>(&self, writer: W) -> Result<(), std::io::Error> {
        let mut out = csv::Writer::from_writer(writer);
        let has = |f: &dyn Fn(&Measurement) -> bool| self.rows.iter().any(f);
        let (temp, time) = (has(&|r| r.temp_c.is_some()), has(&|r| r.t_s.is_some()));
        let torques = self.rows.first().and_then(|r| r.torques_nm.as_ref()).map_or(0, Vec::len);
        let named_tools = self.tools.iter().any(|t| !t.is_empty());
        let mut header: Vec<String> = (1..=self.joint_count)
            .map(|k| match self.joint_columns.get(k - 1).map(|c| c.kind) {
                Some(JointKind::Prismatic) => format!("q{k}_m"),
                _ => format!("q{k}_rad"),
            })
            .collect();
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
                record.push(self.tools.get(row.tool).cloned().unwrap_or_default());
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
