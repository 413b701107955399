//! `autoshovel perceive`: the rope-shovel paper's combined filtering process
//! (§3, SPEC §4.1) on a scan file, as `autoshovel_surface::perceive` runs it;
//! its settings, defaults and stages are documented there.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use autoshovel_surface::perceive::PerceptionParams;

use crate::output::out_dir;

/// Arguments of `perceive`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The scan (.pcd .ply .las .laz .xyz .csv .txt).
    #[arg(long, required_unless_present = "print_config")]
    pub input: Option<PathBuf>,
    /// Pipeline settings (TOML); defaults otherwise (`autoshovel perceive --print-config` shows them).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// Print the pipeline settings (the defaults, or --config's) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// The settings of `--config`, or the defaults.
pub fn load_params(config: Option<&Path>) -> Result<PerceptionParams> {
    Ok(match config {
        Some(p) => PerceptionParams::load(p)?,
        None => PerceptionParams::default(),
    })
}

/// Runs `perceive`.
pub fn run(args: &Args) -> Result<()> {
    let params = load_params(args.config.as_deref())?;
    if args.print_config {
        crate::say!("{}", params.to_toml());
        return Ok(());
    }
    let input = args.input.as_deref().context("--input is required")?;
    let out = out_dir(
        args.output.out.as_deref(),
        &[Some(input), args.config.as_deref()],
        args.output.force,
    )?;
    let job = crate::jobs::perceive(input, &params, out.as_ref(), !args.output.json)?;
    job.report(args.output.json, |s| {
        crate::say!("perceive {}", s.input);
        for st in &s.stages {
            crate::say!(
                "  {:<12} {:>10} points  {:>9.1} ms",
                st.stage,
                st.points,
                st.ms
            );
        }
        crate::say!(
            "  roll {:.3} deg, pitch {:.3} deg from a floor of {} points ({:.1} % of the scan, RMS {:.1} mm), fit degree {}, R² {:.4} (all points {:.4})",
            s.roll_deg,
            s.pitch_deg,
            s.floor_points,
            100.0 * s.floor_share,
            1e3 * s.floor_rms_m,
            s.fit.degree,
            s.r2,
            s.fit.r2_all_points
        );
    })
}
