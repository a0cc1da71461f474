//! The diagnosis's figures: its plots ([`Diagnosis::error_plots`], the data) drawn by the same
//! writer as the calibration report, so the diagnosis folder (`folder.rs`) and the report cannot
//! drift apart.

use crate::figures::{self, Series};
use diagnose::Diagnosis;
use errors::Error;

/// The diagnosis's plots as `(file name, SVG text)`: the held-out error against each moving joint
/// (`joint<k>.svg`), the payload (`payload.svg`), the temperature (`temperature.svg`) and the time
/// (`time.svg`) where they vary, before and after the selected effects.
pub fn diagnosis_figures(diagnosis: &Diagnosis) -> Result<Vec<(String, String)>, Error> {
    let mut plots = Vec::new();
    for plot in diagnosis.error_plots() {
        let series = [
            Series { name: "geometric model".into(), after: false, points: plot.before_mm },
            Series { name: "with the selected effects".into(), after: true, points: plot.after_mm },
        ];
        plots.push((plot.file_name, figures::scatter(&plot.title, &plot.x_label, "error (mm)", &series)?));
    }
    Ok(plots)
}
