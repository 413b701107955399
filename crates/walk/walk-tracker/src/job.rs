//! The `track` job: every asked controller on one scenario and seed, and
//! the job's typed summary (SPEC §6) — the metrics of the chosen
//! controller's run at the top level, the gains each controller ran with,
//! and with `compare` one row per controller.

use serde::Serialize;

use crate::choice::ControllerKind;
use crate::controller::{ControllerParams, Gains};
use crate::error::TrackError;
use crate::plant::{CrawlerParams, SlipParams};
use crate::scenario::{Noise, TrackScenario};
use crate::sensor::RtkParams;
use crate::sim::{simulate, Event, Metrics, Run, SimParams};

/// The job's name in its summary.
pub const JOB: &str = "track";

/// One controller's run.
#[derive(Debug, Clone)]
pub struct ControllerRun {
    /// Which controller.
    pub kind: ControllerKind,
    /// Its name, as the controller gives it.
    pub name: &'static str,
    /// The gains it ran with, as the controller reports them.
    pub gains: Gains,
    /// The run.
    pub run: Run,
    /// Wall-clock time of the simulation (ms).
    pub sim_time_ms: f64,
}

/// The runs of a `track` job.
#[derive(Debug, Clone)]
pub struct Tracking {
    /// One run per controller, in [`ControllerKind::ALL`] order with
    /// `compare`, else the chosen controller's alone.
    pub runs: Vec<ControllerRun>,
    /// Index in `runs` of the chosen controller.
    pub main: usize,
    /// Whether every controller ran.
    pub compare: bool,
}

/// Runs `controller` (every controller with `compare`, same scenario and
/// seed) on `scenario` with the scenario's gains.
pub fn track(scenario: &TrackScenario, controller: ControllerKind, compare: bool) -> Tracking {
    let kinds: Vec<ControllerKind> = if compare {
        ControllerKind::ALL.to_vec()
    } else {
        vec![controller]
    };
    let runs: Vec<ControllerRun> = kinds
        .into_iter()
        .map(|kind| {
            let mut ctl = kind.build(&scenario.controllers);
            let t0 = std::time::Instant::now();
            let run = simulate(&scenario.setup, ctl.as_mut());
            ControllerRun {
                kind,
                name: ctl.name(),
                gains: ctl.gains(),
                run,
                sim_time_ms: t0.elapsed().as_secs_f64() * 1e3,
            }
        })
        .collect();
    let main = runs.iter().position(|r| r.kind == controller).unwrap_or(0);
    Tracking {
        runs,
        main,
        compare,
    }
}

impl Tracking {
    /// One run alone (a drive on a PLC, a replayed log): the job's main run.
    pub fn single(run: ControllerRun) -> Self {
        Tracking {
            runs: vec![run],
            main: 0,
            compare: false,
        }
    }

    /// The chosen controller's run.
    pub fn main(&self) -> &ControllerRun {
        &self.runs[self.main]
    }

    /// The job's summary.
    pub fn summary(&self, scenario: &TrackScenario) -> TrackSummary {
        let main = self.main();
        let setup = &scenario.setup;
        TrackSummary {
            job: JOB,
            scenario: scenario.name.clone(),
            noise: scenario.noise,
            seed: setup.rtk.seed,
            run: RunSummary::of(main),
            realtime_factor: main.run.metrics.duration_s * 1e3 / main.sim_time_ms.max(1e-9),
            events: main.run.events.clone(),
            success: main.run.metrics.completed,
            params: TrackParams {
                crawler: setup.crawler,
                slip: setup.slip,
                rtk: setup.rtk,
                sim: setup.sim,
                controllers: scenario.controllers,
            },
            compare: self
                .compare
                .then(|| self.runs.iter().map(RunSummary::of).collect()),
        }
    }
}

/// One controller's line of the summary: its metrics (field names of
/// [`Metrics`]), safety events, time and gains.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunSummary {
    /// The controller's name.
    pub controller: &'static str,
    /// Measures of the run.
    #[serde(flatten)]
    pub metrics: Metrics,
    /// Safety and runner interventions (every event but a leg's end).
    pub safety_events: usize,
    /// Wall-clock time of the simulation (ms).
    pub sim_time_ms: f64,
    /// The gains the controller ran with.
    pub gains: Gains,
}

impl RunSummary {
    /// The line of one run.
    pub fn of(r: &ControllerRun) -> Self {
        Self {
            controller: r.name,
            metrics: r.run.metrics,
            safety_events: r.run.events.iter().filter(|e| e.is_safety()).count(),
            sim_time_ms: r.sim_time_ms,
            gains: r.gains,
        }
    }
}

/// Every parameter of the run (`params` of the summary).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackParams {
    /// Machine.
    pub crawler: CrawlerParams,
    /// Ground.
    pub slip: SlipParams,
    /// Sensor.
    pub rtk: RtkParams,
    /// Loop.
    pub sim: SimParams,
    /// The gains of every controller (`fuzzy`, `pid`, `pure_pursuit`).
    #[serde(flatten)]
    pub controllers: ControllerParams,
}

/// The summary of a `track` job (SPEC §6).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackSummary {
    /// `"track"`.
    pub job: &'static str,
    /// The scenario's name.
    pub scenario: String,
    /// Noise setting (`off`, `rtk`).
    pub noise: Noise,
    /// Seed of the sensor noise.
    pub seed: u64,
    /// The chosen controller's run, its fields at the top level.
    #[serde(flatten)]
    pub run: RunSummary,
    /// Simulated time over wall-clock time.
    pub realtime_factor: f64,
    /// The chosen controller's safety and runner events.
    pub events: Vec<Event>,
    /// The chosen controller completed the scenario.
    pub success: bool,
    /// Every parameter of the run.
    pub params: TrackParams,
    /// With `--compare`: one line per controller.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub compare: Option<Vec<RunSummary>>,
}

impl TrackSummary {
    /// Why the chosen controller failed, if it did: its last safety event.
    pub fn failure(&self) -> Option<TrackError> {
        if self.success {
            return None;
        }
        let why = self
            .events
            .iter()
            .rev()
            .find(|e| e.is_safety())
            .map(|e| e.message.clone())
            .unwrap_or_else(|| "did not finish".into());
        Some(TrackError::NotCompleted {
            controller: self.run.controller.to_string(),
            scenario: self.scenario.clone(),
            why,
        })
    }
}
