//! The registered model as the text of a model file, checked as `calib eval` would read it.

use errors::{CommonKind, Error};
use model::CalibratedModel;

/// The RON text of `model`, as `model::write_model` writes it, read back through
/// `model::parse_model` (every check a reader runs), so that no file is written that a reader
/// refuses; `file` names it in errors.
pub fn checked_model_text(model: &CalibratedModel, file: &str) -> Result<String, Error> {
    let mut text = ron::ser::to_string_pretty(model, ron::ser::PrettyConfig::default().depth_limit(6))
        .map_err(|e| Error::at_line(file.to_owned(), 1, 1, CommonKind::RonFormat { message: e.to_string() }))?;
    text.push('\n');
    model::parse_model(&text, file)?;
    Ok(text)
}
