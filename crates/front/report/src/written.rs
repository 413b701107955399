//! What a job wrote: the files under its output folder, recorded as they are
//! written, and `summary.json` with that list in its `files` field (SPEC §6).

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::error::ReportError;
use crate::json::{write_summary, SUMMARY_FILE};

/// Files a job wrote, relative to its output folder.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Written {
    /// SVG plots.
    pub plots: Vec<String>,
    /// Everything else (CSV, JSON, PNG, point clouds).
    pub files: Vec<String>,
}

impl Written {
    /// Records a plot pair `[svg, png]` written under `base`.
    pub fn plot(&mut self, base: &Path, pair: [PathBuf; 2]) {
        let [svg, png] = pair;
        self.plots.push(rel(base, &svg));
        self.files.push(rel(base, &png));
    }

    /// Records a data file written under `base`.
    pub fn file(&mut self, base: &Path, path: &Path) {
        self.files.push(rel(base, path));
    }

    /// Every file, data first, then the SVG plots.
    pub fn all(&self) -> Vec<String> {
        self.files.iter().chain(&self.plots).cloned().collect()
    }
}

fn rel(base: &Path, p: &Path) -> String {
    p.strip_prefix(base)
        .unwrap_or(p)
        .to_string_lossy()
        .replace('\\', "/")
}

/// A summary with the list of files its job wrote (`files`), as
/// `summary.json` holds it and `--json` prints it.
#[derive(Debug, Clone, Serialize)]
pub struct WithFiles<'a, S: Serialize> {
    /// The job's own summary, its fields at the top level.
    #[serde(flatten)]
    pub summary: &'a S,
    /// Files written, relative to the output folder (absent without one).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub files: Option<Vec<String>>,
}

/// `summary` as a JSON value (non-finite numbers become `null`); an error if
/// it does not serialise to a JSON object.
pub fn summary_value<S: Serialize>(summary: &S) -> Result<serde_json::Value, ReportError> {
    let v = serde_json::to_value(summary)
        .map_err(|e| ReportError::invalid(format!("cannot serialise summary: {e}")))?;
    if !v.is_object() {
        return Err(ReportError::invalid("a job summary must be a JSON object"));
    }
    Ok(v)
}

/// Records `summary.json` in `written`, then writes `summary` into `dir`
/// with `files` listing everything written; returns what was written.
pub fn write_job_summary<S: Serialize>(
    dir: &Path,
    summary: &S,
    written: &mut Written,
) -> Result<serde_json::Value, ReportError> {
    written.file(dir, &dir.join(SUMMARY_FILE));
    let v = summary_value(&WithFiles {
        summary,
        files: Some(written.all()),
    })?;
    write_summary(dir, &v)?;
    Ok(v)
}
