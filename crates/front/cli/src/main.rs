//! `autoshovel`: the command-line program. One subcommand per job (SPEC §6);
//! each writes `summary.json`, CSV data and SVG+PNG plots with `--out DIR`
//! and prints the summary alone with `--json`.

/// `println!` that ignores a closed stdout (`autoshovel ... | head`) instead of panicking.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stdout().lock(), $($arg)*);
    }};
}
pub(crate) use say;

mod filter;
mod link;
mod output;
mod perceive;
mod pile;
mod plan_dig;
mod plan_excavate;
mod plan_path;
mod shift;
mod study;
mod study_boulders;
mod track;
mod tune_trackers;
mod validate_dig;

use std::path::PathBuf;
use std::process::ExitCode;

use clap::{CommandFactory, FromArgMatches, Parser, Subcommand, ValueEnum};

/// Autonomy toolkit for mining excavators: perceive, plan the dig, plan the walk, drive.
#[derive(Debug, Parser)]
#[command(name = "autoshovel", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Plan the crawler's walk to the next face with a potential field (SPEC §2).
    PlanPath(plan_path::Args),
    /// Drive the crawler along a path: fuzzy, PID, pure-pursuit or Stanley tracking in the simulator (SPEC §3).
    Track(track::Args),
    /// Write a synthetic LiDAR scan of a muck pile (Fig. 7 shapes) to a point-cloud file.
    GeneratePile(pile::Args),
    /// Level, filter and fit a muck-pile scan (rope-shovel paper §3, SPEC §4.1).
    Perceive(perceive::Args),
    /// Filter any cloud: voxel, statistical, radius, pass-through and level stages in the order given (PCL's semantics).
    Filter(filter::Args),
    /// Plan the dig: a 6th-order tooth path by the Grey Wolf Optimizer (rope-shovel paper §4, SPEC §4.2–4.3).
    PlanDig(plan_dig::Args),
    /// Planned against measured: compare a plan-dig plan with a testbed record (rope-shovel paper §5, Table 6, Fig. 20).
    ValidateDig(validate_dig::Args),
    /// Plan a hydraulic excavator's dig round buried boulders: two-level planning (SPEC §5).
    PlanExcavate(plan_excavate::Args),
    /// The whole machine: a shift of scan, dig, swing, dump and walk against a changing pit (SPEC §9).
    Shift(shift::Args),
    /// Seeded random haul-road study: classic APF, improved APF and the Theta* reference.
    StudyPaths(study::Args),
    /// Seeded boulder study of the excavator planner that knows only what it touches.
    StudyBoulders(study_boulders::Args),
    /// Tune every tracker with the same budget, then score them on runs none was tuned on.
    TuneTrackers(tune_trackers::Args),
    /// Print a built-in scenario (of plan-path, track, plan-excavate or shift) as TOML, to copy and edit.
    Scenario {
        /// Built-in scenario name (an unknown one lists them all, by job).
        name: String,
    },
    /// A simulated shovel PLC on OPC UA: the crawler plant behind a secure server, with its watchdog and faults.
    PlcSim(link::PlcSimArgs),
    /// The workstation: drive a PLC (or plc-sim) along a path over secure OPC UA.
    Drive(link::DriveArgs),
    /// Recompute the tracking metrics (Figs. 13–14) from a drive's MCAP log or a CSV of RTK fixes.
    Replay(link::ReplayArgs),
    /// Acknowledge a PLC's latched fault (the machine must be at rest).
    PlcAck(link::AckArgs),
    /// Certificates and trust lists for the machine link.
    #[command(subcommand)]
    Pki(link::PkiCommand),
    /// Run every job on its embedded defaults and write one report (index.html).
    Demo {
        /// Report folder.
        #[arg(long, default_value = "autoshovel-demo")]
        out: PathBuf,
        /// Print the combined summary as JSON on stdout.
        #[arg(long)]
        json: bool,
        /// Replace files in the report folder that autoshovel did not write.
        #[arg(long)]
        force: bool,
    },
}

/// Field choice on the command line.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum PlannerArg {
    /// Classic artificial potential field ([W eq. 1]–[W eq. 5]), the baseline.
    Apf,
    /// Improved artificial potential field ([W eq. 6]–[W eq. 15]).
    ImprovedApf,
}

impl From<PlannerArg> for autoshovel_walk_planner::FieldKind {
    fn from(p: PlannerArg) -> Self {
        match p {
            PlannerArg::Apf => autoshovel_walk_planner::FieldKind::Classic,
            PlannerArg::ImprovedApf => autoshovel_walk_planner::FieldKind::Improved,
        }
    }
}

/// `autoshovel scenario NAME`: a built-in's TOML, whichever job it is for
/// (plan-path's travel scenarios, which `track` also takes, then track's
/// own, then plan-excavate's, then shift's).
fn print_scenario(name: &str) -> anyhow::Result<()> {
    let text = autoshovel_walk_planner::scenario::builtin_text(name)
        .ok()
        .or_else(|| autoshovel_walk_tracker::scenario::builtin_text(name))
        .or_else(|| autoshovel_excavator_dig::Scenario::builtin_toml(name))
        .or_else(|| {
            autoshovel_work_shift::scenario::BUILTINS
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, text)| *text)
        });
    let Some(text) = text else {
        let own: Vec<&str> = autoshovel_walk_tracker::scenario::BUILTIN_TOML
            .iter()
            .map(|(n, _)| *n)
            .collect();
        anyhow::bail!(
            "unknown built-in scenario '{name}': plan-path and track have {}; track also {}; plan-excavate has {}; shift has {}",
            autoshovel_walk_planner::scenario::builtin_names().join(", "),
            own.join(", "),
            autoshovel_excavator_dig::Scenario::builtin_names().join(", "),
            autoshovel_work_shift::scenario::BUILTINS
                .iter()
                .map(|(n, _)| *n)
                .collect::<Vec<_>>()
                .join(", ")
        );
    };
    use std::io::Write as _;
    let _ = write!(std::io::stdout().lock(), "{text}");
    Ok(())
}

/// `autoshovel demo`: every job on its embedded defaults into `out`, one
/// line a job (or the summary alone under `--json`).
fn demo(out: &std::path::Path, json: bool, force: bool) -> anyhow::Result<()> {
    let options = autoshovel_jobs::demo::DemoOptions {
        force,
        progress: !json,
        stop: &link::DRIVE_STOP,
    };
    let got = autoshovel_jobs::demo::run(out, options, &mut |line| {
        if !json {
            say!("{line}");
        }
    })?;
    if json {
        output::print_json(&serde_json::json!({ "job": "demo", "jobs": got.jobs }))?;
    } else {
        say!("report: {}", got.index.display());
    }
    Ok(())
}

fn main() -> ExitCode {
    // The matches are kept: `filter` runs its stages in the order given.
    let matches = Cli::command().get_matches();
    let cli = Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit());
    autoshovel_jobs::process::keep_freed_memory();
    // Ctrl-C stops any job at once; what it had staged in the output folder
    // goes with it, so nothing half-written is left there.
    let _ = ctrlc::set_handler(|| {
        // A drive (or plc-sim) ends its own way: setpoints zeroed first.
        // A second Ctrl-C exits at once.
        use std::sync::atomic::Ordering;
        if link::DRIVE_ACTIVE.load(Ordering::Relaxed)
            && !link::DRIVE_STOP.swap(true, Ordering::Relaxed)
        {
            eprintln!("interrupted: zeroing the setpoints");
            return;
        }
        autoshovel_report::remove_unfinished();
        eprintln!("interrupted: nothing more was written");
        std::process::exit(130);
    });
    let result = match cli.command {
        Command::PlanPath(args) => plan_path::run(&args),
        Command::StudyPaths(args) => study::run(&args),
        Command::StudyBoulders(args) => study_boulders::run(&args),
        Command::TuneTrackers(args) => tune_trackers::run(&args),
        Command::Track(args) => track::run(&args),
        Command::GeneratePile(args) => pile::run(&args),
        Command::Perceive(args) => perceive::run(&args),
        Command::Filter(args) => filter::run(
            &args,
            matches.subcommand_matches("filter").unwrap_or(&matches),
        ),
        Command::PlanDig(args) => plan_dig::run(&args),
        Command::ValidateDig(args) => validate_dig::run(&args),
        Command::PlanExcavate(args) => plan_excavate::run(&args),
        Command::Shift(args) => shift::run(&args),
        Command::Scenario { name } => print_scenario(&name),
        Command::PlcSim(args) => link::plc_sim(&args),
        Command::Drive(args) => link::drive(&args),
        Command::PlcAck(args) => link::ack(&args),
        Command::Replay(args) => link::replay(&args),
        Command::Pki(cmd) => link::pki_cmd(&cmd),
        Command::Demo { out, json, force } => demo(&out, json, force),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            // Interrupted (Ctrl-C), after zeroing the setpoints: the shell's 128 + SIGINT.
            let interrupted = match e.downcast_ref::<autoshovel_jobs::JobError>() {
                Some(e) => e.interrupted(),
                None => matches!(
                    e.downcast_ref::<autoshovel_plc_link::LinkError>(),
                    Some(autoshovel_plc_link::LinkError::Interrupted { .. })
                ),
            };
            if interrupted {
                return ExitCode::from(130);
            }
            ExitCode::FAILURE
        }
    }
}
