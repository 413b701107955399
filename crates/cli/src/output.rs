//! Output conventions shared by every job (SPEC §6): `--out DIR` gets
//! `summary.json`, CSV and SVG+PNG plots; `--json` prints the summary alone
//! on stdout; human-readable lines go to stdout only without `--json`.
//!
//! Every job is a [`Job`] of its typed summary (made by the library crate
//! that computes it) and the files written.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};
pub use autoshovel_report::Written;
use serde::Serialize;

/// Makes sure `dir` is a directory we may write into, creating it if needed.
/// An existing directory is used as it is: only the files a job names are
/// written, nothing else in it is touched.
pub fn prepare_dir(dir: &Path) -> Result<PathBuf> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out {}: exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create output directory {}", dir.display()))?;
    Ok(dir.to_path_buf())
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
    /// Writes the job's files into `out` (when given) with `write`, then
    /// `summary.json` listing them all.
    pub fn finish(
        summary: S,
        out: Option<&Path>,
        write: impl FnOnce(&Path, &mut Written) -> Result<()>,
    ) -> Result<Self> {
        let mut written = Written::default();
        if let Some(dir) = out {
            write(dir, &mut written)?;
            autoshovel_report::write_job_summary(dir, &summary, &mut written)?;
        }
        Ok(Self {
            summary,
            written,
            out: out.map(Path::to_path_buf),
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
