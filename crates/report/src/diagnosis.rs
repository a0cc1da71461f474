//! The diagnosis's figures and its report folder (`calib diagnose --report DIR`), drawn by the same
//! writer as the calibration report, so the two cannot drift apart.

use crate::figures::{self, Series};
use crate::{Error, html};
use pipeline::InputFiles;
use pipeline::diagnose::{Diagnosis, PoseDiagnosis};
use std::path::{Path, PathBuf};

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

/// Writes the diagnosis's report folder: `diagnosis.md` (the diagnosis's own markdown), its SVG
/// plots ([`diagnosis_figures`]) and `diagnosis.html` (the diagnosis section of the calibration
/// report, plots inline). The folder is made if need be; every file is checked against `inputs`
/// (as the output of `option`) before the first is written, and each is written atomically
/// ([`pipeline::write_file`]). Returns the path of `diagnosis.md`.
pub fn write_diagnosis_report(
    diagnosis: &Diagnosis,
    folder: &Path,
    option: &'static str,
    inputs: &InputFiles,
) -> Result<PathBuf, Error> {
    let plots = diagnosis_figures(diagnosis)?;
    let names: Vec<String> = plots.iter().map(|(name, _)| name.clone()).collect();
    let markdown = folder.join("diagnosis.md");
    let page = folder.join("diagnosis.html");
    for path in names.iter().map(|name| folder.join(name)).chain([markdown.clone(), page.clone()]) {
        inputs.check_output(option, &path)?;
    }
    let html = html::diagnosis_page(diagnosis, &plots);
    std::fs::create_dir_all(folder).map_err(|source| Error::Io { path: folder.display().to_string(), source })?;
    for (name, svg) in &plots {
        pipeline::write_file(&folder.join(name), svg.as_bytes())?;
    }
    pipeline::write_file(&markdown, diagnosis.markdown(&names).as_bytes())?;
    pipeline::write_file(&page, html.as_bytes())?;
    Ok(markdown)
}
