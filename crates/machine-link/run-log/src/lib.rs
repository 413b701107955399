//! The run log: an MCAP file (the ROS 2 default bag format; Foxglove opens
//! it) of JSON messages, one channel per topic, stamped on the PLC's clock
//! ([`record`]), written by `drive`, `plc-sim` and `shift`; and its replay
//! ([`replay`]), which recomputes the tracking metrics of a drive from its
//! log or from a real machine's RTK track.
//!
//! A crate of its own so that whatever writes or plots a run (the machine
//! link, the shift, the figures) shares one format without pulling the
//! OPC UA stack in.

mod error;
pub mod read;
pub mod record;
pub mod replay;

pub use error::RunLogError;
pub use read::{read_messages, LogEnd};
pub use record::{
    topic, EndMsg, EventMsg, LegMsg, MotorsMsg, PathMsg, PoseMsg, RtkMsg, RunLog, TickMsg,
    UNIX_EPOCH_TICKS,
};
pub use replay::{read_rtk_csv, replay_mcap, replay_rtk, Replay, ReplaySummary, TrackRow};
