//! The diagnosis's report folder (`calib diagnose --report DIR`): its markdown, its figures and its
//! page, written through the same writer as the calibration report.

use crate::diagnosis::diagnosis_figures;
use crate::html;
use diagnose::Diagnosis;
use errors::Error;
use measurements::InputFiles;
use std::path::{Path, PathBuf};

/// Writes the diagnosis's report folder: `diagnosis.md` (the diagnosis's own markdown), its SVG
/// plots ([`diagnosis_figures`]) and `diagnosis.html` (the diagnosis section of the calibration
/// report, plots inline). The folder is made if need be; every file is checked against `inputs`
/// (as the output of `option`) before the first is written, and each is written atomically
/// ([`measurements::write_file`]). Returns the path of `diagnosis.md`.
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
    std::fs::create_dir_all(folder).map_err(|source| Error::io(folder.display().to_string(), source))?;
    for (name, svg) in &plots {
        measurements::write_file(&folder.join(name), svg.as_bytes())?;
    }
    measurements::write_file(&markdown, diagnosis.markdown(&names).as_bytes())?;
    measurements::write_file(&page, html.as_bytes())?;
    Ok(markdown)
}
