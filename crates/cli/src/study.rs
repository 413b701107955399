//! `autoshovel study-paths`: the seeded random haul-road study comparing the
//! classic field, the improved field and the Theta* reference.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use autoshovel_figures::study::markdown_table;
use autoshovel_propel::study::{run_map, summarize, MapRow, StudyParams, StudySummary};
use indicatif::{ParallelProgressIterator, ProgressBar, ProgressStyle};
use rayon::prelude::*;

use crate::output::{prepare_dir, Job};

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
    /// Write summary.json, maps.csv and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
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
    let out = args.out.as_deref().map(prepare_dir).transpose()?;
    let job = study(&params, out.as_deref(), !args.json)?;
    job.report(args.json, |s| crate::say!("{}", markdown_table(s)))
}

/// Runs the study (maps in parallel, with a progress bar if asked); writes
/// the outputs into `out` if given.
pub fn study(
    params: &StudyParams,
    out: Option<&Path>,
    progress: bool,
) -> Result<Job<StudySummary>> {
    if params.maps == 0 || params.maps > 100_000 {
        bail!("--maps {} must be between 1 and 100000", params.maps);
    }
    if params.min_obstacles > params.max_obstacles || params.max_obstacles > 60 {
        bail!(
            "--min-obstacles {} and --max-obstacles {} must satisfy min <= max <= 60",
            params.min_obstacles,
            params.max_obstacles
        );
    }
    let bar = if progress {
        ProgressBar::new(params.maps as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} maps, {eta} left")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar.set_message("planning");
    let rows: Vec<MapRow> = (0..params.maps)
        .into_par_iter()
        .progress_with(bar.clone())
        .map(|i| run_map(params, i))
        .collect();
    bar.finish_and_clear();
    Job::finish(summarize(params, &rows), out, |dir, written| {
        Ok(autoshovel_figures::study::write_study(
            dir, params, &rows, written,
        )?)
    })
}
