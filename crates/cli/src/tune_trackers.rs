//! `autoshovel tune-trackers`: every tracker tuned with the same budget on
//! the same training runs, then scored on runs none was tuned on
//! (`autoshovel_track::tune`).

use std::path::PathBuf;

use anyhow::Result;
use autoshovel_figures::tune::markdown_table;

/// Arguments of `tune-trackers`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Evaluations of the whole training set per tracker.
    #[arg(long, default_value_t = 300)]
    pub budget: usize,
    /// Seed of the searches.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write summary.json, trackers.csv, progress.csv and the plot here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace existing files in the output that autoshovel did not write.
    #[arg(long)]
    pub force: bool,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

/// Runs the comparison as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let out = crate::output::out_dir(args.out.as_deref(), &[], args.force)?;
    let job = crate::jobs::tune_trackers(args.budget, args.seed, out.as_ref(), !args.json)?;
    job.report(args.json, |s| crate::say!("{}", markdown_table(s)))
}
