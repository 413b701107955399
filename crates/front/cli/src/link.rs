//! The machine link's commands: `plc-sim` (a simulated shovel PLC on OPC
//! UA), `drive` (the workstation driving a PLC along a path), `plc-ack`
//! (a person acknowledging a latched fault) and `pki` (certificates and
//! trust lists). The model, the PLC, the workstation and the certificates
//! are `autoshovel_plc_link`; this module parses, runs and writes.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use anyhow::{bail, Result};
use autoshovel_plc_link::drive::DriveSummary;
use autoshovel_plc_link::{
    pki, Clock, FaultKind, Link, LinkParams, PlcParams, PlcServer, Policy, ServeParams,
};
use autoshovel_walk_tracker::scenario::{resolve, TrackScenario};

use crate::output::out_dir;
use crate::output::Report as _;
use crate::track::{ControllerArg, NoiseArg};

/// Set by Ctrl-C while a drive runs: the drive zeroes the setpoints and ends.
pub static DRIVE_STOP: AtomicBool = AtomicBool::new(false);
/// Whether a drive is running (Ctrl-C then stops it instead of exiting).
pub static DRIVE_ACTIVE: AtomicBool = AtomicBool::new(false);

/// The default endpoint (4840: the OPC UA port registered with IANA).
const DEFAULT_ENDPOINT: &str = "opc.tcp://127.0.0.1:4840/";

/// Security and identity, shared by `drive` and `plc-ack`.
#[derive(Debug, clap::Args)]
pub struct SecurityArgs {
    /// PKI folder (`plc/` and `workstation/` certificates and trust lists,
    /// the operator's password); made on first use.
    #[arg(long, default_value = "pki")]
    pub pki: PathBuf,
    /// User name to log in as (writing setpoints needs one).
    #[arg(long, default_value = pki::OPERATOR)]
    pub user: String,
    /// File whose first line is the user's password (default: PKI/operator.password).
    #[arg(long)]
    pub password_file: Option<PathBuf>,
    /// Security policy (always SignAndEncrypt; `none` needs --insecure).
    #[arg(long, value_enum, default_value = "basic256sha256")]
    pub policy: PolicyArg,
    /// Allow security None (logged loudly).
    #[arg(long)]
    pub insecure: bool,
}

/// Policy choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PolicyArg {
    /// Basic256Sha256, SignAndEncrypt.
    Basic256sha256,
    /// Aes256-Sha256-RsaPss, SignAndEncrypt.
    Aes256sha256rsapss,
    /// No security (needs --insecure).
    None,
}

impl SecurityArgs {
    fn password(&self) -> Result<String> {
        let file = self
            .password_file
            .clone()
            .unwrap_or_else(|| self.pki.join(pki::PASSWORD_FILE));
        Ok(pki::read_password(&file)?)
    }

    fn link(&self, endpoint: &str) -> Result<LinkParams> {
        first_use(&self.pki)?;
        let mut p = LinkParams::new(
            endpoint,
            self.pki.clone(),
            Some((self.user.clone(), self.password()?)),
        );
        p.policy = match self.policy {
            PolicyArg::Basic256sha256 => Policy::Basic256Sha256,
            PolicyArg::Aes256sha256rsapss => Policy::Aes256Sha256RsaPss,
            PolicyArg::None => Policy::None,
        };
        p.insecure = self.insecure;
        Ok(p)
    }
}

/// Makes the PKI folder on first use (when it does not exist at all).
fn first_use(root: &Path) -> Result<()> {
    if let Some(r) = pki::init_if_absent(root)? {
        eprintln!(
            "made {}: plc and workstation certificates, each trusting the other{}",
            root.display(),
            r.password_file
                .map(|p| format!("; the operator's password in {}", p.display()))
                .unwrap_or_default()
        );
    }
    Ok(())
}

fn scenario_of(name: &str, noise: Option<NoiseArg>, seed: u64) -> Result<TrackScenario> {
    let noise = noise.map(|n| match n {
        NoiseArg::Off => autoshovel_walk_tracker::Noise::Off,
        NoiseArg::Rtk => autoshovel_walk_tracker::Noise::Rtk,
    });
    Ok(resolve(name, noise, seed)?)
}

/// Arguments of `plc-sim`.
#[derive(Debug, clap::Args)]
pub struct PlcSimArgs {
    /// The scenario whose machine, ground, receiver and start pose to simulate (as `track` takes it).
    #[arg(long, default_value = "curve")]
    pub scenario: String,
    /// Sensor noise and slip (default: off for fig9a/b, rtk for the others).
    #[arg(long, value_enum)]
    pub noise: Option<NoiseArg>,
    /// Seed of the sensor noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Address to listen on.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: String,
    /// Port (4840 is OPC UA's; 0 picks a free one and prints it).
    #[arg(long, default_value_t = 4840)]
    pub port: u16,
    /// Machine time per wall-clock time (1 = real time).
    #[arg(long, default_value_t = 1.0)]
    pub time_scale: f64,
    /// Advance one control period each time the workstation answers (exact repeats under any load).
    #[arg(long, conflicts_with = "time_scale")]
    pub lockstep: bool,
    /// Start in manual mode (setpoints ignored).
    #[arg(long)]
    pub manual: bool,
    /// Inject a fault at a machine time: KIND@SECONDS or KIND@SECONDS:VALUE, KIND one of
    /// rtk-dropout, rtk-jump, rtk-freeze, link-cut, delay (VALUE: duration
    /// (s), for rtk-jump the offset (m); default 1). Repeatable.
    #[arg(long = "fault")]
    pub faults: Vec<String>,
    /// Stop after this many wall-clock seconds (default: run until Ctrl-C).
    #[arg(long)]
    pub duration: Option<f64>,
    /// PKI folder (made on first use).
    #[arg(long, default_value = "pki")]
    pub pki: PathBuf,
    /// The operator's password file (default: PKI/operator.password).
    #[arg(long)]
    pub password_file: Option<PathBuf>,
    /// Also offer security None (logged loudly).
    #[arg(long)]
    pub insecure: bool,
    /// The MCAP run log of the machine (default: plc-sim-UNIXTIME-PID.mcap here).
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Print the PLC's summary JSON alone on stdout at the end.
    #[arg(long)]
    pub json: bool,
}

/// Runs `plc-sim`.
pub fn plc_sim(args: &PlcSimArgs) -> Result<()> {
    if !(args.time_scale.is_finite() && args.time_scale > 0.0 && args.time_scale <= 100.0) {
        bail!(
            "--time-scale {}: expected a factor in (0, 100]",
            args.time_scale
        );
    }
    let scenario = scenario_of(&args.scenario, args.noise, args.seed)?;
    let schedule = args
        .faults
        .iter()
        .map(|f| FaultKind::parse_spec(f).map_err(|e| anyhow::anyhow!("--fault {e}")))
        .collect::<Result<Vec<_>>>()?;
    first_use(&args.pki)?;
    let password = pki::read_password(
        &args
            .password_file
            .clone()
            .unwrap_or_else(|| args.pki.join(pki::PASSWORD_FILE)),
    )?;
    let params = PlcParams {
        setup: scenario.setup.clone(),
        clock: if args.lockstep {
            Clock::Lockstep
        } else {
            Clock::Scaled(args.time_scale)
        },
        heartbeat_timeout: autoshovel_plc_link::HEARTBEAT_TIMEOUT,
        auto: !args.manual,
        schedule,
    };
    let serve = ServeParams {
        host: args.host.clone(),
        port: args.port,
        pki: args.pki.clone(),
        insecure: args.insecure,
        users: vec![(pki::OPERATOR.to_string(), password)],
    };
    let log_path = args
        .log
        .clone()
        .unwrap_or_else(|| default_log(None, "plc-sim"));
    let log = autoshovel_plc_link::RunLog::create(
        &log_path,
        &[
            ("job", "plc-sim".to_string()),
            ("scenario", scenario.name.clone()),
            ("seed", args.seed.to_string()),
        ],
        false,
    )?;
    let rt = autoshovel_jobs::runtime()?;
    DRIVE_STOP.store(false, Ordering::Relaxed);
    DRIVE_ACTIVE.store(true, Ordering::Relaxed);
    let summary = rt.block_on(async {
        let server = PlcServer::start_logged(params, serve, Some(log)).await?;
        eprintln!(
            "plc-sim: {} on {} ({}; machine of scenario {}, seed {}); Ctrl-C to stop",
            if args.lockstep { "lockstep" } else { "running" },
            server.endpoint(),
            if args.insecure {
                "Basic256Sha256 / Aes256-Sha256-RsaPss SignAndEncrypt, and None"
            } else {
                "Basic256Sha256 / Aes256-Sha256-RsaPss SignAndEncrypt"
            },
            scenario.name,
            args.seed
        );
        let until = args.duration.map(Duration::from_secs_f64);
        let mut seen = 0usize;
        let t0 = tokio::time::Instant::now();
        loop {
            tokio::time::sleep(Duration::from_millis(20)).await;
            {
                let p = server.plc.lock().unwrap_or_else(|e| e.into_inner());
                for e in &p.events[seen..] {
                    eprintln!(
                        "plc-sim: t = {:.2} s (wall {:.2} s): {}: {}",
                        e.t_s, e.wall_s, e.kind, e.message
                    );
                }
                seen = p.events.len();
            }
            if DRIVE_STOP.load(Ordering::Relaxed) || until.is_some_and(|u| t0.elapsed() >= u) {
                break;
            }
        }
        let mut s = server
            .plc
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .summary(&scenario.name, args.seed, &server.endpoint());
        if let Some(done) = server.stop().await {
            s.log = Some(done?.display().to_string());
        }
        Ok::<_, anyhow::Error>(s)
    })?;
    if args.json {
        crate::output::print_json(&summary)?;
    }
    Ok(())
}

/// Arguments of `drive`.
#[derive(Debug, clap::Args)]
pub struct DriveArgs {
    /// The PLC's endpoint.
    #[arg(long, default_value = DEFAULT_ENDPOINT)]
    pub endpoint: String,
    /// The path to drive: as `track` takes it (a built-in or a TOML file).
    #[arg(long, default_value = "curve")]
    pub scenario: String,
    /// Tracker.
    #[arg(long, value_enum, default_value = "fuzzy")]
    pub controller: ControllerArg,
    /// The scenario's noise setting (the machine's own noise is the PLC's; this sets the loop's parameters as `track` does).
    #[arg(long, value_enum)]
    pub noise: Option<NoiseArg>,
    /// The scenario's seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Security and identity.
    #[command(flatten)]
    pub security: SecurityArgs,
    /// Give up when the link stays down this long (s).
    #[arg(long, default_value_t = 30.0)]
    pub link_timeout: f64,
    /// Give up waiting for a fault's acknowledgement after this long (s).
    #[arg(long, default_value_t = 600.0)]
    pub ack_timeout: f64,
    /// Write summary.json, CSV and plots here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The MCAP run log (default: OUT/drive.mcap, or drive-UNIXTIME-PID.mcap here).
    #[arg(long)]
    pub log: Option<PathBuf>,
    /// Replace existing files in the output (and the log) that autoshovel did not write.
    #[arg(long)]
    pub force: bool,
    /// Print the summary JSON alone on stdout.
    #[arg(long)]
    pub json: bool,
}

fn default_log(out: Option<&Path>, stem: &str) -> PathBuf {
    match out {
        Some(dir) => dir.join(format!("{stem}.mcap")),
        None => {
            let secs = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0);
            PathBuf::from(format!("{stem}-{secs}-{}.mcap", std::process::id()))
        }
    }
}

/// Runs `drive`.
pub fn drive(args: &DriveArgs) -> Result<()> {
    for (flag, v) in [
        ("--link-timeout", args.link_timeout),
        ("--ack-timeout", args.ack_timeout),
    ] {
        if !(v.is_finite() && v > 0.0 && v <= 86_400.0) {
            bail!("{flag} {v}: expected seconds in (0, 86400]");
        }
    }
    let scenario = scenario_of(&args.scenario, args.noise, args.seed)?;
    let out = out_dir(
        args.out.as_deref(),
        &[Some(Path::new(&args.scenario))],
        args.force,
    )?;
    let mut params = args.security.link(&args.endpoint)?;
    params.link_timeout = Duration::from_secs_f64(args.link_timeout);
    params.ack_timeout = Duration::from_secs_f64(args.ack_timeout);
    let log_path = args
        .log
        .clone()
        .unwrap_or_else(|| default_log(args.out.as_deref(), "drive"));
    let rt = autoshovel_jobs::runtime()?;
    DRIVE_STOP.store(false, Ordering::Relaxed);
    DRIVE_ACTIVE.store(true, Ordering::Relaxed);
    let job = autoshovel_jobs::drive(
        &rt,
        &scenario,
        args.controller.into(),
        &params,
        &log_path,
        args.force,
        out.as_ref(),
        &DRIVE_STOP,
    );
    DRIVE_ACTIVE.store(false, Ordering::Relaxed);
    let job = job?;
    for e in job.summary.track.events.iter().filter(|e| e.is_safety()) {
        eprintln!("safety: t = {:.2} s: {} ({})", e.t_s, e.message, e.kind);
    }
    for e in &job.summary.link.events {
        eprintln!("link: wall {:.2} s: {} ({})", e.wall_s, e.message, e.kind);
    }
    job.report(args.json, |s: &DriveSummary| {
        let m = &s.track.run.metrics;
        crate::say!(
            "drive {} over {} ({:?}, metrics on {}): max dev {:.3} m, mean dev {:.3} m, final pos err {:.3} m, completed {}",
            s.track.scenario,
            s.link.endpoint,
            s.link.policy,
            s.link.metrics_on,
            m.max_centroid_dev_m,
            m.mean_centroid_dev_m,
            m.final_position_error_m,
            m.completed
        );
        crate::say!(
            "round trips: read p50 {:.2} ms p99 {:.2} ms, write p50 {:.2} ms p99 {:.2} ms",
            s.link.read_ms.p50,
            s.link.read_ms.p99,
            s.link.write_ms.p50,
            s.link.write_ms.p99
        );
    })?;
    match job.summary.track.failure() {
        Some(e) => Err(e.into()),
        None => Ok(()),
    }
}

/// Arguments of `plc-ack`.
#[derive(Debug, clap::Args)]
pub struct AckArgs {
    /// The PLC's endpoint.
    #[arg(long, default_value = DEFAULT_ENDPOINT)]
    pub endpoint: String,
    /// Security and identity.
    #[command(flatten)]
    pub security: SecurityArgs,
}

/// Runs `plc-ack`: calls the PLC's Acknowledge method.
pub fn ack(args: &AckArgs) -> Result<()> {
    let params = args.security.link(&args.endpoint)?;
    let rt = autoshovel_jobs::runtime()?;
    rt.block_on(async {
        let link = Link::open(&params).await?;
        let r = link.acknowledge().await;
        link.close().await;
        r
    })?;
    crate::say!("acknowledged on {}", args.endpoint);
    Ok(())
}

/// `pki` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum PkiCommand {
    /// Make the plc and workstation certificates (keeping existing ones),
    /// have each trust the other, and make the operator's password file.
    Init {
        /// PKI folder.
        #[arg(long, default_value = "pki")]
        dir: PathBuf,
        /// Extra host names or addresses the PLC's certificate names.
        #[arg(long = "host")]
        hosts: Vec<String>,
    },
    /// Add a peer's certificate (DER or PEM) to an application's trust list.
    Trust {
        /// The application's folder (e.g. pki/workstation).
        #[arg(long)]
        dir: PathBuf,
        /// The certificate to trust.
        cert: PathBuf,
    },
}

/// Runs `pki`.
pub fn pki_cmd(cmd: &PkiCommand) -> Result<()> {
    match cmd {
        PkiCommand::Init { dir, hosts } => {
            let r = pki::init(dir, hosts)?;
            for p in &r.made {
                crate::say!("made {}", p.display());
            }
            for p in &r.trusted {
                crate::say!("trusted {}", p.display());
            }
            if let Some(p) = r.password_file {
                crate::say!("operator password in {} (mode 0600)", p.display());
            }
        }
        PkiCommand::Trust { dir, cert } => {
            let to = pki::trust(dir, cert)?;
            crate::say!("trusted {}", to.display());
        }
    }
    Ok(())
}

/// Arguments of `replay`.
#[derive(Debug, clap::Args)]
pub struct ReplayArgs {
    /// A `drive` MCAP log, or a CSV of RTK fixes (t_s, east_m, north_m, heading_deg) with --path.
    pub log: PathBuf,
    /// For a CSV: the planned path, as `track` takes a scenario (built-in or TOML).
    #[arg(long)]
    pub path: Option<String>,
    #[command(flatten)]
    pub output: crate::output::OutputArgs,
}

/// Runs `replay`.
pub fn replay(args: &ReplayArgs) -> Result<()> {
    let planned = match &args.path {
        Some(path) => Some(scenario_of(path, Some(NoiseArg::Off), 1)?),
        None => None,
    };
    let out = out_dir(
        args.output.out.as_deref(),
        &[Some(args.log.as_path())],
        args.output.force,
    )?;
    let job = autoshovel_jobs::replay(&args.log, planned.as_ref(), out.as_ref())?;
    job.report(args.output.json, |s: &autoshovel_run_log::ReplaySummary| {
        let m = &s.metrics;
        crate::say!(
            "replay {} (on {}): max dev {:.3} m, mean dev {:.3} m, final pos err {:.3} m, final heading err {:.2} deg, completed {}",
            s.source,
            s.measured_on,
            m.max_centroid_dev_m,
            m.mean_centroid_dev_m,
            m.final_position_error_m,
            m.final_heading_error_deg,
            m.completed
        );
    })
}
