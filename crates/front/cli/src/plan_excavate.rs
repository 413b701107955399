//! `autoshovel plan-excavate`: the hydraulic excavator's two-level dig
//! planning (SPEC §5; Shao, Ye & Sun 2016) on a built-in scenario or a TOML
//! file. The planning, the loaders and the summary are
//! `autoshovel_excavator_dig`; the CSV tables and the plots of the paper's
//! Figs. 5–6 are `autoshovel_figures::excavate`. This module parses the
//! arguments, loads, runs and writes. A plan that fails is an error naming
//! the reason; no summary is written for it.

use std::path::{Path, PathBuf};

use crate::output::Report as _;
use anyhow::Result;
use autoshovel_excavator_dig::{ExcavateSummary, Setup};

/// Arguments of `plan-excavate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// paper-over, paper-under, two-boulders, or a scenario TOML file (`--print-scenario` shows the format).
    #[arg(long, default_value = "paper-over")]
    pub scenario: String,
    /// Machine profile (TOML); default: the 15 t class backhoe (`--print-profile` shows it).
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Print the scenario as TOML and exit (a built-in with its comments, or the checked file).
    #[arg(long, conflicts_with = "print_profile")]
    pub print_scenario: bool,
    /// Print the machine profile as TOML and exit (the built-in one, commented, or the checked --profile).
    #[arg(long)]
    pub print_profile: bool,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs `plan-excavate` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    if args.print_scenario {
        print_raw(&Setup::scenario_toml(&args.scenario)?);
        return Ok(());
    }
    if args.print_profile {
        print_raw(&Setup::profile_toml(args.profile.as_deref())?);
        return Ok(());
    }
    let setup = Setup::load(&args.scenario, args.profile.as_deref())?;
    // Refuse a bad --out before planning; it is created only for a plan.
    let out = crate::output::out_dir(
        args.output.out.as_deref(),
        &[Some(Path::new(&args.scenario)), args.profile.as_deref()],
        args.output.force,
    )?;
    autoshovel_jobs::plan_excavate(&setup, out.as_ref())?.report(args.output.json, print_human)
}

fn print_raw(text: &str) {
    use std::io::Write as _;
    let _ = write!(std::io::stdout().lock(), "{text}");
}

/// "(x, y)" to the millimetre; + 0.0 turns −0 into 0.
fn p(v: [f64; 2]) -> String {
    format!("({:.3}, {:.3})", v[0] + 0.0, v[1] + 0.0)
}

fn print_human(s: &ExcavateSummary) {
    let r = &s.plan;
    crate::say!(
        "plan-excavate {} ({}), profile {}",
        r.scenario,
        s.scenario_source,
        s.profile
    );
    crate::say!(
        "  volume {:.3} m³ of {:.3} m³ ({:+.2} %): soil {:.3} + boulders {:.3} m³",
        r.achieved_volume_m3,
        r.target_volume_m3,
        s.volume_error_pct,
        r.soil_volume_m3,
        r.obstacle_volume_m3
    );
    crate::say!(
        "  level 1: start {}, midpoint {}, end {} m",
        p(s.level1_start_m),
        p(r.level1_mid_m),
        p(r.level1_end_m)
    );
    if r.contacts.is_empty() {
        crate::say!("  no boulder met");
    }
    for (i, c) in r.contacts.iter().enumerate() {
        crate::say!(
            "  contact {} with boulder {} at {:.2} s, {} m: F_f ({:.1}, {:.1}) kN, γ {:.1}° → {}",
            i + 1,
            c.obstacle,
            c.t_s,
            p(c.point_m),
            c.force_n[0] / 1e3,
            c.force_n[1] / 1e3,
            c.gamma_deg,
            c.decision
        );
    }
    crate::say!(
        "  dig {:.2} s, ends at {} m; min envelope distance {} m; max joint step {:.2} of the speed limit",
        r.duration_s,
        p(r.final_tip_m),
        r.min_envelope_distance_m
            .map_or("-".to_string(), |d| format!("{d:.4}")),
        r.max_joint_step_ratio
    );
    let t = r.peak_torques_nm.map(|v| v / 1e3);
    crate::say!(
        "  peak torques boom {:.0}, stick {:.0}, bucket {:.0} kN·m; peak digging force {:.1} kN (soil alone {:.1} kN); planned in {:.2} ms",
        t[0],
        t[1],
        t[2],
        s.peak_digging_force_n / 1e3,
        r.peak_soil_force_n / 1e3,
        r.plan_time_ms
    );
}
