//! The workstation's side of the loop (walking paper §5.1, Fig. 11): the
//! speed profile of each leg, the tracking controller at the RTK rate and
//! the safety layer, fed only with what the workstation receives from the
//! machine — RTK fixes with their own timestamps, the machine's clock and
//! the motors' actual speeds. The simulated plant and its truth stay in
//! [`crate::machine`]; [`crate::sim::simulate`] joins the two in one process,
//! and `autoshovel drive` joins this same code to a PLC over OPC UA, so a run
//! on the link and a run in the simulator take the same decisions.

use autoshovel_core::Pose2;

use crate::controller::{ControlInput, Controller};
use crate::geometry::{deviations, Deviations, RefLeg};
use crate::plant::{CrawlerParams, TrackCommand};
use crate::sensor::RtkFix;
use serde::{Deserialize, Serialize};

pub use crate::plant::AT_REST_RPM;

/// Closed-loop settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimParams {
    /// Plant integration step (s).
    pub plant_dt_s: f64,
    /// Control loop rate (Hz) (the RTK delivers fixes at its own rate).
    pub control_rate_hz: f64,
    /// Cruise centroid speed (m/s).
    pub speed_mps: f64,
    /// Acceleration and braking of the speed profile (m/s²).
    pub accel_mps2: f64,
    /// Slowest speed before the end of a leg (m/s).
    pub creep_mps: f64,
    /// Preview distance L at standstill [W eq. 21] (m).
    pub preview_m: f64,
    /// Growth of L with speed (s).
    pub preview_gain_s: f64,
    /// Within `terminal_zone_m` of a leg's end, L is at least this (m): the
    /// preview then runs onto the path's continued last tangent, so the
    /// machine lines up with it as it stops (at creep speed L would shrink
    /// to where centimetre RTK noise hides the heading).
    pub terminal_preview_m: f64,
    /// See `terminal_preview_m` (m).
    pub terminal_zone_m: f64,
    /// Stop when the newest fix is older than this (s).
    pub pose_timeout_s: f64,
    /// Largest plausible speed over ground; a fix implying more is a jump (m/s).
    pub max_plausible_speed_mps: f64,
    /// Give up after this much simulated time per metre of path (plus 30 s).
    pub time_per_m_limit_s: f64,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            plant_dt_s: 0.001,
            control_rate_hz: 10.0,
            speed_mps: 0.5,
            accel_mps2: 0.5,
            creep_mps: 0.05,
            preview_m: 0.19,
            preview_gain_s: 0.42,
            terminal_preview_m: 1.0,
            terminal_zone_m: 2.0,
            pose_timeout_s: 0.3,
            max_plausible_speed_mps: 5.0,
            time_per_m_limit_s: 20.0,
        }
    }
}

/// Something the safety layer or the runner did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    /// Time (s).
    pub t_s: f64,
    /// Kind: "stale-pose", "pose-jump", "pose-recovered", "leg-end", "timeout".
    pub kind: &'static str,
    /// Human text.
    pub message: String,
}

impl Event {
    /// Kind of the event that closes each leg normally.
    pub const LEG_END: &'static str = "leg-end";

    /// Whether the safety layer or the runner intervened (every event but
    /// the normal end of a leg).
    pub fn is_safety(&self) -> bool {
        self.kind != Self::LEG_END
    }
}

/// What the workstation decided at one control tick.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Leg index.
    pub leg: usize,
    /// The pose the decision used (the newest fix).
    pub measured: Pose2,
    /// Deviations of [W eq. 21]–[W eq. 22] at that pose.
    pub dev: Deviations,
    /// Reference speed (m/s).
    pub speed_ref_mps: f64,
    /// Steering n_r − n_l from the controller (rpm).
    pub steer_rpm: f64,
    /// The motor setpoints.
    pub command: TrackCommand,
}

/// Where the run stands after a tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Status {
    /// Keep driving with the last decision's command.
    Running,
    /// Every leg done, machine at rest.
    Finished,
    /// The run time limit passed; setpoints zero.
    TimedOut,
    /// No fix at the start, or a fix no machine could make: setpoints zero,
    /// and the machine must be brought to rest before anything else.
    Stopped,
}

/// The result of one tick: the decisions taken (one, or two at the end of
/// a leg, where the next leg starts in the same tick; none when the run
/// ends) and the status.
#[derive(Debug, Clone, PartialEq)]
pub struct Tick {
    /// The decisions, in order; the last one's command goes to the motors.
    pub decisions: Vec<Decision>,
    /// The run's status.
    pub status: Status,
}

impl Tick {
    /// The command to send now: the last decision's, else stop.
    pub fn command(&self) -> TrackCommand {
        match self.status {
            Status::Running => self
                .decisions
                .last()
                .map(|d| d.command)
                .unwrap_or(TrackCommand::STOP),
            _ => TrackCommand::STOP,
        }
    }
}

/// The workstation: the legs to drive, the loop settings and a controller.
pub struct Workstation<'a> {
    legs: &'a [RefLeg],
    crawler: CrawlerParams,
    sp: SimParams,
    controller: &'a mut dyn Controller,
    t_limit_s: f64,
    leg: usize,
    leg_started: bool,
    s_hint: Option<f64>,
    speed_ref: f64,
    stopping: bool,
    last_fix: Option<(f64, Pose2)>,
    stale: bool,
    done: Option<Status>,
    /// Every event so far.
    pub events: Vec<Event>,
}

impl<'a> Workstation<'a> {
    /// A workstation about to drive `legs`; `t_limit_s` is when it gives up.
    pub fn new(
        legs: &'a [RefLeg],
        crawler: CrawlerParams,
        sp: SimParams,
        controller: &'a mut dyn Controller,
        t_limit_s: f64,
    ) -> Self {
        Self {
            legs,
            crawler,
            sp,
            controller,
            t_limit_s,
            leg: 0,
            leg_started: false,
            s_hint: None,
            speed_ref: 0.0,
            stopping: false,
            last_fix: None,
            stale: false,
            done: if legs.is_empty() {
                Some(Status::Finished)
            } else {
                None
            },
            events: Vec::new(),
        }
    }

    /// Index of the leg being driven.
    pub fn leg(&self) -> usize {
        self.leg
    }

    /// Whether the run has ended, and how.
    pub fn finished(&self) -> Option<Status> {
        self.done
    }

    /// Brings the speed reference to zero and forgets the controller's
    /// state: the machine was stopped from outside (a PLC fault), so the
    /// next tick starts the leg's speed profile from rest.
    pub fn halt(&mut self) {
        self.speed_ref = 0.0;
        self.controller.reset();
    }

    /// Records an event of the link (reconnects, faults, acknowledgements).
    pub fn note(&mut self, t_s: f64, kind: &'static str, message: String) {
        self.event(t_s, kind, message);
    }

    fn event(&mut self, t_s: f64, kind: &'static str, message: String) {
        self.events.push(Event { t_s, kind, message });
    }

    fn end(&mut self, status: Status) -> Tick {
        self.done = Some(status);
        Tick {
            decisions: Vec::new(),
            status,
        }
    }

    /// One control tick at `t_s` on the machine's clock: `fix` is a fix that
    /// arrived since the last tick (its own timestamp gives its age),
    /// `motors_rpm` the motors' actual speeds (left, right). Safety: a fix
    /// implying a speed over ground above `max_plausible_speed_mps` stops
    /// the run; a newest fix older than `pose_timeout_s` zeroes the
    /// setpoints until fixes come back.
    pub fn tick(&mut self, t_s: f64, fix: Option<RtkFix>, motors_rpm: (f64, f64)) -> Tick {
        if let Some(status) = self.done {
            return Tick {
                decisions: Vec::new(),
                status,
            };
        }
        let sp = self.sp;
        let mut decisions = Vec::with_capacity(1);
        let mut fix = fix;
        loop {
            if !self.leg_started {
                self.controller.reset();
                self.leg_started = true;
                self.s_hint = None;
                self.speed_ref = 0.0;
                self.stopping = false;
            }
            if t_s > self.t_limit_s {
                self.event(
                    t_s,
                    "timeout",
                    format!("leg {} not finished after {t_s:.1} s; stopped", self.leg),
                );
                let mut tick = self.end(Status::TimedOut);
                tick.decisions = decisions;
                return tick;
            }
            if let Some(f) = fix.take() {
                let pose = f.to_pose();
                if let Some((tf, prev)) = self.last_fix {
                    let dist = (pose.position() - prev.position()).norm();
                    let implied = dist / (f.time_s - tf).max(1e-9);
                    if implied > sp.max_plausible_speed_mps && dist > 0.5 {
                        self.event(
                            t_s,
                            "pose-jump",
                            format!(
                                "fix jumped {dist:.2} m in {:.2} s ({implied:.1} m/s): tracks stopped",
                                f.time_s - tf
                            ),
                        );
                        let mut tick = self.end(Status::Stopped);
                        tick.decisions = decisions;
                        return tick;
                    }
                }
                if self.stale {
                    self.event(t_s, "pose-recovered", "fixes are back; resuming".into());
                    self.stale = false;
                }
                self.last_fix = Some((f.time_s, pose));
            }
            let Some((tf, measured)) = self.last_fix else {
                self.event(
                    t_s,
                    "stale-pose",
                    "no fix at the start: tracks stopped".into(),
                );
                let mut tick = self.end(Status::Stopped);
                tick.decisions = decisions;
                return tick;
            };
            let leg = &self.legs[self.leg];
            let dir = leg.direction.sign();
            let control_dt = 1.0 / sp.control_rate_hz;
            let mut steer = 0.0;
            let remaining_hint = self
                .s_hint
                .map(|h| leg.length_m() - h)
                .unwrap_or(f64::INFINITY);
            // The preview distance L of [W eq. 21], growing with speed.
            let mut preview = sp.preview_m + sp.preview_gain_s * self.speed_ref.abs();
            if remaining_hint <= sp.terminal_zone_m {
                preview = preview.max(sp.terminal_preview_m);
            }
            let dev = deviations(leg, measured, preview, self.s_hint);
            let cmd;
            if t_s - tf > sp.pose_timeout_s + 1e-6 {
                if !self.stale {
                    self.event(
                        t_s,
                        "stale-pose",
                        format!(
                            "newest fix is {:.0} ms old (limit {:.0} ms): tracks stopped",
                            (t_s - tf) * 1e3,
                            sp.pose_timeout_s * 1e3
                        ),
                    );
                    self.stale = true;
                }
                self.speed_ref = 0.0;
                cmd = TrackCommand::STOP;
            } else {
                self.s_hint = Some(dev.s_a_m);
                let remaining = leg.length_m() - dev.s_a_m;
                if remaining <= 0.02 || self.stopping {
                    self.stopping = true;
                    self.speed_ref = 0.0;
                    cmd = TrackCommand::STOP;
                } else {
                    let brake = (2.0 * sp.accel_mps2 * remaining).sqrt().max(sp.creep_mps);
                    let want = sp.speed_mps.min(brake);
                    self.speed_ref =
                        (self.speed_ref.abs() + sp.accel_mps2 * control_dt).min(want) * dir;
                    let input = ControlInput {
                        leg,
                        pose: measured,
                        dev: &dev,
                        speed_mps: self.speed_ref,
                        dt_s: control_dt,
                        crawler: &self.crawler,
                    };
                    steer = self.controller.step(&input);
                    let base = self.speed_ref / self.crawler.mps_per_rpm();
                    cmd = TrackCommand {
                        left_rpm: base - 0.5 * steer,
                        right_rpm: base + 0.5 * steer,
                    }
                    .saturate(self.crawler.motor_max_rpm);
                }
            }
            decisions.push(Decision {
                leg: self.leg,
                measured,
                dev,
                speed_ref_mps: self.speed_ref,
                steer_rpm: steer,
                command: cmd,
            });
            let at_rest = motors_rpm.0.abs() < AT_REST_RPM && motors_rpm.1.abs() < AT_REST_RPM;
            if self.stopping && at_rest {
                let name = leg.direction.name();
                self.event(
                    t_s,
                    Event::LEG_END,
                    format!("leg {} ({name}) done, machine at rest", self.leg),
                );
                self.leg += 1;
                self.leg_started = false;
                if self.leg == self.legs.len() {
                    self.done = Some(Status::Finished);
                    return Tick {
                        decisions,
                        status: Status::Finished,
                    };
                }
                // The next leg starts in this same tick, on the same fix.
                continue;
            }
            return Tick {
                decisions,
                status: Status::Running,
            };
        }
    }
}
