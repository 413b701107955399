//! `autoshovel validate-dig`: planned against measured, the rope-shovel
//! paper's testbed validation (§5, Table 6, Fig. 20) —
//! `autoshovel_rope_shovel_dig::validate::validate` on a `plan-dig --out` folder and a
//! measured CSV, written by `autoshovel_figures::validate`.
//!
//! `--out DIR` gets `summary.json`, `aligned.csv` and the plots `forces`
//! (and `travel` when the record has the rope and handle). Without a
//! testbed, `--simulate FILE` writes a measurement made from the plan with
//! known errors (`autoshovel_rope_shovel_dig::validate::simulate_measurement`) and
//! compares against it.

use std::path::{Path, PathBuf};

use crate::output::Report as _;
use anyhow::{bail, Result};
use autoshovel_figures::validate as figures;
use autoshovel_rope_shovel_dig::validate::{
    simulate_measurement, AlignParams, MeasuredRecord, MeasurementModel, PlannedRecord,
    ValidateSummary,
};
use autoshovel_rope_shovel_dig::DigError;

/// Arguments of `validate-dig`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
The measured CSV has a header row naming its columns: t_s, hoist_force_n and
crowd_force_n are required; rope_length_m, handle_extension_m and mass_kg (the
weighed dig mass: the last value in the column) are optional; other columns are
ignored.

No testbed at hand? `--simulate m.csv` writes a measurement made from the plan
(a logger started --sim-delay-s before the dig, force sensors with gains
--sim-gain-hoist/--sim-gain-crowd and Gaussian noise --sim-noise-n, a dig
--sim-time-scale times as long, a mass off by --sim-mass-offset-kg) and
compares the plan with it; the report should give those errors back:

  autoshovel plan-dig --surface typical --out plan
  autoshovel validate-dig --plan plan --simulate m.csv --out check")]
pub struct Args {
    /// The `--out` folder of one `autoshovel plan-dig` plan (summary.json and samples.csv).
    #[arg(long)]
    pub plan: PathBuf,
    /// The measured record (CSV with a header naming its columns).
    #[arg(
        long,
        required_unless_present = "simulate",
        conflicts_with = "simulate"
    )]
    pub measured: Option<PathBuf>,
    /// Write a measurement simulated from the plan to this CSV, then compare with it.
    #[arg(long)]
    pub simulate: Option<PathBuf>,
    /// Offsets searched either side of the record's start (s); default: half the planned dig time.
    #[arg(long)]
    pub max_lag_s: Option<f64>,
    /// Largest deviation of the measured dig's pace from the plan's searched (%) (0: as planned).
    #[arg(long, default_value_t = 10.0)]
    pub max_stretch_pct: f64,
    /// --simulate: time from the logger's start to the dig's start (s).
    #[arg(long, default_value_t = MeasurementModel::testbed().delay_s, allow_negative_numbers = true)]
    pub sim_delay_s: f64,
    /// --simulate: gain of the hoist force sensor.
    #[arg(long, default_value_t = MeasurementModel::testbed().gain_hoist)]
    pub sim_gain_hoist: f64,
    /// --simulate: gain of the crowd force sensor.
    #[arg(long, default_value_t = MeasurementModel::testbed().gain_crowd)]
    pub sim_gain_crowd: f64,
    /// --simulate: standard deviation of the force noise (N).
    #[arg(long, default_value_t = MeasurementModel::testbed().noise_n)]
    pub sim_noise_n: f64,
    /// --simulate: measured dig time per planned dig time.
    #[arg(long, default_value_t = MeasurementModel::testbed().time_scale)]
    pub sim_time_scale: f64,
    /// --simulate: weighed minus planned mass (kg).
    #[arg(long, default_value_t = MeasurementModel::testbed().mass_offset_kg, allow_negative_numbers = true)]
    pub sim_mass_offset_kg: f64,
    /// --simulate: logger sample period (s).
    #[arg(long, default_value_t = MeasurementModel::testbed().sample_period_s)]
    pub sim_period_s: f64,
    /// --simulate: seed of the noise.
    #[arg(long, default_value_t = MeasurementModel::testbed().seed)]
    pub sim_seed: u64,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

impl Args {
    /// The measurement model of the `--sim-*` options.
    fn model(&self) -> MeasurementModel {
        MeasurementModel {
            noise_n: self.sim_noise_n,
            delay_s: self.sim_delay_s,
            time_scale: self.sim_time_scale,
            gain_hoist: self.sim_gain_hoist,
            gain_crowd: self.sim_gain_crowd,
            mass_offset_kg: self.sim_mass_offset_kg,
            sample_period_s: self.sim_period_s,
            seed: self.sim_seed,
            ..MeasurementModel::testbed()
        }
    }

    /// The alignment search of `--max-lag-s` and `--max-stretch-pct`.
    fn align(&self) -> AlignParams {
        AlignParams {
            max_lag_s: self.max_lag_s,
            max_stretch: self.max_stretch_pct / 100.0,
            ..AlignParams::default()
        }
    }
}

/// The library names its fields; the user wrote flags.
fn flag_error(e: DigError) -> anyhow::Error {
    let DigError::BadParameter {
        name,
        value,
        expected,
    } = e
    else {
        return e.into();
    };
    let flag = match name {
        "MeasurementModel.noise_n" => "--sim-noise-n",
        "MeasurementModel.delay_s" => "--sim-delay-s",
        "MeasurementModel.time_scale" => "--sim-time-scale",
        "MeasurementModel.gain_hoist" => "--sim-gain-hoist",
        "MeasurementModel.gain_crowd" => "--sim-gain-crowd",
        "MeasurementModel.mass_offset_kg" => "--sim-mass-offset-kg",
        "MeasurementModel.sample_period_s" => "--sim-period-s",
        "AlignParams.max_lag_s" => "--max-lag-s",
        "AlignParams.max_stretch" => {
            return anyhow::anyhow!(
                "--max-stretch-pct {}: expected a percentage in [0, 50]",
                100.0 * value
            )
        }
        other => other,
    };
    anyhow::anyhow!("{flag} {value}: expected {expected}")
}

/// Runs `validate-dig` as the command line asks.
pub fn run(args: &Args) -> Result<()> {
    let params = args.align();
    params.validate().map_err(flag_error)?;
    let planned = PlannedRecord::load(&args.plan)?;
    let out = crate::output::out_dir(
        args.output.out.as_deref(),
        &[
            Some(&args.plan.join("summary.json")),
            Some(&args.plan.join("samples.csv")),
            args.measured.as_deref(),
            args.simulate.as_deref(),
        ],
        args.output.force,
    )?;
    let measured = match (&args.measured, &args.simulate) {
        (Some(path), _) => MeasuredRecord::load(path)?,
        (None, Some(path)) => simulate(&planned, &args.model(), path, args.output.force)?,
        (None, None) => bail!("give --measured FILE.csv, or --simulate FILE.csv"),
    };
    let job = autoshovel_jobs::validate_dig(&planned, &measured, &params, out.as_ref())?;
    job.report(args.output.json, print_human)
}

/// Writes the simulated measurement to `path` (never over a file that is
/// there, unless `force`) and returns it.
fn simulate(
    planned: &PlannedRecord,
    model: &MeasurementModel,
    path: &Path,
    force: bool,
) -> Result<MeasuredRecord> {
    if path.exists() && !force {
        bail!(
            "--simulate {}: the file exists; remove it, choose another name, or add --force",
            path.display()
        );
    }
    let m = simulate_measurement(planned, model, path).map_err(flag_error)?;
    m.write(path)?;
    Ok(m)
}

/// The human-readable lines of a comparison.
fn print_human(s: &ValidateSummary) {
    let a = &s.alignment;
    crate::say!(
        "validate-dig {} pile: plan {}, measured {}",
        s.surface,
        s.plan,
        s.measured
    );
    crate::say!(
        "  aligned: the dig starts {:.3} s into the record (t = {:.3} s), time scale {:.4}, correlation {:.4}; {} of {} plan samples compared",
        a.delay_s,
        a.offset_s,
        a.time_scale,
        a.correlation,
        s.compared_samples,
        s.planned_samples
    );
    crate::say!("{}", figures::markdown(s));
}
