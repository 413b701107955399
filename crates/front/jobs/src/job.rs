//! What every job shares (SPEC §6): the output folder of `--out DIR`
//! (`summary.json`, CSV data and SVG+PNG plots, staged so that nothing
//! half-written is left), the finished [`Job`] of a typed summary and the
//! files written, and the progress bars drawn on stderr.

use std::path::{Path, PathBuf};

pub use autoshovel_report::{OutDir, Staging, Written};
use serde::Serialize;

use crate::{JobError, Result};

/// The output folder of `--out DIR`, protecting the job's `inputs` (never
/// written over) and, without `force`, every existing file autoshovel did
/// not write. A `DIR` that is a file is refused before any work.
pub fn out_dir(
    dir: Option<&Path>,
    inputs: &[Option<&Path>],
    force: bool,
) -> Result<Option<OutDir>> {
    let Some(dir) = dir else { return Ok(None) };
    if dir.exists() && !dir.is_dir() {
        return Err(JobError::setting(
            "--out",
            dir.display(),
            "exists and is not a directory",
        ));
    }
    Ok(Some(OutDir {
        dir: dir.to_path_buf(),
        inputs: inputs.iter().flatten().map(|p| p.to_path_buf()).collect(),
        force,
    }))
}

/// A progress bar drawn with `template` on stderr, or a hidden one when
/// `show` is false (under `--json`, in the demo, from Python).
pub fn progress_bar(show: bool, template: &str) -> indicatif::ProgressBar {
    if !show {
        return indicatif::ProgressBar::hidden();
    }
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    bar
}

/// A finished job: its typed summary and the files it wrote (none without
/// an output folder).
#[derive(Debug, Clone)]
pub struct Job<S> {
    /// The job's summary, as its library crate made it.
    pub summary: S,
    /// Files written under the output folder.
    pub written: Written,
    /// The output folder, if one was given.
    pub out: Option<PathBuf>,
}

impl<S: Serialize> Job<S> {
    /// Writes the job's files with `write` into a staging folder of `out`
    /// (when given), then `summary.json` listing them all, then moves them
    /// into `out` under the output rule (`autoshovel_report::staging`).
    pub fn finish<E: From<autoshovel_report::ReportError>>(
        summary: S,
        out: Option<&OutDir>,
        write: impl FnOnce(&Path, &mut Written) -> Result<(), E>,
    ) -> Result<Self, E> {
        let staging = out.map(OutDir::stage).transpose()?;
        Self::finish_in(summary, staging, write)
    }

    /// [`Job::finish`] into a staging folder the job has already written to.
    pub fn finish_in<E: From<autoshovel_report::ReportError>>(
        summary: S,
        staging: Option<Staging>,
        write: impl FnOnce(&Path, &mut Written) -> Result<(), E>,
    ) -> Result<Self, E> {
        let mut written = Written::default();
        let mut out = None;
        if let Some(staging) = staging {
            write(staging.path(), &mut written)?;
            autoshovel_report::write_job_summary(staging.path(), &summary, &mut written)?;
            out = Some(staging.dir().to_path_buf());
            staging.commit(&written)?;
        }
        Ok(Self {
            summary,
            written,
            out,
        })
    }

    /// The summary as `summary.json` holds it (with `files` when written).
    pub fn json(&self) -> Result<serde_json::Value> {
        Ok(autoshovel_report::summary_value(
            &autoshovel_report::WithFiles {
                summary: &self.summary,
                files: self.out.as_ref().map(|_| self.written.all()),
            },
        )?)
    }
}
