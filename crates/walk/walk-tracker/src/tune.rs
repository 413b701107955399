//! Tracking comparison on equal terms (`autoshovel tune-trackers`): every
//! tracker gets the same tuning budget on the same training runs, and all
//! are reported on runs none was tuned on.
//!
//! - **Training**: Fig. 9a and 9b (noise off) and the straight, curve and
//!   V-shape runs with RTK noise and slip at seeds 11, 12 and 13.
//! - **Held out, same scenarios**: the three noisy runs at seeds 1–6.
//! - **Unseen scenarios**: `tight-curve` (a 120° arc of 5 m radius) and
//!   `long-v-slip` (a 40 m V with 3 % / 15 % slip), seeds 1–6.
//! - **Objective**, the same for every tracker, averaged over the runs:
//!   J = mean |centroid deviation| over the whole run + 0.2·largest deviation
//!   once on the path + 0.5·final position error (m) + 0.01·|final heading
//!   error| (deg), plus 10 for a run that does not complete.
//! - **Search**, the same for every tracker: `budget` evaluations of the whole
//!   training set, seeded; the first is the tracker's default gains, then
//!   60 % of the budget random in the tracker's box (log-uniform where the
//!   range spans decades), the rest Gaussian steps (σ 0.1 of the box) round
//!   the best so far.
//! - The paper's PID (kp 800, ki 100, kd 300 on the position error, §5.4) is
//!   reported as it is, untuned.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Serialize;

use crate::choice::ControllerKind;
use crate::controller::{ControllerParams, PidError, PidParams, Universe};
use crate::error::TrackError;
use crate::scenario::{resolve, Noise};
use crate::sim::{simulate, Metrics, Setup};

/// One run of a set: a scenario with its noise and seed, resolved once.
#[derive(Debug, Clone)]
pub struct Case {
    /// `scenario@seed` (or `scenario` without noise).
    pub name: String,
    /// The run.
    pub setup: Setup,
}

/// The training, held-out and unseen sets (module docs).
#[derive(Debug, Clone)]
pub struct CaseSets {
    /// Tuned on.
    pub training: Vec<Case>,
    /// The training scenarios at other seeds.
    pub held_out: Vec<Case>,
    /// Scenarios none was tuned on.
    pub unseen: Vec<Case>,
}

fn case(name: &str, noise: Noise, seed: u64) -> Result<Case, TrackError> {
    let s = resolve(name, Some(noise), seed)?;
    Ok(Case {
        name: match noise {
            Noise::Off => name.to_string(),
            Noise::Rtk => format!("{name}@{seed}"),
        },
        setup: s.setup,
    })
}

impl CaseSets {
    /// The sets of the module docs.
    pub fn standard() -> Result<Self, TrackError> {
        let noisy = ["straight", "curve", "v-shape"];
        let mut training = vec![case("fig9a", Noise::Off, 1)?, case("fig9b", Noise::Off, 1)?];
        for name in noisy {
            for seed in 11..=13 {
                training.push(case(name, Noise::Rtk, seed)?);
            }
        }
        let mut held_out = Vec::new();
        for name in noisy {
            for seed in 1..=6 {
                held_out.push(case(name, Noise::Rtk, seed)?);
            }
        }
        let mut unseen = Vec::new();
        for name in ["tight-curve", "long-v-slip"] {
            for seed in 1..=6 {
                unseen.push(case(name, Noise::Rtk, seed)?);
            }
        }
        Ok(Self {
            training,
            held_out,
            unseen,
        })
    }
}

/// The objective of one run (module docs).
pub fn run_cost(m: &Metrics) -> f64 {
    let finite = |v: f64, worst: f64| if v.is_finite() { v } else { worst };
    finite(m.mean_centroid_dev_overall_m, 10.0)
        + 0.2 * finite(m.max_centroid_dev_m, 10.0)
        + 0.5 * finite(m.final_position_error_m, 10.0)
        + 0.01 * finite(m.final_heading_error_deg.abs(), 180.0)
        + if m.completed { 0.0 } else { 10.0 }
}

/// A tracker with a box of gains to tune.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Tunable {
    /// The fuzzy tracker, constant α, fixed universes.
    Fuzzy,
    /// The fuzzy tracker with α growing with curvature.
    FuzzyCurvature,
    /// The fuzzy tracker with variable universes.
    FuzzyVariable,
    /// PID on e = d + α·d0.
    PidPreview,
    /// PID on the position error d0.
    PidPosition,
    /// Pure pursuit.
    PurePursuit,
    /// Stanley.
    Stanley,
}

/// One gain's range: (name, low, high, log-scaled).
pub type Range = (&'static str, f64, f64, bool);

impl Tunable {
    /// Every tunable tracker, in report order.
    pub const ALL: [Tunable; 7] = [
        Tunable::Fuzzy,
        Tunable::FuzzyCurvature,
        Tunable::FuzzyVariable,
        Tunable::PidPreview,
        Tunable::PidPosition,
        Tunable::PurePursuit,
        Tunable::Stanley,
    ];

    /// Its name in reports.
    pub fn name(self) -> &'static str {
        match self {
            Tunable::Fuzzy => "fuzzy",
            Tunable::FuzzyCurvature => "fuzzy, α(κ)",
            Tunable::FuzzyVariable => "fuzzy, variable universe",
            Tunable::PidPreview => "pid on d + α·d0",
            Tunable::PidPosition => "pid on d0",
            Tunable::PurePursuit => "pure-pursuit",
            Tunable::Stanley => "stanley",
        }
    }

    /// The controller it runs as.
    pub fn kind(self) -> ControllerKind {
        match self {
            Tunable::Fuzzy | Tunable::FuzzyCurvature | Tunable::FuzzyVariable => {
                ControllerKind::Fuzzy
            }
            Tunable::PidPreview | Tunable::PidPosition => ControllerKind::Pid,
            Tunable::PurePursuit => ControllerKind::PurePursuit,
            Tunable::Stanley => ControllerKind::Stanley,
        }
    }

    /// The box searched.
    pub fn ranges(self) -> Vec<Range> {
        let fuzzy = vec![
            ("alpha", 0.0, 1.5, false),
            ("k1", 0.3, 10.0, true),
            ("k2", 1.0, 100.0, true),
            ("k3", 0.3, 2.5, true),
            ("ec_filter_s", 0.0, 1.0, false),
        ];
        match self {
            Tunable::Fuzzy => fuzzy,
            Tunable::FuzzyCurvature => {
                let mut r = fuzzy;
                r.push(("alpha_curvature_m", 0.0, 5.0, false));
                r
            }
            Tunable::FuzzyVariable => {
                let mut r = fuzzy;
                r.push(("vu_tau", 0.2, 1.0, false));
                r.push(("vu_epsilon", 0.02, 0.5, true));
                r
            }
            Tunable::PidPreview => vec![
                ("kp", 50.0, 50_000.0, true),
                ("ki", 0.0, 1000.0, false),
                ("kd", 0.0, 20_000.0, false),
                ("alpha", 0.0, 1.5, false),
            ],
            Tunable::PidPosition => vec![
                ("kp", 50.0, 50_000.0, true),
                ("ki", 0.0, 1000.0, false),
                ("kd", 0.0, 20_000.0, false),
            ],
            Tunable::PurePursuit => vec![
                ("lookahead_m", 0.3, 6.0, true),
                ("lookahead_gain_s", 0.0, 3.0, false),
            ],
            Tunable::Stanley => vec![
                ("k_per_s", 0.1, 10.0, true),
                ("softening_mps", 0.05, 2.0, true),
                ("heading_time_s", 0.1, 3.0, true),
            ],
        }
    }

    /// The untuned gains it starts from.
    pub fn defaults(self) -> ControllerParams {
        let mut p = ControllerParams::default();
        match self {
            Tunable::FuzzyVariable => p.fuzzy.universe = Universe::Variable,
            Tunable::PidPosition => p.pid = PidParams::paper(),
            _ => {}
        }
        p
    }

    /// The gains at `x` (one value per range, in order).
    pub fn params(self, x: &[f64]) -> ControllerParams {
        let mut p = self.defaults();
        for ((name, ..), &v) in self.ranges().iter().zip(x) {
            *gain(self.kind(), &mut p, name) = v;
        }
        p
    }

    /// The default gains as a point of the box (clamped into it).
    fn default_point(self) -> Vec<f64> {
        let mut p = self.defaults();
        self.ranges()
            .iter()
            .map(|&(name, lo, hi, _)| gain(self.kind(), &mut p, name).clamp(lo, hi))
            .collect()
    }
}

/// The gain `name` of a `kind` tracker in `p` (the names of [`Tunable::ranges`]).
fn gain<'a>(kind: ControllerKind, p: &'a mut ControllerParams, name: &str) -> &'a mut f64 {
    match (kind, name) {
        (ControllerKind::Fuzzy, "alpha") => &mut p.fuzzy.alpha,
        (ControllerKind::Fuzzy, "k1") => &mut p.fuzzy.k1,
        (ControllerKind::Fuzzy, "k2") => &mut p.fuzzy.k2,
        (ControllerKind::Fuzzy, "k3") => &mut p.fuzzy.k3,
        (ControllerKind::Fuzzy, "ec_filter_s") => &mut p.fuzzy.ec_filter_s,
        (ControllerKind::Fuzzy, "alpha_curvature_m") => &mut p.fuzzy.alpha_curvature_m,
        (ControllerKind::Fuzzy, "vu_tau") => &mut p.fuzzy.vu_tau,
        (ControllerKind::Fuzzy, "vu_epsilon") => &mut p.fuzzy.vu_epsilon,
        (ControllerKind::Pid, "kp") => &mut p.pid.kp,
        (ControllerKind::Pid, "ki") => &mut p.pid.ki,
        (ControllerKind::Pid, "kd") => &mut p.pid.kd,
        (ControllerKind::Pid, "alpha") => &mut p.pid.alpha,
        (ControllerKind::PurePursuit, "lookahead_m") => &mut p.pure_pursuit.lookahead_m,
        (ControllerKind::PurePursuit, "lookahead_gain_s") => &mut p.pure_pursuit.lookahead_gain_s,
        (ControllerKind::Stanley, "k_per_s") => &mut p.stanley.k_per_s,
        (ControllerKind::Stanley, "softening_mps") => &mut p.stanley.softening_mps,
        (ControllerKind::Stanley, "heading_time_s") => &mut p.stanley.heading_time_s,
        (kind, name) => unreachable!("{kind:?} has no gain {name}"),
    }
}

/// Mean objective and every run's metrics of `params` as `kind` over `cases`.
pub fn evaluate(
    kind: ControllerKind,
    params: &ControllerParams,
    cases: &[Case],
) -> (f64, Vec<Metrics>) {
    let metrics: Vec<Metrics> = cases
        .iter()
        .map(|c| {
            let mut ctl = kind.build(params);
            simulate(&c.setup, ctl.as_mut()).metrics
        })
        .collect();
    let cost = metrics.iter().map(run_cost).sum::<f64>() / cases.len().max(1) as f64;
    (cost, metrics)
}

/// The result of tuning one tracker.
#[derive(Debug, Clone, Serialize)]
pub struct Tuned {
    /// The tracker.
    pub tracker: Tunable,
    /// Its name.
    pub name: &'static str,
    /// The best gains found.
    pub params: ControllerParams,
    /// Their training objective.
    pub training_cost: f64,
    /// The training objective of the default gains.
    pub default_cost: f64,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Best training objective after each evaluation.
    pub progress: Vec<f64>,
}

/// Tunes `tracker` on `training` with `budget` evaluations, seeded (module docs).
pub fn tune(tracker: Tunable, training: &[Case], budget: usize, seed: u64) -> Tuned {
    let ranges = tracker.ranges();
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let to_unit = |i: usize, v: f64| {
        let (_, lo, hi, log) = ranges[i];
        if log {
            (v.ln() - lo.ln()) / (hi.ln() - lo.ln())
        } else {
            (v - lo) / (hi - lo)
        }
    };
    let from_unit = |i: usize, u: f64| {
        let (_, lo, hi, log) = ranges[i];
        let u = u.clamp(0.0, 1.0);
        if log {
            (lo.ln() + u * (hi.ln() - lo.ln())).exp()
        } else {
            lo + u * (hi - lo)
        }
    };
    let start: Vec<f64> = tracker.default_point();
    let mut best_u: Vec<f64> = start
        .iter()
        .enumerate()
        .map(|(i, &v)| to_unit(i, v))
        .collect();
    let (default_cost, _) = evaluate(tracker.kind(), &tracker.params(&start), training);
    let mut best_cost = default_cost;
    let mut best_x = start.clone();
    let mut progress = vec![best_cost];
    let random = (budget as f64 * 0.6).round() as usize;
    for k in 1..budget {
        let u: Vec<f64> = if k < random {
            (0..ranges.len()).map(|_| rng.gen::<f64>()).collect()
        } else {
            best_u
                .iter()
                .map(|&b| {
                    let step: f64 = rng.sample(rand_distr::StandardNormal);
                    (b + 0.1 * step).clamp(0.0, 1.0)
                })
                .collect()
        };
        let x: Vec<f64> = u
            .iter()
            .enumerate()
            .map(|(i, &v)| from_unit(i, v))
            .collect();
        let (cost, _) = evaluate(tracker.kind(), &tracker.params(&x), training);
        if cost < best_cost {
            best_cost = cost;
            best_u = u;
            best_x = x;
        }
        progress.push(best_cost);
    }
    Tuned {
        tracker,
        name: tracker.name(),
        params: tracker.params(&best_x),
        training_cost: best_cost,
        default_cost,
        evaluations: progress.len(),
        progress,
    }
}

/// How one tracker did on one set of runs.
#[derive(Debug, Clone, Serialize)]
pub struct SetScore {
    /// The objective, averaged.
    pub cost: f64,
    /// Mean over runs of the mean |centroid deviation| over the whole run (m).
    pub mean_dev_m: f64,
    /// Largest |centroid deviation| once on the path, over runs (m).
    pub max_dev_m: f64,
    /// Mean |final heading error| (deg).
    pub mean_abs_final_heading_deg: f64,
    /// Runs that completed (%).
    pub completed_pct: f64,
}

impl SetScore {
    fn of(cost: f64, m: &[Metrics]) -> Self {
        let n = m.len().max(1) as f64;
        Self {
            cost,
            mean_dev_m: m.iter().map(|m| m.mean_centroid_dev_overall_m).sum::<f64>() / n,
            max_dev_m: m.iter().map(|m| m.max_centroid_dev_m).fold(0.0, f64::max),
            mean_abs_final_heading_deg: m
                .iter()
                .map(|m| m.final_heading_error_deg.abs())
                .sum::<f64>()
                / n,
            completed_pct: 100.0 * m.iter().filter(|m| m.completed).count() as f64 / n,
        }
    }
}

/// One row of the comparison: a tracker with its gains and its scores.
#[derive(Debug, Clone, Serialize)]
pub struct TrackerRow {
    /// The tracker's name.
    pub tracker: &'static str,
    /// The gains it ran with.
    pub params: ControllerParams,
    /// Evaluations spent tuning them (0: untuned).
    pub evaluations: usize,
    /// On the training runs.
    pub training: SetScore,
    /// On the training scenarios at other seeds.
    pub held_out: SetScore,
    /// On the scenarios none was tuned on.
    pub unseen: SetScore,
}

/// The `tune-trackers` summary.
#[derive(Debug, Clone, Serialize)]
pub struct TuneSummary {
    /// `tune-trackers`.
    pub job: &'static str,
    /// Evaluations per tracker.
    pub budget: usize,
    /// Seed of the searches.
    pub seed: u64,
    /// Run names of each set.
    pub training_runs: Vec<String>,
    /// Held-out run names.
    pub held_out_runs: Vec<String>,
    /// Unseen run names.
    pub unseen_runs: Vec<String>,
    /// Every tuned tracker, then the paper's PID as it is.
    pub trackers: Vec<TrackerRow>,
}

/// Scores `params` as `kind` on every set.
pub fn score(
    name: &'static str,
    kind: ControllerKind,
    params: ControllerParams,
    evaluations: usize,
    sets: &CaseSets,
) -> TrackerRow {
    let set = |cases: &[Case]| {
        let (cost, m) = evaluate(kind, &params, cases);
        SetScore::of(cost, &m)
    };
    TrackerRow {
        tracker: name,
        params,
        evaluations,
        training: set(&sets.training),
        held_out: set(&sets.held_out),
        unseen: set(&sets.unseen),
    }
}

/// The summary from the tuned trackers (in any order; reported in
/// [`Tunable::ALL`] order) and the paper's PID.
pub fn summarize(sets: &CaseSets, tuned: &[Tuned], budget: usize, seed: u64) -> TuneSummary {
    let names = |c: &[Case]| c.iter().map(|c| c.name.clone()).collect();
    let mut trackers: Vec<TrackerRow> = Tunable::ALL
        .iter()
        .filter_map(|t| tuned.iter().find(|x| x.tracker == *t))
        .map(|t| score(t.name, t.tracker.kind(), t.params, t.evaluations, sets))
        .collect();
    let paper = ControllerParams {
        pid: PidParams {
            error: PidError::Position,
            ..PidParams::paper()
        },
        ..ControllerParams::default()
    };
    trackers.push(score(
        "pid, the paper's gains",
        ControllerKind::Pid,
        paper,
        0,
        sets,
    ));
    TuneSummary {
        job: "tune-trackers",
        budget,
        seed,
        training_runs: names(&sets.training),
        held_out_runs: names(&sets.held_out),
        unseen_runs: names(&sets.unseen),
        trackers,
    }
}
