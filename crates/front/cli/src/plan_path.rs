//! `autoshovel plan-path`: travel planning with the classic or improved
//! potential field on a built-in or user scenario (SPEC §2, §6).

use std::path::Path;

use anyhow::Result;
use autoshovel_walk_planner::{PlanPathSummary, Scenario};

use crate::output::out_dir;
use crate::output::Report as _;
use crate::PlannerArg;

/// Arguments of `plan-path`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Built-in scenario (straight, straight-reverse, curve, curve-reverse, v-shape) or a TOML file.
    #[arg(long, default_value = "curve")]
    pub scenario: String,
    /// Potential field to descend.
    #[arg(long, value_enum, default_value = "improved-apf")]
    pub planner: PlannerArg,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
    /// Success needs every leg to end within this of its required heading (deg).
    #[arg(long, default_value_t = autoshovel_walk_planner::DEFAULT_HEADING_TOLERANCE_DEG)]
    pub heading_tolerance_deg: f64,
}

/// Runs `plan-path` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let scenario = Scenario::resolve(&args.scenario)?;
    let out = out_dir(
        args.output.out.as_deref(),
        &[Some(Path::new(&args.scenario))],
        args.output.force,
    )?;
    let job = autoshovel_jobs::plan_path(
        &scenario,
        args.planner.into(),
        args.heading_tolerance_deg,
        out.as_ref(),
    )?;
    job.report(args.output.json, print_human)?;
    match &job.summary.error {
        Some(e) => Err(anyhow::anyhow!(
            "{} could not plan scenario '{}': {e}",
            job.summary.planner,
            job.summary.scenario
        )),
        None => Ok(()),
    }
}

fn print_human(s: &PlanPathSummary) {
    let f = |v: Option<f64>| {
        v.filter(|v| v.is_finite())
            .map(|v| format!("{v:.3}"))
            .unwrap_or_else(|| "-".into())
    };
    crate::say!(
        "{} on {}: {}",
        s.planner,
        s.scenario,
        if s.success { "success" } else { "FAILED" }
    );
    crate::say!(
        "  length            {} m (reference {} m, ratio {})",
        f(s.length_m),
        f(s.reference.length_m),
        f(s.reference.length_ratio)
    );
    crate::say!("  min clearance     {} m", f(s.min_clearance_m));
    crate::say!(
        "  heading error     {} deg at the goal, {} deg at the start",
        f(s.final_heading_error_deg),
        f(s.start_heading_error_deg)
    );
    crate::say!("  max curvature     {} 1/m", f(s.max_curvature_per_m));
    crate::say!("  escapes           {}", s.escapes);
    crate::say!("  plan time         {} ms", f(s.plan_time_ms));
}
