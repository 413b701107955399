//! The PLC's logic, as `autoshovel plc-sim` runs it (walking paper §5.1,
//! Fig. 11): the simulated machine ([`Machine`]: crawler plant with slip and
//! motor limits, RTK at its rate with its noise and mounting offset) under
//! the two setpoints the workstation writes, and the protection a PLC gives
//! its machine — setpoints obeyed only in auto, with a fresh heartbeat and
//! no latched fault; a heartbeat older than the timeout or a dropped link
//! ramps both motors to zero within their acceleration limit and latches a
//! fault that only an acknowledgement at rest clears (no self-restart).
//!
//! Kept free of the protocol so it can be tested on its own; `server.rs`
//! puts it behind OPC UA.

use std::time::Duration;

use autoshovel_core::Pose2;
use autoshovel_walk_tracker::sim::plant_steps;
use autoshovel_walk_tracker::{Machine, RtkFix, Setup, TrackCommand};
use serde::Serialize;

use crate::control::{lock_status, Caller, Control, Refusal};
use crate::model::{fault_code, mode};

/// Which fault to inject, and for how long.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum FaultKind {
    /// The receiver reports nothing for `duration_s`.
    RtkDropout {
        /// Length (s of machine time).
        duration_s: f64,
    },
    /// The next fix is off by `offset_m` east (a multipath jump).
    RtkJump {
        /// Offset (m).
        offset_m: f64,
    },
    /// The receiver's timestamp stops for `duration_s` while it still reports.
    RtkFreeze {
        /// Length (s of machine time).
        duration_s: f64,
    },
    /// The network is cut for `duration_s` (connections dropped, new ones refused).
    LinkCut {
        /// Length (s of wall time).
        duration_s: f64,
    },
    /// The PLC's replies are held back by `delay_s` for `duration_s`.
    Delay {
        /// Added delay (s).
        delay_s: f64,
        /// Length (s of wall time).
        duration_s: f64,
    },
}

impl FaultKind {
    /// The names [`FaultKind::parse`] takes.
    pub const NAMES: &'static [&'static str] =
        &["rtk-dropout", "rtk-jump", "rtk-freeze", "link-cut", "delay"];

    /// A scheduled fault from `KIND@SECONDS[:VALUE]` (VALUE 1 when left
    /// out); the error names the spec.
    pub fn parse_spec(s: &str) -> Result<(f64, FaultKind), String> {
        let (kind, rest) = s
            .split_once('@')
            .ok_or_else(|| format!("{s}: expected KIND@SECONDS[:VALUE]"))?;
        let (at, value) = rest.split_once(':').unwrap_or((rest, "1"));
        let at: f64 = at
            .parse()
            .ok()
            .filter(|t: &f64| t.is_finite() && *t >= 0.0)
            .ok_or_else(|| format!("{s}: time {at:?} is not a number of seconds ≥ 0"))?;
        let value: f64 = value
            .parse()
            .map_err(|_| format!("{s}: value {value:?} is not a number"))?;
        let f = FaultKind::parse(kind, value).map_err(|e| format!("{s}: {e}"))?;
        Ok((at, f))
    }

    /// A fault from its name and one number: the duration (s) (for
    /// `rtk-jump`, the offset (m); for `delay`, the delay (s) lasting 5 s).
    pub fn parse(name: &str, value: f64) -> Result<FaultKind, String> {
        if !value.is_finite() || !(0.0..=3600.0).contains(&value) {
            return Err(format!(
                "fault {name}: value {value} is not a duration in 0 ..= 3600 s"
            ));
        }
        Ok(match name {
            "rtk-dropout" => FaultKind::RtkDropout { duration_s: value },
            "rtk-jump" => FaultKind::RtkJump { offset_m: value },
            "rtk-freeze" => FaultKind::RtkFreeze { duration_s: value },
            "link-cut" => FaultKind::LinkCut { duration_s: value },
            "delay" => FaultKind::Delay {
                delay_s: value,
                duration_s: 5.0,
            },
            _ => {
                return Err(format!(
                    "unknown fault {name:?}; known: {}",
                    Self::NAMES.join(", ")
                ))
            }
        })
    }
}

/// The inverter's readings of one motor: a stated model of a 4-pole
/// induction motor on a V/f inverter (rated 50 Hz, 400 V): frequency
/// f = n·p/120 plus 2 % slip under load, voltage ∝ f up to the rated
/// frequency, current a magnetising part plus a part ∝ the torque the
/// acceleration and rolling resistance need.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize)]
pub struct MotorReadings {
    /// Actual speed (rpm).
    pub speed_rpm: f64,
    /// Output frequency (Hz).
    pub frequency_hz: f64,
    /// Current (A).
    pub current_a: f64,
    /// Voltage (V).
    pub voltage_v: f64,
}

impl MotorReadings {
    fn of(rpm: f64, accel_rpm_s: f64, max_accel: f64) -> Self {
        let f_sync = rpm.abs() * 4.0 / 120.0;
        let load = if rpm.abs() > 1.0 { 0.3 } else { 0.0 }
            + if max_accel > 0.0 {
                (accel_rpm_s.abs() / max_accel).min(1.0) * 0.7
            } else {
                0.0
            };
        let f = if f_sync > 0.0 {
            f_sync * (1.0 + 0.02 * load)
        } else {
            0.0
        };
        Self {
            speed_rpm: rpm,
            frequency_hz: f,
            voltage_v: 400.0 * (f / 50.0).min(1.0),
            current_a: if f > 0.0 { 12.0 + 40.0 * load } else { 0.0 },
        }
    }
}

/// The summary of a simulated PLC's session ([`Plc::summary`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlcSimSummary {
    /// `plc-sim`.
    pub job: &'static str,
    /// The scenario whose machine was simulated.
    pub scenario: String,
    /// The seed of its sensor noise.
    pub seed: u64,
    /// Where the PLC listened.
    pub endpoint: String,
    /// Machine time at the end (s).
    pub machine_time_s: f64,
    /// Distance the crawler travelled (m).
    pub travelled_m: f64,
    /// The fault latched at the end, if any.
    pub fault: Option<String>,
    /// How many faults latched.
    pub faults_latched: usize,
    /// Machine times (s) at which the workstation brought the setpoints to zero.
    pub setpoints_zeroed_at_s: Vec<f64>,
    /// Whether the motors sped up while a fault was latched (must never happen).
    pub moved_while_faulted: bool,
    /// The session holding control at the end, if any.
    pub controller: Option<String>,
    /// Writes and calls refused because the caller did not hold control
    /// (none of them touched the machine).
    pub refused_writes: u64,
    /// Everything the PLC did.
    pub events: Vec<PlcEvent>,
    /// The machine never moved while a fault was latched.
    pub success: bool,
    /// The MCAP run log, once finished.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub log: Option<String>,
}

/// Something the PLC did, on both clocks.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PlcEvent {
    /// Wall-clock time since the PLC started (s).
    pub wall_s: f64,
    /// Machine time (s).
    pub t_s: f64,
    /// Kind: `fault`, `acknowledged`, `inject`, `setpoint-rejected`,
    /// `control-claimed`, `control-refused`, `control-released`,
    /// `control-lost`, `write-refused`.
    pub kind: &'static str,
    /// Human text.
    pub message: String,
}

/// The PLC's heartbeat timeout: 250 ms, so that with the workstation's
/// heartbeat every 50 ms the motors are commanded to zero within 300 ms of
/// the link going quiet (the heartbeat was at most 50 ms old then), and a
/// heartbeat older than 300 ms is never obeyed.
pub const HEARTBEAT_TIMEOUT: Duration = Duration::from_millis(250);

/// How the machine's clock runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Clock {
    /// Machine time = wall time × factor.
    Scaled(f64),
    /// Machine time advances one control period each time the workstation
    /// answers the newest step (co-simulation lockstep, as PX4's SITL does
    /// with its simulator): results repeat exactly whatever the load.
    Lockstep,
}

/// Settings of the simulated PLC.
#[derive(Debug, Clone)]
pub struct PlcParams {
    /// Machine, ground, receiver, start pose and plant step.
    pub setup: Setup,
    /// How time runs.
    pub clock: Clock,
    /// Heartbeat timeout: [`HEARTBEAT_TIMEOUT`].
    pub heartbeat_timeout: Duration,
    /// Start in auto (else manual: setpoints ignored).
    pub auto: bool,
    /// Faults to inject at machine times (s).
    pub schedule: Vec<(f64, FaultKind)>,
}

/// The PLC: machine, setpoints, watchdog, fault latch, injected faults.
pub struct Plc {
    /// The settings.
    pub params: PlcParams,
    /// The simulated machine (plant, receiver, clock).
    pub machine: Machine,
    setpoints: TrackCommand,
    heartbeat: Option<u32>,
    heartbeat_at: Option<f64>,
    /// The holder's next heartbeat counts whatever its value (set by a claim).
    claimed_afresh: bool,
    /// Who holds control (OPC 10000-100 LockingServices).
    pub control: Control,
    refused_writes: u64,
    refusals_logged: std::collections::BTreeSet<(u32, &'static str)>,
    /// The latched fault: code and text.
    pub fault: Option<(u32, String)>,
    mode: u8,
    step: u64,
    step_ack: Option<u64>,
    fix: Option<RtkFix>,
    fix_changed: bool,
    rtk_off_until: f64,
    rtk_freeze: Option<(f64, f64)>,
    rtk_jump: Option<f64>,
    substeps: usize,
    period_steps: usize,
    dt: f64,
    machine_target: f64,
    readings: [MotorReadings; 2],
    next_fault: usize,
    /// Everything the PLC did.
    pub events: Vec<PlcEvent>,
    /// Wall time (s) at which each fault latched.
    pub stops: Vec<f64>,
    /// Machine time (s) of each write that brought the setpoints from
    /// moving to both zero (the workstation's own stops).
    pub zeroed_at: Vec<f64>,
    /// Network faults due now, for the server to carry out.
    pub network: Vec<FaultKind>,
    moved_while_faulted: bool,
    wall_s: f64,
}

impl Plc {
    /// A PLC at rest on the setup's start pose.
    pub fn new(params: PlcParams) -> Self {
        let s = &params.setup;
        let machine = Machine::new(s.crawler, s.slip, s.rtk, s.start);
        let (substeps, dt) = plant_steps(&s.sim);
        let mut plc = Self {
            mode: if params.auto {
                mode::AUTO
            } else {
                mode::MANUAL
            },
            params,
            machine,
            setpoints: TrackCommand::STOP,
            heartbeat: None,
            heartbeat_at: None,
            claimed_afresh: false,
            control: Control::default(),
            refused_writes: 0,
            refusals_logged: Default::default(),
            fault: None,
            step: 0,
            step_ack: None,
            fix: None,
            fix_changed: false,
            rtk_off_until: f64::NEG_INFINITY,
            rtk_freeze: None,
            rtk_jump: None,
            substeps,
            period_steps: 0,
            dt,
            machine_target: 0.0,
            readings: [MotorReadings::default(); 2],
            next_fault: 0,
            events: Vec::new(),
            stops: Vec::new(),
            zeroed_at: Vec::new(),
            network: Vec::new(),
            moved_while_faulted: false,
            wall_s: 0.0,
        };
        plc.params
            .schedule
            .sort_by(|a, b| a.0.partial_cmp(&b.0).unwrap_or(std::cmp::Ordering::Equal));
        plc.sense();
        plc
    }

    fn event(&mut self, kind: &'static str, message: String) {
        self.events.push(PlcEvent {
            wall_s: self.wall_s,
            t_s: self.machine.time_s(),
            kind,
            message,
        });
    }

    /// Latches a fault (if none is latched): setpoints are ignored from now on.
    pub fn latch(&mut self, code: u32, text: String) {
        if self.fault.is_some() {
            return;
        }
        self.stops.push(self.wall_s);
        self.event("fault", text.clone());
        self.fault = Some((code, text));
        self.setpoints = TrackCommand::STOP;
    }

    /// The mode (`model::mode`).
    pub fn mode(&self) -> u8 {
        self.mode
    }

    /// The lockstep step the PLC waits at.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// The newest fix as the receiver reports it (with any injected fault).
    pub fn fix(&self) -> Option<RtkFix> {
        self.fix
    }

    /// Whether a new fix arrived since the last call (and clears the flag).
    pub fn take_fix_changed(&mut self) -> bool {
        std::mem::take(&mut self.fix_changed)
    }

    /// The inverter readings (left, right).
    pub fn readings(&self) -> [MotorReadings; 2] {
        self.readings
    }

    /// The setpoints the PLC obeys now (zero when faulted, in manual, or
    /// without a fresh heartbeat).
    pub fn effective_command(&self) -> TrackCommand {
        if self.fault.is_some()
            || self.mode != mode::AUTO
            || self.heartbeat_at.is_none()
            || self.control.holder().is_none()
        {
            TrackCommand::STOP
        } else {
            self.setpoints
        }
    }

    /// Time left (s) before the lock lapses unless the holder's heartbeat
    /// comes (None: nobody holds control, or the watchdog is not armed).
    pub fn lock_remaining_s(&self) -> Option<f64> {
        self.control.holder()?;
        let at = self.heartbeat_at?;
        Some((self.params.heartbeat_timeout.as_secs_f64() - (self.wall_s - at)).max(0.0))
    }

    /// The setpoints as last written and accepted.
    pub fn setpoints(&self) -> TrackCommand {
        self.setpoints
    }

    /// Whether the motors ever sped up while a fault was latched (must never happen).
    pub fn moved_while_faulted(&self) -> bool {
        self.moved_while_faulted
    }

    /// What `autoshovel plc-sim` reports when it stops: the PLC's state,
    /// its events, and success (the machine never moved while a fault
    /// was latched).
    pub fn summary(&self, scenario: &str, seed: u64, endpoint: &str) -> PlcSimSummary {
        PlcSimSummary {
            job: "plc-sim",
            scenario: scenario.to_string(),
            seed,
            endpoint: endpoint.to_string(),
            machine_time_s: self.machine.time_s(),
            travelled_m: self.machine.travelled_m(),
            fault: self.fault.as_ref().map(|f| f.1.clone()),
            faults_latched: self.stops.len(),
            setpoints_zeroed_at_s: self.zeroed_at.clone(),
            moved_while_faulted: self.moved_while_faulted,
            controller: self.control.holder().map(|h| h.caller.describe()),
            refused_writes: self.refused_writes,
            events: self.events.clone(),
            success: !self.moved_while_faulted,
            log: None,
        }
    }

    /// Refuses a command from `who` unless it holds control: counted, the
    /// first of each kind from each session logged, nothing else changed.
    fn commanded_by(&mut self, who: &Caller, what: &'static str) -> Result<(), Refusal> {
        let r = self.control.check(who);
        if let Err(why) = &r {
            self.refused_writes += 1;
            if self.refusals_logged.insert((who.session, what)) {
                let why = match why {
                    Refusal::Locked { by } => format!("control is held by {by}"),
                    _ => "nobody holds control (InitLock first)".to_string(),
                };
                self.event(
                    "write-refused",
                    format!("{what} from {} refused: {why}", who.describe()),
                );
            }
        }
        r
    }

    /// A setpoint write by `who` (`right` selects the motor): refused
    /// unless `who` holds control (no effect); from the holder, refused
    /// when not finite or beyond the motor limit (and a fault is latched,
    /// as a PLC treats a nonsense command); ignored, though accepted,
    /// while a fault is latched.
    pub fn write_setpoint(&mut self, who: &Caller, right: bool, rpm: f64) -> Result<(), Refusal> {
        self.commanded_by(who, "setpoint")?;
        let max = self.params.setup.crawler.motor_max_rpm;
        if !rpm.is_finite() || rpm.abs() > max * (1.0 + 1e-9) {
            let side = if right { "right" } else { "left" };
            let why = format!("{side} setpoint {rpm} rpm is outside ±{max} rpm");
            self.event("setpoint-rejected", why.clone());
            self.latch(fault_code::SETPOINT_REJECTED, why.clone());
            return Err(Refusal::OutOfRange(why));
        }
        if self.fault.is_some() {
            return Ok(());
        }
        let was_moving = self.setpoints != TrackCommand::STOP;
        if right {
            self.setpoints.right_rpm = rpm;
        } else {
            self.setpoints.left_rpm = rpm;
        }
        if was_moving && self.setpoints == TrackCommand::STOP {
            self.zeroed_at.push(self.machine.time_s());
        }
        Ok(())
    }

    /// A heartbeat write by `who`: from the holder, a changed value (or
    /// the first after its claim) refreshes the watchdog; from anyone
    /// else, refused.
    pub fn write_heartbeat(&mut self, who: &Caller, value: u32) -> Result<(), Refusal> {
        self.commanded_by(who, "heartbeat")?;
        if self.claimed_afresh || self.heartbeat != Some(value) {
            self.claimed_afresh = false;
            self.heartbeat = Some(value);
            self.heartbeat_at = Some(self.wall_s);
        }
        Ok(())
    }

    /// A lockstep answer for `step` by `who` (the holder only).
    pub fn write_step_ack(&mut self, who: &Caller, step: u64) -> Result<(), Refusal> {
        self.commanded_by(who, "lockstep answer")?;
        self.step_ack = Some(step);
        Ok(())
    }

    /// `InitLock` by `who`: takes control when nobody holds it (a latched
    /// fault stays latched: the claim moves nothing until acknowledged);
    /// arms the watchdog, so the holder's heartbeat must follow within
    /// the timeout. Returns the lock status (OPC 10000-100).
    pub fn init_lock(&mut self, who: &Caller, context: &str) -> i32 {
        let again = self.control.holds(who);
        let status = self.control.claim(who, context);
        if status != lock_status::OK {
            let by = self.control.holder().map(|h| h.caller.describe());
            self.event(
                "control-refused",
                format!(
                    "claim by {} refused: control is held by {}",
                    who.describe(),
                    by.unwrap_or_default()
                ),
            );
            return status;
        }
        self.heartbeat_at = Some(self.wall_s);
        if !again {
            self.claimed_afresh = true;
            self.event(
                "control-claimed",
                format!("control claimed by {} ({context})", who.describe()),
            );
        }
        status
    }

    /// `RenewLock` by `who`: the holder's claim counts as activity (as a heartbeat).
    pub fn renew_lock(&mut self, who: &Caller) -> Result<i32, Refusal> {
        match self.control.check(who) {
            Ok(()) => {
                self.heartbeat_at = Some(self.wall_s);
                Ok(lock_status::OK)
            }
            Err(Refusal::RequiresLock) => Ok(lock_status::NOT_LOCKED),
            Err(e) => Err(e),
        }
    }

    /// Ends the lock with `text` (the fault's, code `code`): setpoints
    /// zero, watchdog disarmed, a fault latched so that the next claim
    /// moves the machine only after an acknowledgement at rest.
    fn end_control(&mut self, code: u32, text: String) {
        if let Some(h) = self.control.end() {
            self.event(
                if code == fault_code::CONTROL_ENDED {
                    "control-released"
                } else {
                    "control-lost"
                },
                format!("{}: {text}", h.caller.describe()),
            );
        }
        self.heartbeat_at = None;
        self.setpoints = TrackCommand::STOP;
        self.latch(code, text);
    }

    /// `ExitLock` by `who`: the holder releases control.
    pub fn exit_lock(&mut self, who: &Caller) -> Result<i32, Refusal> {
        match self.control.check(who) {
            Ok(()) => {
                self.end_control(
                    fault_code::CONTROL_ENDED,
                    format!(
                        "control released by {}: a new claim moves the machine after an acknowledgement at rest",
                        who.describe()
                    ),
                );
                Ok(lock_status::OK)
            }
            Err(Refusal::RequiresLock) => Ok(lock_status::NOT_LOCKED),
            Err(e) => Err(e),
        }
    }

    /// `BreakLock` by an operator `who`: ends another session's control,
    /// only with the machine at rest or its holder's heartbeat already
    /// stopped (a person takes over a stopped machine; nobody stops a
    /// moving one this way: its controller does, or the machine's own
    /// emergency stop).
    pub fn break_lock(&mut self, who: &Caller) -> Result<i32, Refusal> {
        let Some(h) = self.control.holder() else {
            return Ok(lock_status::NOT_LOCKED);
        };
        if self.heartbeat_at.is_some() && !self.machine.at_rest() {
            return Err(Refusal::InvalidState(format!(
                "the machine is moving under {}: break control only at rest",
                h.caller.describe()
            )));
        }
        let text = format!(
            "control of {} broken by {}: a new claim moves the machine after an acknowledgement at rest",
            h.caller.describe(),
            who.describe()
        );
        self.end_control(fault_code::CONTROL_ENDED, text);
        Ok(lock_status::OK)
    }

    /// The session `session` closed (or the server timed it out): if it
    /// held control, the machine stops and the fault latches.
    pub fn session_closed(&mut self, session: u32) {
        let holder = self.control.holder().map(|h| h.caller.clone());
        if let Some(c) = holder.filter(|c| c.session == session) {
            self.end_control(
                fault_code::LINK_DROPPED,
                format!(
                    "the controlling session of {} closed: motors ramped to zero",
                    c.describe()
                ),
            );
        }
    }

    /// The acknowledge method, by `who` (any operator session): clears a
    /// latched fault once both motors are at rest; the setpoints start
    /// from zero. Closing `who`'s session afterwards changes nothing.
    pub fn acknowledge(&mut self, who: &Caller) -> Result<(), String> {
        match &self.fault {
            None => Ok(()),
            Some(_) if !self.machine.at_rest() => {
                Err("motors are still turning: acknowledge once at rest".into())
            }
            Some((_, text)) => {
                let text = text.clone();
                self.fault = None;
                self.setpoints = TrackCommand::STOP;
                self.event(
                    "acknowledged",
                    format!("fault cleared by {}: {text}", who.describe()),
                );
                Ok(())
            }
        }
    }

    /// Injects `fault` now.
    pub fn inject(&mut self, fault: FaultKind) {
        let t = self.machine.time_s();
        self.event("inject", format!("{fault:?}"));
        match fault {
            FaultKind::RtkDropout { duration_s } => self.rtk_off_until = t + duration_s,
            FaultKind::RtkFreeze { duration_s } => {
                let stamp = self.fix.map(|f| f.time_s).unwrap_or(t);
                self.rtk_freeze = Some((t + duration_s, stamp));
            }
            FaultKind::RtkJump { offset_m } => self.rtk_jump = Some(offset_m),
            FaultKind::LinkCut { .. } | FaultKind::Delay { .. } => self.network.push(fault),
        }
    }

    fn sense(&mut self) {
        let t = self.machine.time_s();
        while let Some((at, f)) = self.params.schedule.get(self.next_fault).copied() {
            if at > t + 1e-9 {
                break;
            }
            self.next_fault += 1;
            self.inject(f);
        }
        if let Some(mut fix) = self.machine.poll_rtk() {
            if t < self.rtk_off_until {
                return;
            }
            if let Some(offset) = self.rtk_jump.take() {
                fix.east_m += offset;
            }
            if let Some((until, stamp)) = self.rtk_freeze {
                if t < until {
                    fix.time_s = stamp;
                } else {
                    self.rtk_freeze = None;
                }
            }
            self.fix = Some(fix);
            self.fix_changed = true;
        }
    }

    fn advance_one(&mut self, cmd: TrackCommand, steps: usize) {
        let before = self.machine.motors_rpm();
        self.machine.advance(cmd, self.dt, steps);
        let after = self.machine.motors_rpm();
        let dt = self.dt * steps as f64;
        if self.fault.is_some()
            && (after.0.abs() > before.0.abs() + 1e-9 || after.1.abs() > before.1.abs() + 1e-9)
        {
            self.moved_while_faulted = true;
        }
        let max_a = self.params.setup.crawler.motor_max_accel_rpm_per_s;
        self.readings = [
            MotorReadings::of(after.0, (after.0 - before.0) / dt, max_a),
            MotorReadings::of(after.1, (after.1 - before.1) / dt, max_a),
        ];
    }

    /// Runs the PLC up to wall-clock time `wall_s` [s since start]: the
    /// watchdog, then the machine (by the clock's rule), sensing fixes at
    /// their times.
    pub fn run_to(&mut self, wall_s: f64) {
        let wall_dt = (wall_s - self.wall_s).max(0.0);
        self.wall_s = wall_s;
        if let Some(at) = self.heartbeat_at {
            if wall_s - at > self.params.heartbeat_timeout.as_secs_f64() {
                let age = (wall_s - at) * 1e3;
                self.end_control(
                    fault_code::HEARTBEAT_LOST,
                    format!(
                        "heartbeat unchanged for {age:.0} ms (limit {:.0} ms): motors ramped to zero, control released",
                        self.params.heartbeat_timeout.as_secs_f64() * 1e3
                    ),
                );
            }
        }
        // The machine's clock starts with the first heartbeat, so a run
        // repeats for its seed.
        if self.heartbeat.is_none() {
            return;
        }
        let lockstep = matches!(self.params.clock, Clock::Lockstep);
        if lockstep && self.fault.is_none() {
            if self.step_ack == Some(self.step) {
                let cmd = self.effective_command();
                self.advance_one(cmd, self.substeps);
                self.step += 1;
                self.sense();
            }
            self.machine_target = self.machine.time_s();
            return;
        }
        // Free-running (or a latched fault in lockstep: the machine stops
        // in real time whatever the workstation does).
        let scale = match self.params.clock {
            Clock::Scaled(f) => f,
            Clock::Lockstep => 1.0,
        };
        self.machine_target += wall_dt * scale;
        while self.machine.time_s() + self.dt <= self.machine_target + 1e-12 {
            let cmd = self.effective_command();
            self.advance_one(cmd, 1);
            self.sense();
            self.period_steps += 1;
            if self.period_steps == self.substeps {
                self.period_steps = 0;
                if lockstep {
                    // A new step each control period, so the workstation
                    // keeps its own watch while the machine stops.
                    self.step += 1;
                }
            }
        }
    }

    /// The simulator's truth: pose and distance travelled.
    pub fn truth(&self) -> (Pose2, f64) {
        (self.machine.truth(), self.machine.travelled_m())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use autoshovel_walk_tracker::scenario::resolve;
    use autoshovel_walk_tracker::Noise;

    fn plc(clock: Clock) -> Plc {
        let sc = resolve("straight", Some(Noise::Off), 1).unwrap();
        let mut p = Plc::new(PlcParams {
            setup: sc.setup,
            clock,
            heartbeat_timeout: HEARTBEAT_TIMEOUT,
            auto: true,
            schedule: Vec::new(),
        });
        assert_eq!(p.init_lock(&ws(), "test"), lock_status::OK);
        p
    }

    /// The workstation's session.
    fn ws() -> Caller {
        caller(1, Some("operator"))
    }

    fn caller(session: u32, user: Option<&str>) -> Caller {
        Caller {
            session,
            user: user.map(str::to_string),
            client: format!("urn:test:{session}"),
        }
    }

    #[test]
    fn the_watchdog_latches_and_only_an_acknowledgement_at_rest_clears_it() {
        let mut p = plc(Clock::Scaled(1.0));
        p.write_heartbeat(&ws(), 1).unwrap();
        p.write_setpoint(&ws(), false, 1000.0).unwrap();
        p.write_setpoint(&ws(), true, 1000.0).unwrap();
        // 0.24 s with heartbeats every 20 ms: moving, no fault.
        let mut t = 0.0;
        for k in 0..12 {
            t += 0.02;
            p.run_to(t);
            p.write_heartbeat(&ws(), 2 + k).unwrap();
        }
        assert!(p.fault.is_none() && !p.machine.at_rest());
        // Silence: latched once the heartbeat is older than 250 ms, not before.
        let last = t;
        while p.fault.is_none() {
            t += 0.001;
            p.run_to(t);
        }
        let waited = t - last;
        assert!(waited > 0.25 && waited <= 0.252, "{waited}");
        assert_eq!(p.effective_command(), TrackCommand::STOP);
        // Still turning: the acknowledgement is refused.
        assert!(p.acknowledge(&ws()).is_err());
        // Control went with the heartbeat: the old holder's commands are
        // refused; claimed again, its setpoints and heartbeats do not
        // restart the machine.
        assert!(p.control.holder().is_none());
        assert_eq!(
            p.write_setpoint(&ws(), false, 2000.0),
            Err(Refusal::RequiresLock)
        );
        assert_eq!(p.init_lock(&ws(), "again"), lock_status::OK);
        p.write_heartbeat(&ws(), 100).unwrap();
        p.write_setpoint(&ws(), false, 2000.0).unwrap();
        for k in 0..2000 {
            t += 0.001;
            p.run_to(t);
            p.write_heartbeat(&ws(), 101 + k).unwrap();
        }
        assert!(p.machine.at_rest() && p.fault.is_some() && !p.moved_while_faulted());
        // The summary reads the same state: one fault latched and held,
        // the crawler moved, then stopped, never while faulted.
        let s = p.summary("fig9a", 7, "opc.tcp://here:1/");
        assert_eq!((s.faults_latched, s.seed, s.success), (1, 7, true));
        assert_eq!(s.refused_writes, 1);
        assert_eq!(s.fault, p.fault.as_ref().map(|f| f.1.clone()));
        assert!(s.travelled_m > 0.0 && s.machine_time_s >= t - 1e-9);
        assert_eq!(s.events, p.events);
        p.acknowledge(&ws()).unwrap();
        assert!(p.fault.is_none() && p.setpoints() == TrackCommand::STOP);
        assert_eq!(p.summary("fig9a", 7, "").fault, None);
    }

    #[test]
    fn nonsense_setpoints_are_refused_and_latch_a_fault() {
        let mut p = plc(Clock::Scaled(1.0));
        p.write_heartbeat(&ws(), 1).unwrap();
        assert!(p.write_setpoint(&ws(), true, f64::NAN).is_err());
        assert_eq!(
            p.fault.as_ref().map(|f| f.0),
            Some(fault_code::SETPOINT_REJECTED)
        );
        let mut p = plc(Clock::Scaled(1.0));
        assert!(p.write_setpoint(&ws(), false, 3000.1).is_err());
        assert!(p.fault.is_some());
    }

    #[test]
    fn injected_rtk_faults_do_what_they_say() {
        let mut p = plc(Clock::Lockstep);
        p.write_heartbeat(&ws(), 1).unwrap();
        let step = |p: &mut Plc| {
            let s = p.step();
            p.write_step_ack(&ws(), s).unwrap();
            p.run_to(0.0);
        };
        step(&mut p);
        let stamp = p.fix().unwrap().time_s;
        p.inject(FaultKind::RtkFreeze { duration_s: 0.35 });
        for _ in 0..3 {
            step(&mut p);
            assert_eq!(p.fix().unwrap().time_s, stamp, "timestamp frozen");
        }
        for _ in 0..2 {
            step(&mut p);
        }
        assert!(p.fix().unwrap().time_s > stamp, "thawed");
        let before = p.fix().unwrap();
        p.inject(FaultKind::RtkDropout { duration_s: 0.25 });
        step(&mut p);
        step(&mut p);
        assert_eq!(p.fix().unwrap(), before, "no fixes in a dropout");
        p.inject(FaultKind::RtkJump { offset_m: 3.0 });
        step(&mut p);
        let jumped = p.fix().unwrap();
        assert!(
            (jumped.east_m - p.truth().0.x - 3.0).abs() < 1e-9,
            "{jumped:?}"
        );
        step(&mut p);
        assert!(
            (p.fix().unwrap().east_m - p.truth().0.x).abs() < 1e-9,
            "one fix only"
        );
    }

    /// Runs `p` for `secs` of wall time from `t`, the holder's heartbeat
    /// every 20 ms; the new time.
    fn hold(p: &mut Plc, mut t: f64, secs: f64, beat: &mut u32) -> f64 {
        let end = t + secs;
        while t < end {
            t += 0.02;
            p.run_to(t);
            *beat += 1;
            p.write_heartbeat(&ws(), *beat).unwrap();
        }
        t
    }

    #[test]
    fn only_the_session_holding_control_moves_the_machine() {
        let mut p = plc(Clock::Scaled(1.0));
        let hmi = caller(7, None);
        let second = caller(8, Some("operator"));
        let mut beat = 0;
        let mut t = hold(&mut p, 0.0, 0.1, &mut beat);
        p.write_setpoint(&ws(), false, 1000.0).unwrap();
        p.write_setpoint(&ws(), true, 1000.0).unwrap();
        t = hold(&mut p, t, 0.5, &mut beat);
        // A second operator session can neither claim nor command, and
        // its heartbeats keep nothing alive; a reader closing changes nothing.
        assert_eq!(
            p.init_lock(&second, "take over"),
            lock_status::ALREADY_LOCKED
        );
        for (who, what) in [(&second, "operator"), (&hmi, "anonymous")] {
            assert!(
                matches!(
                    p.write_setpoint(who, false, -2000.0),
                    Err(Refusal::Locked { .. })
                ),
                "{what}"
            );
            assert!(matches!(
                p.write_heartbeat(who, 9),
                Err(Refusal::Locked { .. })
            ));
            assert!(matches!(
                p.write_step_ack(who, 1),
                Err(Refusal::Locked { .. })
            ));
            assert!(matches!(p.exit_lock(who), Err(Refusal::Locked { .. })));
            assert!(matches!(p.break_lock(who), Err(Refusal::InvalidState(_))));
            p.session_closed(who.session);
        }
        assert_eq!(
            p.setpoints(),
            TrackCommand {
                left_rpm: 1000.0,
                right_rpm: 1000.0
            }
        );
        assert!(p.fault.is_none());
        assert_eq!(p.summary("straight", 1, "").refused_writes, 6);
        let refused = p
            .events
            .iter()
            .filter(|e| e.kind == "write-refused")
            .count();
        assert_eq!(refused, 6, "one event per session and kind");
        // The holder frozen: the other session's heartbeats do not keep
        // the machine moving.
        let frozen = t;
        while p.fault.is_none() {
            t += 0.02;
            p.run_to(t);
            let _ = p.write_heartbeat(&second, (t * 1e3) as u32);
        }
        assert!(t - frozen <= 0.25 + 0.02 + 1e-9);
        assert_eq!(p.fault.as_ref().unwrap().0, fault_code::HEARTBEAT_LOST);
        // Now unheld: the second session claims, but moves nothing until a
        // person acknowledges at rest, from any operator session.
        assert_eq!(p.init_lock(&second, "take over"), lock_status::OK);
        assert!(p.acknowledge(&ws()).is_err(), "still turning");
        for k in 0..300 {
            t += 0.02;
            p.run_to(t);
            p.write_heartbeat(&second, k).unwrap();
        }
        assert!(p.machine.at_rest() && !p.moved_while_faulted());
        p.acknowledge(&hmi).unwrap();
        // The old holder's session closing now changes nothing.
        p.session_closed(ws().session);
        assert!(p.fault.is_none());
        // The holder's own session closing stops the machine.
        p.session_closed(second.session);
        assert_eq!(p.fault.as_ref().unwrap().0, fault_code::LINK_DROPPED);
        assert!(p.control.holder().is_none());
    }

    #[test]
    fn release_and_break_end_control_and_need_an_acknowledgement() {
        let mut p = plc(Clock::Scaled(1.0));
        let mut beat = 0;
        let t = hold(&mut p, 0.0, 0.1, &mut beat);
        assert_eq!(p.exit_lock(&ws()), Ok(lock_status::OK));
        assert_eq!(p.fault.as_ref().unwrap().0, fault_code::CONTROL_ENDED);
        assert_eq!(p.exit_lock(&ws()), Ok(lock_status::NOT_LOCKED));
        p.acknowledge(&ws()).unwrap();
        // Held but at rest: an operator may break it; a fault latches.
        let other = caller(9, Some("operator"));
        assert_eq!(p.init_lock(&ws(), "again"), lock_status::OK);
        p.run_to(t + 0.05);
        assert_eq!(p.break_lock(&other), Ok(lock_status::OK));
        assert!(p.fault.is_some() && p.control.holder().is_none());
        assert_eq!(p.break_lock(&other), Ok(lock_status::NOT_LOCKED));
        assert_eq!(p.renew_lock(&other), Ok(lock_status::NOT_LOCKED));
    }
}
