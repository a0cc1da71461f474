//! The diagnosis's figures, drawn by the same writer as the calibration report, so the diagnosis
//! folder (`folder.rs`) and the report cannot drift apart.

use crate::figures::{self, Series};
use diagnose::{Diagnosis, PoseDiagnosis};
use errors::Error;

/// The diagnosis's plots as `(file name, SVG text)`: the held-out error against each moving joint
/// (`joint<k>.svg`), the payload (`payload.svg`), the temperature (`temperature.svg`) and the time
/// (`time.svg`) where they vary, before and after the selected effects.
pub fn diagnosis_figures(diagnosis: &Diagnosis) -> Result<Vec<(String, String)>, Error> {
    let series = |key: &dyn Fn(&PoseDiagnosis) -> f64| -> Vec<Series> {
        vec![
            Series {
                name: "geometric model".into(),
                after: false,
                points: diagnosis.poses.iter().map(|p| (key(p), p.before_error_mm())).collect(),
            },
            Series {
                name: "with the selected effects".into(),
                after: true,
                points: diagnosis.poses.iter().map(|p| (key(p), p.after_error_mm())).collect(),
            },
        ]
    };
    let mut plots = Vec::new();
    for &joint in &diagnosis.moving_joints {
        let j = joint - 1;
        let title = format!("Held-out error against joint {joint}");
        let svg = if diagnosis.prismatic_joints.contains(&joint) {
            figures::scatter(&title, &format!("joint {joint} (mm)"), "error (mm)", &series(&|p| p.q[j] * 1e3))?
        } else {
            figures::scatter(&title, &format!("joint {joint} (deg)"), "error (mm)", &series(&|p| p.q[j].to_degrees()))?
        };
        plots.push((format!("joint{joint}.svg"), svg));
    }
    let varies = |key: &dyn Fn(&PoseDiagnosis) -> Option<f64>| {
        let values: Vec<f64> = diagnosis.poses.iter().filter_map(key).collect();
        values.len() == diagnosis.poses.len() && values.iter().any(|v| *v != values[0])
    };
    if varies(&|p| Some(p.payload_kg)) {
        let s = series(&|p| p.payload_kg);
        plots.push((
            "payload.svg".into(),
            figures::scatter("Held-out error against payload", "payload (kg)", "error (mm)", &s)?,
        ));
    }
    if varies(&|p| p.temp_c) {
        let s = series(&|p| p.temp_c.unwrap_or(0.0));
        plots.push((
            "temperature.svg".into(),
            figures::scatter("Held-out error against temperature", "temperature (°C)", "error (mm)", &s)?,
        ));
    }
    if varies(&|p| p.t_s) {
        let s = series(&|p| p.t_s.unwrap_or(0.0) / 3600.0);
        plots.push(("time.svg".into(), figures::scatter("Held-out error against time", "time (h)", "error (mm)", &s)?));
    }
    Ok(plots)
}
