//! Output conventions shared by every job (SPEC §6): `--out DIR` gets
//! `summary.json`, CSV and SVG+PNG plots; `--json` prints the summary alone
//! on stdout; human-readable lines go to stdout only without `--json`.
//!
//! Every job is a [`Job`] of its typed summary (made by the library crate
//! that computes it) and the files written.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
pub use autoshovel_report::{OutDir, Staging, Written};
use serde::Serialize;

/// `--out`, `--force` and `--json`, the same for every job (flattened into
/// each subcommand's arguments).
#[derive(Debug, clap::Args)]
pub struct OutputArgs {
    /// Write summary.json, the job's CSV data and its plots (SVG and PNG) here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace existing files in the output that autoshovel did not write
    /// (never the job's own inputs).
    #[arg(long)]
    pub force: bool,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// The output folder of `--out DIR`, protecting the job's `inputs` (never
/// written over) and, without `--force`, every existing file autoshovel did
/// not write. A `DIR` that is a file is refused before any work.
pub fn out_dir(
    dir: Option<&Path>,
    inputs: &[Option<&Path>],
    force: bool,
) -> Result<Option<OutDir>> {
    let Some(dir) = dir else { return Ok(None) };
    if dir.exists() && !dir.is_dir() {
        bail!("--out {}: exists and is not a directory", dir.display());
    }
    Ok(Some(OutDir {
        dir: dir.to_path_buf(),
        inputs: inputs.iter().flatten().map(|p| p.to_path_buf()).collect(),
        force,
    }))
}

/// Prints a summary as pretty JSON on stdout.
pub fn print_json<S: Serialize + ?Sized>(summary: &S) -> Result<()> {
    crate::say!("{}", serde_json::to_string_pretty(summary)?);
    Ok(())
}

/// A progress bar drawn with `template` on stderr, or a hidden one when
/// `show` is false (under `--json`, or in the demo).
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
    pub fn finish(
        summary: S,
        out: Option<&OutDir>,
        write: impl FnOnce(&Path, &mut Written) -> Result<()>,
    ) -> Result<Self> {
        let staging = out.map(OutDir::stage).transpose()?;
        Self::finish_in(summary, staging, write)
    }

    /// [`Job::finish`] into a staging folder the job has already written to.
    pub fn finish_in(
        summary: S,
        staging: Option<Staging>,
        write: impl FnOnce(&Path, &mut Written) -> Result<()>,
    ) -> Result<Self> {
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

    /// Reports the job: the summary alone on stdout under `--json`,
    /// otherwise `human`'s lines and the folder written to.
    pub fn report(&self, json: bool, human: impl FnOnce(&S)) -> Result<()> {
        if json {
            print_json(&self.json()?)?;
        } else {
            human(&self.summary);
            if let Some(dir) = &self.out {
                crate::say!("wrote {}", dir.display());
            }
        }
        Ok(())
    }
}
