//! The calibrated model as a file: RON with a schema version, written atomically.

use crate::{CalibratedModel, Error};
use std::io::Write;
use std::path::Path;

/// The schema version this build writes and reads.
pub const SCHEMA_VERSION: u32 = 1;

/// Writes `model` to `path` as RON. The text goes to a temporary file in the same folder that is
/// then renamed over `path`, so a crash never leaves a half-written model behind.
pub fn write_model(path: &Path, model: &CalibratedModel) -> Result<(), Error> {
    let io = |source| Error::Io { path: path.display().to_string(), source };
    let text = ron::ser::to_string_pretty(model, ron::ser::PrettyConfig::default().depth_limit(6)).map_err(|e| {
        Error::RonFormat { file: path.display().to_string(), line: 1, column: 1, message: e.to_string() }
    })?;
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_else(|| "model".into());
    let temporary = folder.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let mut file = std::fs::File::create(&temporary)?;
        file.write_all(text.as_bytes())?;
        file.write_all(b"\n")?;
        file.sync_all()?;
        std::fs::rename(&temporary, path)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&temporary);
    }
    result.map_err(io)
}

/// Reads a calibrated model, refusing a file of another schema version.
pub fn read_model(path: &Path) -> Result<CalibratedModel, Error> {
    let text = crate::ron_position::read_text(path)?;
    parse_model(&text, &path.display().to_string())
}

/// Parses a calibrated model from RON text and checks that its parts fit together
/// ([`CalibratedModel::check`]); `file` names it in errors.
pub fn parse_model(text: &str, file: &str) -> Result<CalibratedModel, Error> {
    #[derive(serde::Deserialize)]
    struct Version {
        schema_version: u32,
    }
    let position_error = |e: ron::error::SpannedError| Error::RonFormat {
        file: file.to_owned(),
        line: e.span.start.line,
        column: e.span.start.col,
        message: e.code.to_string(),
    };
    // Read the version alone first so that a model from another version is refused with that
    // reason rather than with whichever field changed.
    let options = crate::ron_position::ron_options();
    let version: Version = match options.from_str::<ron::Value>(text) {
        Ok(value) => value.into_rust().map_err(|e| Error::RonFormat {
            file: file.to_owned(),
            line: 1,
            column: 1,
            message: format!("no schema_version: {e}"),
        })?,
        Err(e) => return Err(position_error(e)),
    };
    if version.schema_version != SCHEMA_VERSION {
        return Err(Error::SchemaVersion {
            file: file.to_owned(),
            found: version.schema_version,
            supported: SCHEMA_VERSION,
        });
    }
    let model: CalibratedModel = options.from_str(text).map_err(position_error)?;
    model.check(text, file)?;
    Ok(model)
}
