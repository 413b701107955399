//! `autoshovel shift`: the whole machine (SPEC §9) — a shift of scan, dig,
//! swing, dump and walk on a built-in scenario or a TOML file. The run,
//! the scenario and the summary are `autoshovel_work_shift`; the tables, maps,
//! timeline and animation are `autoshovel_figures::shift`. This module
//! parses the arguments, loads, runs and writes.

use std::path::{Path, PathBuf};

use crate::output::Report as _;
use anyhow::Result;
use autoshovel_rope_shovel_dig::MachineProfile;
use autoshovel_work_shift::{ShiftOptions, ShiftScenario, ShiftSummary, TomlFile};

/// Arguments of `shift`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// bench, or a scenario TOML file (`--print-scenario` shows the format).
    #[arg(long, default_value = "bench")]
    pub scenario: String,
    /// The dig planner's machine profile at 1:30 (TOML), scaled by the scenario's λ; default: the paper's scale model.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Simulated hours (default: the scenario's).
    #[arg(long, conflicts_with = "cycles")]
    pub hours: Option<f64>,
    /// Stop after this many loading cycles.
    #[arg(long)]
    pub cycles: Option<usize>,
    /// Print the scenario as TOML and exit (the built-in with its comments, or the checked file).
    #[arg(long)]
    pub print_scenario: bool,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs `shift` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    if args.print_scenario {
        use std::io::Write as _;
        let text = match autoshovel_work_shift::scenario::BUILTINS
            .iter()
            .find(|(n, _)| *n == args.scenario)
        {
            Some((_, text)) => text.to_string(),
            None => ShiftScenario::resolve(&args.scenario)?.to_toml(),
        };
        let _ = write!(std::io::stdout().lock(), "{text}");
        return Ok(());
    }
    let scenario = ShiftScenario::resolve(&args.scenario)?;
    let profile = match &args.profile {
        Some(p) => MachineProfile::load(p)?,
        None => MachineProfile::scale_model(),
    };
    let options = ShiftOptions {
        hours: args.hours,
        cycles: args.cycles,
        ..ShiftOptions::default()
    };
    let out = crate::output::out_dir(
        args.output.out.as_deref(),
        &[Some(Path::new(&args.scenario)), args.profile.as_deref()],
        args.output.force,
    )?;
    autoshovel_jobs::shift(
        &scenario,
        &profile,
        &options,
        out.as_ref(),
        !args.output.json,
    )?
    .report(args.output.json, print_human)
}

fn print_human(s: &ShiftSummary) {
    crate::say!(
        "shift on {}: {:.2} h simulated{}, {} passes from {} stands, {} walks ({:.0} m)",
        s.scenario,
        s.hours,
        if s.completed {
            ""
        } else {
            " (ended early: no stand left)"
        },
        s.passes,
        s.stands,
        s.walks,
        s.walked_m
    );
    let c = &s.cycle_time_s;
    crate::say!(
        "  {:.0} t, {:.0} t/h; cycle {:.1} s = dig {:.1} + swing {:.1} + dump {:.1} + return {:.1} + wait {:.1}; walking {:.0} s",
        s.tonnes,
        s.tonnes_per_hour,
        c.total_s,
        c.dig_s,
        c.swing_s,
        c.dump_s,
        c.return_s,
        c.wait_s,
        s.walk_time_s
    );
    let e = &s.energy_kwh_per_t;
    crate::say!(
        "  energy {:.3} kWh/t: hoist {:.3}, crowd {:.3}, swing {:.3}, propel {:.3}; fill {:.2} (from {:.2} to {:.2})",
        e.total,
        e.hoist,
        e.crowd,
        e.swing,
        e.propel,
        s.fill_factor.mean,
        s.fill_factor.min,
        s.fill_factor.max
    );
    let b = &s.mass_balance;
    crate::say!(
        "  mass balance: pit lost {:.3} t, trucks got {:.3} t ({}: |difference| {:.1e} t, tolerance {:.1e} t); plans expected {:.0} t; {:.0} m³ left in the pile",
        b.pit_lost_t,
        b.dumped_t,
        if b.closes { "closes" } else { "DOES NOT CLOSE" },
        b.error_t,
        b.tolerance_t,
        b.planned_t,
        s.volume_left_m3
    );
    crate::say!(
        "  {} safety events; {:.1} s of wall time, {:.0} ms a pass",
        s.safety_events,
        s.wall_ms / 1e3,
        s.ms_per_pass
    );
}
