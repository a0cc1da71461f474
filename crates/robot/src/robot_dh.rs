//! Denavit–Hartenberg tables in the robot RON (SPEC version 2): the kinematics as a standard or a
//! modified DH table instead of zero-configuration axes. The table is turned into the axes form
//! exactly: joint `i`'s axis is the z axis of the DH frame the joint turns about (frame `i − 1` in
//! standard DH, frame `i` in modified DH) and passes through that frame's origin; the flange, unless
//! the file gives one, is the last DH frame.

use crate::description::{FlangeDescription, JointDescription};
use errors::ron_position::field_position;
use errors::{CommonKind, Error};
use poe::{DhConvention, DhRow, JointKind, LocalPoe};
use serde::{Deserialize, Serialize};

/// A DH table as written in a robot file: `dh: (convention: Standard, rows: [...])`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DhTable {
    /// `Standard` (distal, `Rz(θ) Tz(d) Tx(a) Rx(α)`) or `Modified` (proximal, Craig:
    /// `Rx(α_{i−1}) Tx(a_{i−1}) Rz(θ_i) Tz(d_i)`, row `i` holding `a_{i−1}` and `α_{i−1}`).
    pub convention: DhConvention,
    /// One row per joint, base first.
    pub rows: Vec<DhTableRow>,
}

/// One row of a DH table. The angle of a revolute joint is `θ = q + θ_offset` and the offset of a
/// prismatic one `d = q + d_offset`, so `q = 0` is the configuration the table shows.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DhTableRow {
    /// Revolute or prismatic.
    pub kind: JointKind,
    /// Link length `a`, metres.
    pub a_m: f64,
    /// Link twist `α`, degrees (or give `alpha_rad`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_deg: Option<f64>,
    /// Link twist `α`, radians (or give `alpha_deg`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub alpha_rad: Option<f64>,
    /// Link offset `d`, metres.
    pub d_m: f64,
    /// Joint angle offset `θ`, degrees (or give `theta_rad`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_deg: Option<f64>,
    /// Joint angle offset `θ`, radians (or give `theta_deg`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub theta_rad: Option<f64>,
    /// Limits of a revolute joint, degrees.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits_deg: Option<(f64, f64)>,
    /// Limits of a prismatic joint, metres.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub limits_m: Option<(f64, f64)>,
}

/// One angle given once, in degrees or radians.
fn angle(deg: Option<f64>, rad: Option<f64>, name: &str) -> Result<f64, String> {
    match (deg, rad) {
        (Some(_), Some(_)) => Err(format!("give {name}_deg or {name}_rad, not both")),
        (None, None) => Err(format!("{name}_deg (or {name}_rad) is required")),
        (Some(deg), None) => Ok(deg.to_radians()),
        (None, Some(rad)) => Ok(rad),
    }
}

impl DhTable {
    /// The table as the kinematics crate takes it, each row checked; a refusal names the row at
    /// its `a_m` field in `text`.
    fn poe_rows(&self, text: &str, file: &str) -> Result<Vec<DhRow>, Error> {
        let at = |row: usize, message: String| {
            let (line, column) = field_position(text, "a_m", row);
            Error::at_line(
                file.to_owned(),
                line as u64,
                column,
                CommonKind::RonFormat { message: format!("DH row {}: {message}", row + 1) },
            )
        };
        if self.rows.is_empty() {
            let (line, column) = field_position(text, "rows", 0);
            return Err(Error::at_line(
                file.to_owned(),
                line as u64,
                column,
                CommonKind::RonFormat { message: "a DH table needs at least one row".into() },
            ));
        }
        self.rows
            .iter()
            .enumerate()
            .map(|(i, row)| {
                let alpha = angle(row.alpha_deg, row.alpha_rad, "alpha").map_err(|m| at(i, m))?;
                let theta = angle(row.theta_deg, row.theta_rad, "theta").map_err(|m| at(i, m))?;
                if ![row.a_m, row.d_m, alpha, theta].iter().all(|v| v.is_finite()) {
                    return Err(at(i, "a_m, d_m, alpha and theta must be finite".into()));
                }
                Ok(DhRow { kind: row.kind, a: row.a_m, alpha, d: row.d_m, theta })
            })
            .collect()
    }

    /// The joints at the zero configuration, and the last DH frame as the flange.
    pub(crate) fn zero_configuration(
        &self,
        text: &str,
        file: &str,
    ) -> Result<(Vec<JointDescription>, FlangeDescription), Error> {
        let rows = self.poe_rows(text, file)?;
        let model = LocalPoe::from_dh(&rows, self.convention);
        let zero = vec![0.0; rows.len()];
        // `from_dh` puts each joint's frame on the DH frame it turns about, so the frame at q = 0
        // holds that joint's axis (its z column) and a point on it (its origin).
        let frames = model.frames(&zero).map_err(Error::kinematics)?;
        let joints = frames
            .iter()
            .zip(&self.rows)
            .map(|(frame, row)| {
                let z = frame.rotation().matrix().column(2).into_owned();
                JointDescription {
                    kind: row.kind,
                    axis: z.into(),
                    point: frame.translation().into(),
                    limits_deg: row.limits_deg,
                    limits_m: row.limits_m,
                    scale: 1.0,
                    pitch_mm: None,
                }
            })
            .collect();
        let flange = model.forward(&zero, 0).map_err(Error::kinematics)?;
        let rotation = flange.rotation().matrix();
        let flange = FlangeDescription {
            position: flange.translation().into(),
            x_axis: rotation.column(0).into_owned().into(),
            z_axis: rotation.column(2).into_owned().into(),
        };
        Ok((joints, flange))
    }
}
