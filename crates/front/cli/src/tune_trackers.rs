//! `autoshovel tune-trackers`: every tracker tuned with the same budget on
//! the same training runs, then scored on runs none was tuned on
//! (`autoshovel_walk_tracker::tune`).

use crate::output::Report as _;
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
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs the comparison as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let out = crate::output::out_dir(args.output.out.as_deref(), &[], args.output.force)?;
    let job =
        autoshovel_jobs::tune_trackers(args.budget, args.seed, out.as_ref(), !args.output.json)?;
    job.report(args.output.json, |s| crate::say!("{}", markdown_table(s)))
}
