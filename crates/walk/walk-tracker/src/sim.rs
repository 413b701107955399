//! The closed loop (SPEC §3): planner path → controller at the RTK rate →
//! crawler plant at a finer fixed step, leg by leg. Each leg runs a speed
//! profile that ramps up, cruises and ramps down to a stop at its end; at a
//! cusp (V-shape) the machine comes to rest before the next leg starts the
//! other way. Safety in the loop: a pose older than `pose_timeout_s` or a
//! jump no machine can make commands both tracks to zero and is logged.
//!
//! Metrics are measured on the *true* state (not the noisy fixes): centroid
//! deviation from the path, convergence distance, final position and heading error.

use autoshovel_core::{angle_diff, Pose2};
use serde::Serialize;

use crate::controller::Controller;
use crate::geometry::{deviations, RefLeg};
use crate::machine::Machine;
use crate::plant::{CrawlerParams, SlipParams, TrackCommand};
use crate::sensor::RtkParams;
use crate::workstation::{Decision, Status, Workstation};
pub use crate::workstation::{Event, SimParams};

/// A sample of the run at one control tick.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Time (s).
    pub t_s: f64,
    /// Leg index.
    pub leg: usize,
    /// True pose.
    pub truth: Pose2,
    /// Measured pose (the last fix).
    pub measured: Pose2,
    /// True signed centroid deviation from the path (m).
    pub centroid_dev_m: f64,
    /// True heading of motion minus the path's tangent (rad).
    pub heading_error_rad: f64,
    /// Measured preview deviation d (m).
    pub d_m: f64,
    /// Measured centroid deviation d0 (m).
    pub d0_m: f64,
    /// Reference speed (m/s).
    pub speed_ref_mps: f64,
    /// Commanded steering n_r − n_l (rpm).
    pub steer_rpm: f64,
    /// Commanded motors.
    pub command: TrackCommand,
    /// Distance travelled so far (m).
    pub travelled_m: f64,
}

/// Measures of a run (SPEC §3, §6).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Metrics {
    /// Largest |centroid deviation| once the machine has reached the path
    /// (first |deviation| < `converged_below_m`) (m).
    pub max_centroid_dev_m: f64,
    /// Mean |centroid deviation| once on the path (m).
    pub mean_centroid_dev_m: f64,
    /// RMS centroid deviation once on the path (m).
    pub rms_centroid_dev_m: f64,
    /// Travel until |deviation| < `converged_below_m` for the first time (m) (NaN: never).
    pub reached_distance_m: f64,
    /// Travel until |deviation| < 1 cm for good (m) (NaN: never).
    pub settled_1cm_distance_m: f64,
    /// Largest |centroid deviation| over the whole run (m).
    pub max_centroid_dev_overall_m: f64,
    /// Mean |centroid deviation| over the whole run (m).
    pub mean_centroid_dev_overall_m: f64,
    /// Travel until |deviation| < `converged_below_m` for good (m) (NaN: never).
    pub convergence_distance_m: f64,
    /// The convergence threshold (m).
    pub converged_below_m: f64,
    /// Distance of the final centroid from the path's end (m).
    pub final_position_error_m: f64,
    /// Final heading minus the required one (deg).
    pub final_heading_error_deg: f64,
    /// Distance travelled (m).
    pub travelled_m: f64,
    /// Simulated time (s).
    pub duration_s: f64,
    /// The run ended at the path's end (no safety stop, no timeout).
    pub completed: bool,
}

/// A finished run.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// Control-tick samples.
    pub samples: Vec<Sample>,
    /// Safety and runner events.
    pub events: Vec<Event>,
    /// Measures.
    pub metrics: Metrics,
}

/// Everything that defines one closed-loop run.
#[derive(Debug, Clone)]
pub struct Setup {
    /// The legs, in order.
    pub legs: Vec<RefLeg>,
    /// The crawler's true start pose.
    pub start: Pose2,
    /// Machine.
    pub crawler: CrawlerParams,
    /// Ground.
    pub slip: SlipParams,
    /// Sensor.
    pub rtk: RtkParams,
    /// Loop.
    pub sim: SimParams,
}

/// Convergence threshold: |centroid deviation| below this for good (SPEC §3) (m).
pub const CONVERGED_BELOW_M: f64 = 0.05;

/// Most plant steps one run may take (each a few tens of nanoseconds).
pub const MAX_PLANT_STEPS: f64 = 1e8;
/// Most control steps one run may take; each keeps a [`Sample`] (about
/// [`SAMPLE_BYTES`]), so 10⁶ is about 150 MB.
pub const MAX_CONTROL_STEPS: f64 = 1e6;
/// Bytes a control step's sample keeps.
pub const SAMPLE_BYTES: f64 = 150.0;

/// The most a run of `setup` can take, before it runs: the time limit
/// (30 s plus `time_per_m_limit_s` per metre of path) (s), the plant steps
/// and the control steps (samples) up to it.
pub fn worst_case(setup: &Setup) -> (f64, f64, f64) {
    let sp = setup.sim;
    let total_len: f64 = setup.legs.iter().map(RefLeg::length_m).sum();
    let t_limit = 30.0 + sp.time_per_m_limit_s * total_len;
    // The last control step runs all its plant steps, past the limit too.
    let control_dt = 1.0 / sp.control_rate_hz;
    (
        t_limit,
        (t_limit + control_dt) / sp.plant_dt_s.min(control_dt),
        t_limit * sp.control_rate_hz,
    )
}

/// Turns the workstation's decisions into [`Sample`]s, measuring the
/// pose given as truth against the leg the workstation is on: the
/// simulator's truth in [`simulate`] and over the link when the PLC is a
/// simulator, else the measured pose. Kept apart from the workstation,
/// which never sees the truth.
#[derive(Debug, Clone, Default)]
pub struct Evaluator {
    hint: Option<(usize, f64)>,
}

impl Evaluator {
    /// An evaluator at the start of a run.
    pub fn new() -> Self {
        Self::default()
    }

    /// The sample of decision `d` taken at `t_s` with the machine at
    /// `truth` after `travelled_m`.
    pub fn sample(
        &mut self,
        legs: &[RefLeg],
        d: &Decision,
        t_s: f64,
        truth: Pose2,
        travelled_m: f64,
    ) -> Sample {
        let hint = self.hint.filter(|(leg, _)| *leg == d.leg).map(|(_, s)| s);
        let true_dev = deviations(&legs[d.leg], truth, 0.0, hint);
        self.hint = Some((d.leg, true_dev.s_a_m));
        Sample {
            t_s,
            leg: d.leg,
            truth,
            measured: d.measured,
            centroid_dev_m: true_dev.d0_m,
            heading_error_rad: true_dev.heading_error_rad,
            d_m: d.dev.d_m,
            d0_m: d.dev.d0_m,
            speed_ref_mps: d.speed_ref_mps,
            steer_rpm: d.steer_rpm,
            command: d.command,
            travelled_m,
        }
    }
}

/// Plant steps per control tick and their length (s).
pub fn plant_steps(sp: &SimParams) -> (usize, f64) {
    let control_dt = 1.0 / sp.control_rate_hz;
    let substeps = ((control_dt / sp.plant_dt_s).round() as usize).max(1);
    (substeps, control_dt / substeps as f64)
}

/// Most plant steps [`simulate`] spends bringing the machine to rest after
/// a safety stop.
pub const MAX_STOP_STEPS: usize = 100_000;

/// Runs the closed loop in one process: the [`Workstation`] (controller and
/// safety, on RTK fixes alone) against the simulated [`Machine`], the
/// metrics measured on the machine's truth.
pub fn simulate(setup: &Setup, controller: &mut dyn Controller) -> Run {
    let (substeps, dt) = plant_steps(&setup.sim);
    let (t_limit, _, _) = worst_case(setup);
    let mut machine = Machine::new(setup.crawler, setup.slip, setup.rtk, setup.start);
    let mut ws = Workstation::new(&setup.legs, setup.crawler, setup.sim, controller, t_limit);
    let mut eval = Evaluator::new();
    let mut samples = Vec::new();
    let status = loop {
        let fix = machine.poll_rtk();
        let tick = ws.tick(machine.time_s(), fix, machine.motors_rpm());
        for d in &tick.decisions {
            samples.push(eval.sample(
                &setup.legs,
                d,
                machine.time_s(),
                machine.truth(),
                machine.travelled_m(),
            ));
        }
        match tick.status {
            Status::Running => machine.advance(tick.command(), dt, substeps),
            Status::Stopped => {
                machine.stop(dt, MAX_STOP_STEPS);
                break Status::Stopped;
            }
            s => break s,
        }
    };
    let completed = status == Status::Finished;
    let metrics = measure(
        &samples,
        setup,
        machine.truth(),
        machine.travelled_m(),
        machine.time_s(),
        completed,
    );
    Run {
        samples,
        events: ws.events,
        metrics,
    }
}

/// The measures of a run from its samples (SPEC §3): `end` is the final
/// pose, `travelled` the distance, `t` the duration.
pub fn measure(
    samples: &[Sample],
    setup: &Setup,
    end: Pose2,
    travelled: f64,
    t: f64,
    completed: bool,
) -> Metrics {
    // From the first sample after which |dev| stays below `threshold`.
    let for_good = |threshold: f64| -> Option<usize> {
        match samples
            .iter()
            .rposition(|s| s.centroid_dev_m.abs() >= threshold)
        {
            None if samples.is_empty() => None,
            None => Some(0),
            Some(i) if i + 1 < samples.len() => Some(i + 1),
            Some(_) => None,
        }
    };
    let conv_index = for_good(CONVERGED_BELOW_M);
    let settled_index = for_good(0.01);
    let reached_index = samples
        .iter()
        .position(|s| s.centroid_dev_m.abs() < CONVERGED_BELOW_M);
    let after: &[Sample] = reached_index.map(|i| &samples[i..]).unwrap_or(&[]);
    let stats = |xs: &[Sample]| {
        if xs.is_empty() {
            return (f64::NAN, f64::NAN, f64::NAN);
        }
        let n = xs.len() as f64;
        let max = xs
            .iter()
            .map(|s| s.centroid_dev_m.abs())
            .fold(0.0, f64::max);
        let mean = xs.iter().map(|s| s.centroid_dev_m.abs()).sum::<f64>() / n;
        let rms = (xs.iter().map(|s| s.centroid_dev_m.powi(2)).sum::<f64>() / n).sqrt();
        (max, mean, rms)
    };
    let (max_a, mean_a, rms_a) = stats(after);
    let (max_o, mean_o, _) = stats(samples);
    let at = |i: Option<usize>| i.map(|i| samples[i].travelled_m).unwrap_or(f64::NAN);
    let last = setup.legs.last();
    let (fpe, fhe) = match last {
        Some(leg) => {
            let goal = *leg.points.last().expect("legs have points");
            (
                (end.position() - goal).norm(),
                angle_diff(end.theta, leg.end_heading_rad).to_degrees(),
            )
        }
        None => (f64::NAN, f64::NAN),
    };
    Metrics {
        max_centroid_dev_m: max_a,
        mean_centroid_dev_m: mean_a,
        rms_centroid_dev_m: rms_a,
        max_centroid_dev_overall_m: max_o,
        mean_centroid_dev_overall_m: mean_o,
        convergence_distance_m: at(conv_index),
        reached_distance_m: at(reached_index),
        settled_1cm_distance_m: at(settled_index),
        converged_below_m: CONVERGED_BELOW_M,
        final_position_error_m: fpe,
        final_heading_error_deg: fhe,
        travelled_m: travelled,
        duration_s: t,
        completed,
    }
}
