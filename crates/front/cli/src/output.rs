//! Output conventions shared by every job (SPEC §6): `--out DIR` gets
//! `summary.json`, CSV and SVG+PNG plots; `--json` prints the summary alone
//! on stdout; human-readable lines go to stdout only without `--json`.
//!
//! Every job is a [`Job`] of its typed summary (made by the library crate
//! that computes it) and the files written (`autoshovel-jobs`).

use std::path::PathBuf;

use anyhow::Result;
pub use autoshovel_jobs::{out_dir, Job, OutDir};
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

/// Prints a summary as pretty JSON on stdout.
pub fn print_json<S: Serialize + ?Sized>(summary: &S) -> Result<()> {
    crate::say!("{}", serde_json::to_string_pretty(summary)?);
    Ok(())
}

/// Reports a finished job on the console.
pub trait Report<S> {
    /// The summary alone on stdout under `--json`, otherwise `human`'s
    /// lines and the folder written to.
    fn report(&self, json: bool, human: impl FnOnce(&S)) -> Result<()>;
}

impl<S: Serialize> Report<S> for Job<S> {
    fn report(&self, json: bool, human: impl FnOnce(&S)) -> Result<()> {
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
