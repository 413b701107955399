//! The simulated machine as its PLC sees it (walking paper §5.1, Fig. 11):
//! the crawler plant ([`crate::plant`]) driven by two motor setpoints, the
//! RTK receiver ([`crate::sensor`]) reporting at its own rate, and the
//! machine's clock. This is the simulator's side: it holds the truth (the
//! true pose, the distance really travelled), which a workstation never
//! reads; `autoshovel plc-sim` serves this same machine over OPC UA.

use autoshovel_core::Pose2;

use crate::plant::{Crawler, CrawlerParams, SlipParams, TrackCommand, AT_REST_RPM};
use crate::sensor::{Rtk, RtkFix, RtkParams};

/// Plant, receiver and clock.
#[derive(Debug, Clone)]
pub struct Machine {
    /// The crawler (true state).
    pub crawler: Crawler,
    /// The RTK receiver.
    pub rtk: Rtk,
    t_s: f64,
    travelled_m: f64,
}

impl Machine {
    /// A machine at rest at `start`, its clock at zero.
    pub fn new(crawler: CrawlerParams, slip: SlipParams, rtk: RtkParams, start: Pose2) -> Self {
        Self {
            crawler: Crawler::new(crawler, slip, start),
            rtk: Rtk::new(rtk),
            t_s: 0.0,
            travelled_m: 0.0,
        }
    }

    /// The machine's clock (s).
    pub fn time_s(&self) -> f64 {
        self.t_s
    }

    /// True pose of the crawler's centroid (the simulator's truth).
    pub fn truth(&self) -> Pose2 {
        self.crawler.state.pose
    }

    /// Distance really travelled by the centroid (the simulator's truth) (m).
    pub fn travelled_m(&self) -> f64 {
        self.travelled_m
    }

    /// Actual motor speeds (left, right) (rpm), as the inverters report them.
    pub fn motors_rpm(&self) -> (f64, f64) {
        (self.crawler.state.left_rpm, self.crawler.state.right_rpm)
    }

    /// Both motors below [`AT_REST_RPM`].
    pub fn at_rest(&self) -> bool {
        let (l, r) = self.motors_rpm();
        l.abs() < AT_REST_RPM && r.abs() < AT_REST_RPM
    }

    /// A fix if one is due now (see [`Rtk::poll`]).
    pub fn poll_rtk(&mut self) -> Option<RtkFix> {
        let truth = self.truth();
        self.rtk.poll(truth, self.t_s)
    }

    /// Advances `steps` plant steps of `dt_s` under `cmd`.
    pub fn advance(&mut self, cmd: TrackCommand, dt_s: f64, steps: usize) {
        for _ in 0..steps {
            let before = self.crawler.state.pose.position();
            self.crawler.step(cmd, dt_s);
            self.travelled_m += (self.crawler.state.pose.position() - before).norm();
            self.t_s += dt_s;
        }
    }

    /// Ramps both motors to zero within their acceleration limit, in plant
    /// steps of `dt_s`, until at rest (at most `max_steps`).
    pub fn stop(&mut self, dt_s: f64, max_steps: usize) {
        for _ in 0..max_steps {
            if self.at_rest() {
                break;
            }
            self.advance(TrackCommand::STOP, dt_s, 1);
        }
    }
}
