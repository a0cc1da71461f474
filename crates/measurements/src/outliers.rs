//! Gross outliers by the line of the file they stand on (issue 31): the identification names
//! them by observation (`poe::identify::RobustReport`), the user needs the CSV line.

use crate::MeasurementSet;
use poe::identify::RobustReport;
use serde::{Deserialize, Serialize};
use std::fmt;

/// A row of the measurement file that the geometric fit named as a gross outlier: its residual
/// is beyond the outlier threshold in robust sigmas (`poe::identify::RobustOptions`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OutlierLine {
    /// 1-based line in the measurement file (0 for rows made in memory).
    pub line: u64,
    /// Its tool point's distance from the fitted model, mm.
    pub position_mm: f64,
    /// That distance in robust sigmas above the median (median and 1.4826 · MAD of every row's).
    pub position_sigmas: f64,
    /// Its orientation's angle from the fitted model, mrad (full-pose data only).
    pub rotation_mrad: Option<f64>,
    /// That angle in robust sigmas above the median.
    pub rotation_sigmas: Option<f64>,
}

impl OutlierLine {
    /// The outliers of `report`, the identification of `data`'s rows in file order.
    pub fn of(report: &RobustReport, data: &MeasurementSet) -> Vec<Self> {
        report
            .outliers
            .iter()
            .map(|o| Self {
                line: data.rows.get(o.observation).map_or(0, |r| r.line),
                position_mm: o.position_m * 1e3,
                position_sigmas: o.position_sigmas,
                rotation_mrad: o.rotation_rad.map(|r| r * 1e3),
                rotation_sigmas: o.rotation_sigmas,
            })
            .collect()
    }
}

impl fmt::Display for OutlierLine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {} ({:.3} mm, {:.0} robust sigmas", self.line, self.position_mm, self.position_sigmas)?;
        if let (Some(angle), Some(sigmas)) = (self.rotation_mrad, self.rotation_sigmas) {
            write!(f, "; {angle:.3} mrad, {sigmas:.0} robust sigmas")?;
        }
        write!(f, ")")
    }
}

/// At most this many rows are spelled out in a message; the JSON has them all.
const LISTED: usize = 10;

/// `line 17 (…), line 250 (…)`, the first [`LISTED`] and a count of the rest.
pub fn list_lines(outliers: &[OutlierLine]) -> String {
    let mut text: Vec<String> = outliers.iter().take(LISTED).map(ToString::to_string).collect();
    if outliers.len() > LISTED {
        text.push(format!("and {} more", outliers.len() - LISTED));
    }
    text.join(", ")
}

/// `data` without the rows `report` names (by row, not line: rows made in memory have none).
pub fn without(data: &MeasurementSet, report: &RobustReport) -> MeasurementSet {
    let named: std::collections::HashSet<usize> = report.outliers.iter().map(|o| o.observation).collect();
    let rows = data.rows.iter().enumerate().filter(|(i, _)| !named.contains(i)).map(|(_, r)| r.clone()).collect();
    MeasurementSet { rows, ..data.clone() }
}
