//! `autoshovel track`: closed-loop tracking of a path by the crawler with the
//! fuzzy tracker, PID, pure pursuit or Stanley (SPEC §3, §6), and `--compare` to run
//! every controller on the same scenario and seed.

use std::path::Path;

use anyhow::Result;
use autoshovel_walk_tracker::scenario::{resolve, Noise};
use autoshovel_walk_tracker::{ControllerKind, RunSummary, TrackSummary};

use crate::output::out_dir;
use crate::output::Report as _;

/// Controller choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ControllerArg {
    /// Fuzzy tracker on preview and centroid deviation (§4.3, Table 1).
    Fuzzy,
    /// PID on the lateral error (kp 800, ki 100, kd 300, §5.4).
    Pid,
    /// Pure pursuit (geometric), forward and reverse.
    PurePursuit,
    /// Stanley (heading and cross-track error, with curvature feed-forward).
    Stanley,
}

impl From<ControllerArg> for ControllerKind {
    fn from(c: ControllerArg) -> Self {
        match c {
            ControllerArg::Fuzzy => ControllerKind::Fuzzy,
            ControllerArg::Pid => ControllerKind::Pid,
            ControllerArg::PurePursuit => ControllerKind::PurePursuit,
            ControllerArg::Stanley => ControllerKind::Stanley,
        }
    }
}

/// Noise choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum NoiseArg {
    /// Exact fixes, ideal tracks.
    Off,
    /// RTK noise (1 cm, ≤ 0.2°, 0.3° mounting offset) and loose-bench slip.
    Rtk,
}

/// Arguments of `track`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// fig9a, fig9b, a plan-path built-in (straight, curve, v-shape, ...), or a TOML file (tracking scenario, or a plan-path scenario to plan first); `autoshovel scenario NAME` prints a built-in.
    #[arg(long, default_value = "fig9a")]
    pub scenario: String,
    /// Tracker.
    #[arg(long, value_enum, default_value = "fuzzy")]
    pub controller: ControllerArg,
    /// Sensor noise and slip (default: off for fig9a/b, rtk for the others).
    #[arg(long, value_enum)]
    pub noise: Option<NoiseArg>,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Run every controller on the same scenario and seed; one table, one overlay plot.
    #[arg(long)]
    pub compare: bool,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs `track` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let noise = args.noise.map(|n| match n {
        NoiseArg::Off => Noise::Off,
        NoiseArg::Rtk => Noise::Rtk,
    });
    let scenario = resolve(&args.scenario, noise, args.seed)?;
    let out = out_dir(
        args.output.out.as_deref(),
        &[Some(Path::new(&args.scenario))],
        args.output.force,
    )?;
    let job = autoshovel_jobs::track(
        &scenario,
        args.controller.into(),
        args.compare,
        out.as_ref(),
    )?;
    // The safety log: on stderr, so stdout stays the summary alone with --json.
    for e in job.summary.events.iter().filter(|e| e.is_safety()) {
        eprintln!("safety: t = {:.2} s: {} ({})", e.t_s, e.message, e.kind);
    }
    job.report(args.output.json, print_human)?;
    match job.summary.failure() {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

fn print_human(s: &TrackSummary) {
    let f = |v: f64, d: usize| {
        if v.is_finite() {
            format!("{v:.d$}")
        } else {
            "-".into()
        }
    };
    crate::say!(
        "track {} (noise {}, seed {})",
        s.scenario,
        s.noise.name(),
        s.seed
    );
    crate::say!("| controller | reached [m] | converged [m] | max dev [m] | mean dev [m] | final heading err [deg] | final pos err [m] | completed |");
    crate::say!("|---|---|---|---|---|---|---|---|");
    let rows: &[RunSummary] = s.compare.as_deref().unwrap_or(std::slice::from_ref(&s.run));
    for r in rows {
        let m = &r.metrics;
        crate::say!(
            "| {} | {} | {} | {} | {} | {} | {} | {} |",
            r.controller,
            f(m.reached_distance_m, 2),
            f(m.convergence_distance_m, 2),
            f(m.max_centroid_dev_m, 3),
            f(m.mean_centroid_dev_m, 3),
            f(m.final_heading_error_deg, 2),
            f(m.final_position_error_m, 3),
            m.completed
        );
    }
}
