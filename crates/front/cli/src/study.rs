//! `autoshovel study-paths`: the seeded random haul-road study comparing the
//! classic field, the improved field and the Theta* reference.

use anyhow::Result;
use autoshovel_figures::study::markdown_table;
use autoshovel_walk_planner::study::StudyParams;

use crate::output::out_dir;
use crate::output::Report as _;

/// Arguments of `study-paths`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Number of random maps.
    #[arg(long, default_value_t = 500)]
    pub maps: usize,
    /// Seed of the map generator.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Fewest obstacles per map.
    #[arg(long, default_value_t = 3)]
    pub min_obstacles: usize,
    /// Most obstacles per map.
    #[arg(long, default_value_t = 12)]
    pub max_obstacles: usize,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs the study as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let params = StudyParams {
        maps: args.maps,
        seed: args.seed,
        min_obstacles: args.min_obstacles,
        max_obstacles: args.max_obstacles,
        ..Default::default()
    };
    let out = out_dir(args.output.out.as_deref(), &[], args.output.force)?;
    let job = autoshovel_jobs::study(&params, out.as_ref(), !args.output.json)?;
    job.report(args.output.json, |s| crate::say!("{}", markdown_table(s)))
}
