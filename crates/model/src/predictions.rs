//! The prediction CSV of `calib predict`: the tool pose the model predicts for every row, its
//! standard deviation where the model has one, and the error where the row was measured.

use crate::{CalibratedModel, PredictedPose};
use errors::Error;
use measurements::MeasurementSet;
use std::io::Write;

/// Writes the predictions of `model` for the rows of `data` (`predictions`, one per row, from
/// [`CalibratedModel::predict`]) as CSV to `out`: `line`, the position in mm (and the orientation
/// as a unit quaternion for a full-pose model), the standard deviations in mm (and mrad) where the
/// model predicts them, and `error_mm` where `data` holds measured positions. `sink` names `out`
/// in errors.
pub fn write_predictions<W: Write>(
    out: W,
    sink: &str,
    model: &CalibratedModel,
    data: &MeasurementSet,
    predictions: &[PredictedPose],
) -> Result<(), Error> {
    let failed = |e: csv::Error| Error::io(sink.to_owned(), std::io::Error::other(e));
    let mut out = csv::Writer::from_writer(out);
    // The GP's standard deviation, and that of what the effects leave where they fade out.
    let gp = model.predicts_std();
    let mut header: Vec<&str> = vec!["line", "x_mm", "y_mm", "z_mm"];
    if model.full_pose {
        header.extend(["qw", "qx", "qy", "qz"]);
    }
    if gp {
        header.extend(["std_x_mm", "std_y_mm", "std_z_mm"]);
        if model.full_pose {
            header.extend(["std_rx_mrad", "std_ry_mrad", "std_rz_mrad"]);
        }
    }
    if data.positions_measured {
        header.push("error_mm");
    }
    out.write_record(&header).map_err(failed)?;
    for (row, prediction) in data.rows.iter().zip(predictions) {
        let p = prediction.pose.translation() * 1e3;
        let mut record =
            vec![row.line.to_string(), format!("{:.6}", p.x), format!("{:.6}", p.y), format!("{:.6}", p.z)];
        if model.full_pose {
            record.extend(prediction.pose.rotation().to_quaternion().iter().map(|v| format!("{v:.9}")));
        }
        if let Some(std) = prediction.std {
            record.extend(std[..3].iter().map(|s| format!("{:.6}", s * 1e3)));
            if model.full_pose {
                record.extend(std[3..].iter().map(|s| format!("{:.6}", s * 1e3)));
            }
        }
        if data.positions_measured {
            record.push(format!("{:.6}", (row.position - prediction.pose.translation()).norm() * 1e3));
        }
        out.write_record(&record).map_err(failed)?;
    }
    out.flush().map_err(|source| Error::io(sink.to_owned(), source))
}
