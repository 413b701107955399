//! `autoshovel replay`: the tracking metrics of Figs. 13–14 (centroid
//! deviation, heading error) recomputed from a record of a run — a `drive`
//! MCAP log (its path and every decision, on the simulator's truth when
//! the PLC was `plc-sim`), or a plain CSV of a real machine's RTK track
//! against its planned path.

use std::path::Path;

use autoshovel_core::Pose2;
use autoshovel_walk_tracker::sim::{measure, Evaluator, Event, Run, Sample, Setup};
use autoshovel_walk_tracker::workstation::Decision;
use autoshovel_walk_tracker::{deviations, RefLeg, RtkFix, TrackCommand};
use serde::Serialize;

use crate::error::RunLogError;
use crate::read::{read_messages, LogEnd};
use crate::record::{topic, EventMsg, PathMsg, PoseMsg, TickMsg};

/// The part of the end message replay needs.
#[derive(serde::Deserialize)]
struct EndIn {
    t_s: f64,
    end: PoseMsg,
    travelled_m: f64,
    completed: bool,
}

/// A replayed run.
#[derive(Debug, Clone)]
pub struct Replay {
    /// Samples, events and metrics, as `track` computes them.
    pub run: Run,
    /// The path.
    pub legs: Vec<RefLeg>,
    /// What the deviations are measured on: `simulator truth`, `rtk fixes`.
    pub measured_on: &'static str,
    /// Where the record came from.
    pub source: String,
    /// For a log its writer never closed (killed, power lost): the bytes
    /// read as whole records, up to which it was replayed.
    pub cut: Option<u64>,
    /// Why the run ended, as its last `end` event says.
    pub ended: Option<String>,
}

fn err(path: &Path, why: impl Into<String>) -> RunLogError {
    RunLogError::Content {
        path: path.to_path_buf(),
        why: why.into(),
    }
}

fn io_err(path: &Path, source: std::io::Error) -> RunLogError {
    RunLogError::Io {
        path: path.to_path_buf(),
        source,
    }
}

/// The legs of a path message.
pub fn legs_of(msg: &PathMsg, path: &Path) -> Result<Vec<RefLeg>, RunLogError> {
    msg.legs
        .iter()
        .enumerate()
        .map(|(i, l)| {
            RefLeg::new(
                l.direction,
                l.points
                    .iter()
                    .map(|p| autoshovel_core::Vec2::new(p[0], p[1]))
                    .collect(),
                Some(l.end_heading_rad),
            )
            .map_err(|e| err(path, format!("{} leg {i}: {e:?}", topic::PATH)))
        })
        .collect()
}

fn setup_with(legs: Vec<RefLeg>, start: Pose2) -> Setup {
    Setup {
        legs,
        start,
        crawler: Default::default(),
        slip: Default::default(),
        rtk: Default::default(),
        sim: Default::default(),
    }
}

/// Replays a `drive` MCAP log, read record by record ([`crate::read`]):
/// the path first, then every decision measured as it comes. A log whose
/// writer was killed is replayed up to its last whole chunk, and the
/// replay says it was cut.
pub fn replay_mcap(path: &Path) -> Result<Replay, RunLogError> {
    let mut legs: Option<Vec<RefLeg>> = None;
    let mut eval = Evaluator::new();
    let mut samples: Vec<Sample> = Vec::new();
    let mut last: Option<TickMsg> = None;
    let mut truth_all = true;
    let mut events: Vec<Event> = Vec::new();
    let mut ended: Option<String> = None;
    let mut end_msg: Option<(f64, PoseMsg, f64, bool)> = None;
    let end = read_messages(path, |topic_name, sequence, data| {
        let bad = |source: serde_json::Error| RunLogError::Message {
            path: path.to_path_buf(),
            topic: topic_name.to_string(),
            sequence,
            source,
        };
        match topic_name {
            topic::PATH => {
                let msg: PathMsg = serde_json::from_slice(data).map_err(bad)?;
                legs = Some(legs_of(&msg, path)?);
            }
            topic::TICK => {
                let t: TickMsg = serde_json::from_slice(data).map_err(bad)?;
                let legs = legs.as_ref().ok_or_else(|| {
                    err(path, format!("message {sequence}: a tick before the path"))
                })?;
                check_tick(&t, legs.len()).map_err(|why| {
                    err(path, format!("message {sequence} on {topic_name}: {why}"))
                })?;
                let d = decision(legs, &t);
                truth_all &= t.truth.is_some();
                let truth: Pose2 = t.truth.unwrap_or(t.measured).into();
                samples.push(eval.sample(legs, &d, t.t_s, truth, t.travelled_m));
                last = Some(t);
            }
            topic::EVENT => {
                let e: EventMsg = serde_json::from_slice(data).map_err(bad)?;
                if e.kind == "end" {
                    ended = Some(e.message.clone());
                }
                if e.source == "workstation" {
                    events.push(Event {
                        t_s: e.t_s,
                        kind: intern(&e.kind),
                        message: e.message,
                    });
                }
            }
            topic::SUMMARY => {
                let v: EndIn = serde_json::from_slice(data).map_err(bad)?;
                end_msg = Some((v.t_s, v.end, v.travelled_m, v.completed));
            }
            _ => {}
        }
        Ok(())
    })?;
    let legs =
        legs.ok_or_else(|| err(path, format!("no {} message: not a drive log", topic::PATH)))?;
    let Some(last) = last else {
        return Err(err(path, format!("no {} messages", topic::TICK)));
    };
    // The end as the drive recorded it; a log cut short ends at its last tick.
    let (t_end, end_pose, travelled, completed) = end_msg.unwrap_or_else(|| {
        (
            last.t_s,
            last.truth.unwrap_or(last.measured),
            last.travelled_m,
            events.iter().filter(|e| e.kind == Event::LEG_END).count() == legs.len(),
        )
    });
    let setup = setup_with(legs.clone(), samples[0].truth);
    let metrics = measure(
        &samples,
        &setup,
        end_pose.into(),
        travelled,
        t_end,
        completed,
    );
    Ok(Replay {
        run: Run {
            samples,
            events,
            metrics,
        },
        legs,
        measured_on: if truth_all {
            "simulator truth"
        } else {
            "rtk fixes"
        },
        source: path.display().to_string(),
        cut: match end {
            LogEnd::Complete => None,
            LogEnd::Cut { bytes } => Some(bytes),
        },
        ended,
    })
}

/// What a tick must be to be measured: its leg on the path, its numbers finite.
fn check_tick(t: &TickMsg, legs: usize) -> Result<(), String> {
    if t.leg >= legs {
        return Err(format!("tick at {} s names leg {} of {legs}", t.t_s, t.leg));
    }
    let poses = [Some(t.measured), t.truth].into_iter().flatten();
    let finite = [t.t_s, t.travelled_m, t.d_m, t.d0_m]
        .into_iter()
        .chain(poses.flat_map(|p| [p.x, p.y, p.theta]))
        .all(f64::is_finite);
    if !finite {
        return Err(format!(
            "tick at {} s holds a number that is not finite",
            t.t_s
        ));
    }
    Ok(())
}

fn decision(legs: &[RefLeg], t: &TickMsg) -> Decision {
    let measured: Pose2 = t.measured.into();
    let mut dev = deviations(&legs[t.leg], measured, 0.0, None);
    dev.d_m = t.d_m;
    dev.d0_m = t.d0_m;
    Decision {
        leg: t.leg,
        measured,
        dev,
        speed_ref_mps: t.speed_ref_mps,
        steer_rpm: t.steer_rpm,
        command: TrackCommand {
            left_rpm: t.left_rpm,
            right_rpm: t.right_rpm,
        },
    }
}

/// Event kinds as the workstation names them (the summary's `kind` is a
/// `&'static str`).
fn intern(kind: &str) -> &'static str {
    const KINDS: &[&str] = &[
        "leg-end",
        "stale-pose",
        "pose-jump",
        "pose-recovered",
        "timeout",
        "link-lost",
        "link-restored",
        "plc-fault",
        "acknowledged",
    ];
    KINDS
        .iter()
        .find(|k| **k == kind)
        .copied()
        .unwrap_or("other")
}

/// One row of a real machine's RTK track.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TrackRow {
    /// Time (s).
    pub t_s: f64,
    /// The fix.
    pub fix: RtkFix,
}

/// Reads a CSV of RTK fixes: a header naming `t_s` (or `time_s`),
/// `east_m`, `north_m` and `heading_deg` (north, clockwise, the
/// receiver's), in any order; other columns are ignored.
pub fn read_rtk_csv(path: &Path) -> Result<Vec<TrackRow>, RunLogError> {
    let text = std::fs::read_to_string(path).map_err(|source| io_err(path, source))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty());
    let (_, header) = lines.next().ok_or_else(|| {
        err(
            path,
            "empty file: expected a header t_s,east_m,north_m,heading_deg",
        )
    })?;
    let names: Vec<String> = header
        .split(',')
        .map(|s| s.trim().to_ascii_lowercase())
        .collect();
    let col = |want: &[&str]| {
        names
            .iter()
            .position(|n| want.contains(&n.as_str()))
            .ok_or_else(|| {
                err(
                    path,
                    format!(
                        "line 1: no column {} in the header {header:?}",
                        want.join(" or ")
                    ),
                )
            })
    };
    let (ct, ce, cn, ch) = (
        col(&["t_s", "time_s"])?,
        col(&["east_m", "east"])?,
        col(&["north_m", "north"])?,
        col(&["heading_deg", "heading"])?,
    );
    let mut rows = Vec::new();
    for (i, line) in lines {
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        let num = |c: usize, name: &str| -> Result<f64, RunLogError> {
            cells
                .get(c)
                .and_then(|s| s.parse::<f64>().ok())
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    err(
                        path,
                        format!(
                            "line {}: {name} {:?} is not a finite number",
                            i + 1,
                            cells.get(c).copied().unwrap_or("")
                        ),
                    )
                })
        };
        let t = num(ct, "t_s")?;
        let (east, north) = (num(ce, "east_m")?, num(cn, "north_m")?);
        if east.abs().max(north.abs()) > COORD_LIMIT_M {
            return Err(err(
                path,
                format!(
                    "line {}: east {east} m, north {north} m lies beyond any projected grid (|x| ≤ {COORD_LIMIT_M:e} m)",
                    i + 1
                ),
            ));
        }
        if let Some(prev) = rows.last().map(|r: &TrackRow| r.t_s) {
            if t <= prev {
                return Err(err(
                    path,
                    format!(
                        "line {}: time {t} does not increase (previous {prev})",
                        i + 1
                    ),
                ));
            }
        }
        rows.push(TrackRow {
            t_s: t,
            fix: RtkFix {
                time_s: t,
                east_m: east,
                north_m: north,
                heading_north_cw_rad: num(ch, "heading_deg")?.to_radians(),
            },
        });
    }
    if rows.len() < 2 {
        return Err(err(path, "fewer than two fixes"));
    }
    Ok(rows)
}

/// A run is complete when its last fix is within this of the path's end (m).
pub const COMPLETE_WITHIN_M: f64 = 0.5;

/// The largest coordinate a fix may have (m): UTM northings stay below
/// 10 000 km, and every projected grid in use within that.
pub const COORD_LIMIT_M: f64 = 1e7;

/// A track is replayed against a path only if its first fix lies within
/// this of the path's start (m): farther, it is another walk's track or
/// another path.
pub const START_WITHIN_M: f64 = 10.0;

/// Replays a real machine's RTK track (`read_rtk_csv`) against `legs`: each
/// fix is measured against the leg the machine is on (the next leg takes
/// over once the fix is nearer to it and the current one is run to its end).
///
/// Refused when the track does not start on the path (its first fix farther
/// than [`START_WITHIN_M`] from the path's start) or a metric comes out not finite.
pub fn replay_rtk(
    rows: &[TrackRow],
    legs: Vec<RefLeg>,
    source: &str,
) -> Result<Replay, RunLogError> {
    let path = Path::new(source);
    let (Some(first), Some(start)) = (rows.first(), legs.first().and_then(|l| l.points.first()))
    else {
        return Err(err(path, "no fixes, or a path without points"));
    };
    let off = (first.fix.to_pose().position() - *start).norm();
    if off.is_nan() || off > START_WITHIN_M {
        return Err(err(
            path,
            format!(
                "the track's first fix is {off:.1} m from the path's start (limit {START_WITHIN_M} m): is this the walk's own --path?"
            ),
        ));
    }
    let mut eval = Evaluator::new();
    let mut samples = Vec::with_capacity(rows.len());
    let mut leg = 0usize;
    let mut travelled = 0.0;
    let mut prev: Option<Pose2> = None;
    for r in rows {
        let pose = r.fix.to_pose();
        if let Some(p) = prev {
            travelled += (pose.position() - p.position()).norm();
        }
        prev = Some(pose);
        while leg + 1 < legs.len() {
            let here = deviations(&legs[leg], pose, 0.0, None);
            let next = deviations(&legs[leg + 1], pose, 0.0, None);
            let at_end = legs[leg].length_m() - here.s_a_m < 0.5;
            if at_end && next.d0_m.abs() <= here.d0_m.abs() + 0.05 {
                leg += 1;
            } else {
                break;
            }
        }
        let dev = deviations(&legs[leg], pose, 0.0, None);
        let d = Decision {
            leg,
            measured: pose,
            dev,
            speed_ref_mps: f64::NAN,
            steer_rpm: f64::NAN,
            command: TrackCommand::STOP,
        };
        samples.push(eval.sample(&legs, &d, r.t_s, pose, travelled));
    }
    let end = prev.expect("at least two rows");
    let goal = *legs
        .last()
        .and_then(|l| l.points.last())
        .expect("legs have points");
    let completed = (end.position() - goal).norm() <= COMPLETE_WITHIN_M;
    let setup = setup_with(legs.clone(), samples[0].truth);
    let t_end = rows.last().map(|r| r.t_s).unwrap_or(0.0) - rows[0].t_s;
    let metrics = measure(&samples, &setup, end, travelled, t_end, completed);
    let numbers = [
        metrics.max_centroid_dev_m,
        metrics.mean_centroid_dev_m,
        metrics.final_position_error_m,
    ];
    if !numbers.iter().all(|x| x.is_finite()) {
        return Err(err(
            path,
            format!("the deviations from the path are not finite ({numbers:?}): the track does not follow this path"),
        ));
    }
    Ok(Replay {
        run: Run {
            samples,
            events: Vec::new(),
            metrics,
        },
        legs,
        measured_on: "rtk fixes",
        source: source.to_string(),
        cut: None,
        ended: None,
    })
}

/// The `replay` job's summary.
#[derive(Debug, Clone, Serialize)]
pub struct ReplaySummary {
    /// `"replay"`.
    pub job: &'static str,
    /// The record replayed.
    pub source: String,
    /// What the deviations are measured on.
    pub measured_on: &'static str,
    /// The metrics (as `track` and `drive` report them).
    #[serde(flatten)]
    pub metrics: autoshovel_walk_tracker::Metrics,
    /// Workstation events found in the record.
    pub events: Vec<Event>,
    /// Whether the run completed.
    pub success: bool,
    /// The log was cut (its writer never closed it): replayed up to its
    /// last whole record.
    pub cut: bool,
    /// Why the run ended, as the log's `end` event says (None: no such event).
    pub ended: Option<String>,
}

impl Replay {
    /// The job's summary.
    pub fn summary(&self) -> ReplaySummary {
        ReplaySummary {
            job: "replay",
            source: self.source.clone(),
            measured_on: self.measured_on,
            metrics: self.run.metrics,
            events: self.run.events.clone(),
            success: self.run.metrics.completed,
            cut: self.cut.is_some(),
            ended: self.ended.clone(),
        }
    }
}
