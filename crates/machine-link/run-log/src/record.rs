//! The run log: an MCAP file (the ROS 2 default bag format; Foxglove opens
//! it) of JSON messages, one channel per topic, stamped on the PLC's clock.
//! `drive` logs the planned path, every decision with the pose it used (and
//! the simulator's truth when the PLC is `plc-sim`), the RTK fixes, the
//! motor readings and every event; `plc-sim` logs its fixes, truth,
//! setpoints, readings and events. [`crate::replay`] reads the drive's log
//! back into the tracking metrics.
//!
//! Written uncompressed (no C compression libraries to build), in chunks
//! with CRCs closed each control period ([`RunLog::sync`]): a writer killed
//! mid-run leaves a log readable up to its last period. MCAP's indexes and
//! summary are kept, so readers seek by time.

use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

use autoshovel_core::Pose2;
use autoshovel_walk_tracker::RefLeg;
use serde::{Deserialize, Serialize};

use crate::error::RunLogError;

/// The topics.
pub mod topic {
    /// The planned path (one message at the start).
    pub const PATH: &str = "/autoshovel/path";
    /// Every workstation decision.
    pub const TICK: &str = "/autoshovel/tick";
    /// Every event (the workstation's, the link's, the PLC's).
    pub const EVENT: &str = "/autoshovel/event";
    /// The metrics at the end.
    pub const SUMMARY: &str = "/autoshovel/summary";
    /// RTK fixes as the receiver gives them.
    pub const RTK: &str = "/rtk/fix";
    /// Inverter readings.
    pub const MOTORS: &str = "/plc/motors";
    /// Setpoints as the PLC holds them.
    pub const SETPOINTS: &str = "/plc/setpoints";
    /// The simulator's truth.
    pub const TRUTH: &str = "/sim/truth";
}

/// A pose in a message.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PoseMsg {
    /// East (m).
    pub x: f64,
    /// North (m).
    pub y: f64,
    /// θ from east, counter-clockwise (rad).
    pub theta: f64,
}

impl From<Pose2> for PoseMsg {
    fn from(p: Pose2) -> Self {
        Self {
            x: p.x,
            y: p.y,
            theta: p.theta,
        }
    }
}

impl From<PoseMsg> for Pose2 {
    fn from(p: PoseMsg) -> Self {
        Pose2::new(p.x, p.y, p.theta)
    }
}

/// One leg of the path message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LegMsg {
    /// `forward` or `reverse`.
    pub direction: autoshovel_core::Direction,
    /// Points [[x, y]] (m).
    pub points: Vec<[f64; 2]>,
    /// Heading required at the end (rad).
    pub end_heading_rad: f64,
}

impl LegMsg {
    /// The message of `leg`.
    pub fn of(leg: &RefLeg) -> Self {
        Self {
            direction: leg.direction,
            points: leg.points.iter().map(|p| [p.x, p.y]).collect(),
            end_heading_rad: leg.end_heading_rad,
        }
    }
}

/// The path message.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PathMsg {
    /// The legs in order.
    pub legs: Vec<LegMsg>,
}

/// One decision of the workstation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct TickMsg {
    /// Time on the PLC's clock since the run started (s).
    pub t_s: f64,
    /// Leg index.
    pub leg: usize,
    /// The pose the decision used (the newest fix, in the library's frame).
    pub measured: PoseMsg,
    /// The simulator's truth (None on a real machine).
    pub truth: Option<PoseMsg>,
    /// Distance travelled (truth, or along the fixes) (m).
    pub travelled_m: f64,
    /// Preview deviation d (m).
    pub d_m: f64,
    /// Centroid deviation d0 (m).
    pub d0_m: f64,
    /// Reference speed (m/s).
    pub speed_ref_mps: f64,
    /// Steering n_r − n_l (rpm).
    pub steer_rpm: f64,
    /// Left setpoint (rpm).
    pub left_rpm: f64,
    /// Right setpoint (rpm).
    pub right_rpm: f64,
}

/// An RTK fix.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RtkMsg {
    /// The receiver's time since the run started (s).
    pub t_s: f64,
    /// East (m).
    pub east_m: f64,
    /// North (m).
    pub north_m: f64,
    /// Heading from north, clockwise (deg).
    pub heading_deg: f64,
    /// NMEA fix quality.
    pub quality: u8,
}

/// Inverter readings of both motors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MotorsMsg {
    /// Time (s).
    pub t_s: f64,
    /// Left: speed (rpm), frequency (Hz), current (A), voltage (V).
    pub left: [f64; 4],
    /// Right: the same.
    pub right: [f64; 4],
}

/// The end of a drive: where the machine stopped, and the metrics.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct EndMsg {
    /// Time (s).
    pub t_s: f64,
    /// Final pose (truth on a simulator, else the last fix).
    pub end: PoseMsg,
    /// Distance travelled (m).
    pub travelled_m: f64,
    /// Whether the path was completed.
    pub completed: bool,
    /// The metrics.
    pub metrics: autoshovel_walk_tracker::Metrics,
}

/// An event.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventMsg {
    /// Time (s) (machine time, or wall time for link events).
    pub t_s: f64,
    /// Who: `workstation`, `link`, `plc`.
    pub source: String,
    /// Kind.
    pub kind: String,
    /// Human text.
    pub message: String,
}

/// An open MCAP log.
pub struct RunLog {
    w: mcap::Writer<BufWriter<File>>,
    channels: BTreeMap<&'static str, u16>,
    seq: u32,
    path: PathBuf,
    /// Unix time of the run's t = 0 (ns).
    pub origin_ns: u64,
    /// The latest run time written (s).
    last_t_s: f64,
}

fn write_err(path: &Path, source: mcap::McapError) -> RunLogError {
    RunLogError::McapWrite {
        path: path.to_path_buf(),
        source,
    }
}

/// OPC UA DateTime ticks (100 ns since 1601) of the Unix epoch.
pub const UNIX_EPOCH_TICKS: i64 = 116_444_736_000_000_000;

impl RunLog {
    /// Creates `path` with `metadata` (name/value pairs); an existing file
    /// is refused unless `overwrite`.
    pub fn create(
        path: &Path,
        metadata: &[(&str, String)],
        overwrite: bool,
    ) -> Result<RunLog, RunLogError> {
        let f = if overwrite {
            File::create(path)
        } else {
            File::options().write(true).create_new(true).open(path)
        }
        .map_err(|source| {
            let path = path.to_path_buf();
            if source.kind() == std::io::ErrorKind::AlreadyExists {
                RunLogError::Exists { path }
            } else {
                RunLogError::Io { path, source }
            }
        })?;
        // Chunks carry CRCs; [`RunLog::sync`] closes one each control
        // period, so a killed writer leaves every period but the last whole.
        let opts = mcap::WriteOptions::new()
            .compression(None)
            .calculate_chunk_crcs(true)
            .calculate_data_section_crc(true)
            .profile("")
            .library(format!("autoshovel {}", env!("CARGO_PKG_VERSION")));
        let mut w = opts
            .create(BufWriter::new(f))
            .map_err(|e| write_err(path, e))?;
        let meta = mcap::records::Metadata {
            name: "autoshovel".into(),
            metadata: metadata
                .iter()
                .map(|(k, v)| (k.to_string(), v.clone()))
                .collect(),
        };
        w.write_metadata(&meta).map_err(|e| write_err(path, e))?;
        Ok(RunLog {
            w,
            channels: BTreeMap::new(),
            seq: 0,
            path: path.to_path_buf(),
            origin_ns: 0,
            last_t_s: 0.0,
        })
    }

    /// Sets t = 0 of the run from the PLC clock's DateTime ticks.
    pub fn set_origin_ticks(&mut self, ticks: i64) {
        self.origin_ns = ((ticks - UNIX_EPOCH_TICKS).max(0) as u64).saturating_mul(100);
    }

    fn channel(&mut self, topic: &'static str) -> Result<u16, RunLogError> {
        if let Some(id) = self.channels.get(topic) {
            return Ok(*id);
        }
        let schema = format!(r#"{{"type":"object","title":"{topic}"}}"#);
        let sid = self
            .w
            .add_schema(topic, "jsonschema", schema.as_bytes())
            .map_err(|e| write_err(&self.path, e))?;
        let id = self
            .w
            .add_channel(sid, topic, "json", &BTreeMap::new())
            .map_err(|e| write_err(&self.path, e))?;
        self.channels.insert(topic, id);
        Ok(id)
    }

    /// Writes `msg` on `topic` at run time `t_s`.
    pub fn write<T: Serialize>(
        &mut self,
        topic: &'static str,
        t_s: f64,
        msg: &T,
    ) -> Result<(), RunLogError> {
        let id = self.channel(topic)?;
        let data = serde_json::to_vec(msg).map_err(|source| RunLogError::Encode {
            path: self.path.clone(),
            source,
        })?;
        if t_s.is_finite() {
            self.last_t_s = self.last_t_s.max(t_s);
        }
        let t = self
            .origin_ns
            .saturating_add((t_s.max(0.0) * 1e9).round() as u64);
        self.seq = self.seq.wrapping_add(1);
        self.w
            .write_to_known_channel(
                &mcap::records::MessageHeader {
                    channel_id: id,
                    sequence: self.seq,
                    log_time: t,
                    publish_time: t,
                },
                &data,
            )
            .map_err(|e| write_err(&self.path, e))
    }

    /// The latest run time written (s).
    pub fn last_t_s(&self) -> f64 {
        self.last_t_s
    }

    /// Makes what was written so far durable: closes the open chunk (with
    /// its CRC) and hands it to the operating system, so that a process
    /// killed after this leaves it readable ([`crate::read`]).
    pub fn sync(&mut self) -> Result<(), RunLogError> {
        self.w.flush().map_err(|e| write_err(&self.path, e))
    }

    /// Writes the summary and index and closes the file.
    pub fn finish(mut self) -> Result<PathBuf, RunLogError> {
        self.w.finish().map_err(|e| write_err(&self.path, e))?;
        Ok(self.path)
    }
}
