//! Gross outliers by the line of the file they stand on: the identification names
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
    /// That distance in robust sigmas above the median (median and 1.4826 · MAD of every row's);
    /// 0 where it is at or below the median.
    pub position_sigmas: f64,
    /// Its orientation's angle from the fitted model, mrad (full-pose data only).
    pub rotation_mrad: Option<f64>,
    /// That angle in robust sigmas above the median; 0 where it is at or below the median (a row
    /// named for its position may have an orientation like the others').
    pub rotation_sigmas: Option<f64>,
}

/// Below one robust sigma above the median a value is within the rows' spread: the message says
/// so rather than give a count (a row named for its position, whose orientation is like the
/// others', was "-1 robust sigmas").
const WITHIN_SPREAD_SIGMAS: f64 = 1.0;

impl OutlierLine {
    /// A row at `line` with its residuals and their robust sigmas above the median, counted from
    /// 0: a value below the median is not a number of sigmas "below" anything a reader compares.
    pub fn new(
        line: u64,
        position_mm: f64,
        position_sigmas: f64,
        rotation_mrad: Option<f64>,
        rotation_sigmas: Option<f64>,
    ) -> Self {
        Self {
            line,
            position_mm,
            position_sigmas: position_sigmas.max(0.0),
            rotation_mrad,
            rotation_sigmas: rotation_sigmas.map(|z| z.max(0.0)),
        }
    }

    /// The outliers of `report`, the identification of `data`'s rows in file order.
    pub fn of(report: &RobustReport, data: &MeasurementSet) -> Vec<Self> {
        report
            .outliers
            .iter()
            .map(|o| {
                Self::new(
                    data.rows.get(o.observation).map_or(0, |r| r.line),
                    o.position_m * 1e3,
                    o.position_sigmas,
                    o.rotation_rad.map(|r| r * 1e3),
                    o.rotation_sigmas,
                )
            })
            .collect()
    }
}

/// `N robust sigmas`, or `within the spread` below [`WITHIN_SPREAD_SIGMAS`].
fn sigmas_text(sigmas: f64) -> String {
    if sigmas < WITHIN_SPREAD_SIGMAS { "within the spread".to_owned() } else { format!("{sigmas:.0} robust sigmas") }
}

impl fmt::Display for OutlierLine {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "line {} ({:.3} mm, {}", self.line, self.position_mm, sigmas_text(self.position_sigmas))?;
        if let (Some(angle), Some(sigmas)) = (self.rotation_mrad, self.rotation_sigmas) {
            write!(f, "; {angle:.3} mrad, {}", sigmas_text(sigmas))?;
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_within_the_spread_is_not_a_negative_count_of_sigmas() {
        // UR10 C even rows, 500 mm added to one z: its rotation was "-1 robust sigmas".
        let row = OutlierLine::new(402, 499.862, 2398.2, Some(0.448), Some(-0.7));
        assert_eq!(row.rotation_sigmas, Some(0.0));
        assert_eq!(row.to_string(), "line 402 (499.862 mm, 2398 robust sigmas; 0.448 mrad, within the spread)");
        let both = OutlierLine::new(17, 3.0, 12.4, Some(9.0), Some(31.6));
        assert_eq!(both.to_string(), "line 17 (3.000 mm, 12 robust sigmas; 9.000 mrad, 32 robust sigmas)");
    }
}
