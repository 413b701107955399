//! `autoshovel study-boulders`: the hydraulic excavator's dig with one
//! buried boulder of random size and place, planned by the planner that knows
//! only what it touches, measured on the truth (`autoshovel_excavator_dig::study`).

use std::path::{Path, PathBuf};

use crate::output::Report as _;
use anyhow::Result;
use autoshovel_excavator_dig::study::BoulderStudyParams;
use autoshovel_excavator_dig::Setup;
use autoshovel_figures::boulders::markdown_table;

/// Arguments of `study-boulders`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The dig to put the boulders in: paper-over, paper-under, or a scenario
    /// TOML file (its own boulders are replaced).
    #[arg(long, default_value = "paper-over")]
    pub scenario: String,
    /// Machine profile (TOML); default: the 15 t class backhoe.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Number of boulders, one dig each.
    #[arg(long, default_value_t = 200)]
    pub cases: usize,
    /// Seed of the boulders and of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Smallest boulder radius (m).
    #[arg(long, default_value_t = 0.15)]
    pub min_radius: f64,
    /// Largest boulder radius (m).
    #[arg(long, default_value_t = 0.5)]
    pub max_radius: f64,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs the study as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let setup = Setup::load(&args.scenario, args.profile.as_deref())?;
    let params = BoulderStudyParams {
        cases: args.cases,
        seed: args.seed,
        radius_m: [args.min_radius, args.max_radius],
    };
    let out = crate::output::out_dir(
        args.output.out.as_deref(),
        &[Some(Path::new(&args.scenario)), args.profile.as_deref()],
        args.output.force,
    )?;
    let job = autoshovel_jobs::study_boulders(
        &setup.scenario,
        &setup.profile,
        &params,
        out.as_ref(),
        !args.output.json,
    )?;
    job.report(args.output.json, |s| crate::say!("{}", markdown_table(s)))
}
