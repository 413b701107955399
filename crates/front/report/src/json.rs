//! The job summary file, `summary.json`.

use std::path::{Path, PathBuf};

use crate::error::ReportError;

/// Name of the summary file inside a job's output directory.
pub const SUMMARY_FILE: &str = "summary.json";

/// Writes `summary` pretty-printed, with a trailing newline, to
/// `<dir>/summary.json` and returns that path.
pub fn write_summary(dir: &Path, summary: &serde_json::Value) -> Result<PathBuf, ReportError> {
    let path = dir.join(SUMMARY_FILE);
    let mut text = serde_json::to_string_pretty(summary).map_err(|e| {
        ReportError::invalid(format!("{}: cannot serialise summary: {e}", path.display()))
    })?;
    text.push('\n');
    std::fs::write(&path, text).map_err(|e| ReportError::io(&path, e))?;
    Ok(path)
}
