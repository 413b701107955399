//! The machine link (walking paper §5.1–5.2, Fig. 11): the shovel PLC's
//! OPC UA information model ([`model`]), who may move the machine
//! ([`control`]: one session at a time, on OPC UA's LockingServices), the
//! simulated PLC that protects its machine ([`plc`]) behind a secure OPC UA
//! server ([`server`], its node manager [`nodes`]), the
//! workstation that drives it ([`drive`](mod@drive)), certificates and trust lists
//! ([`pki`]), and the network relay that lets tests pull the cable
//! ([`relay`]). Runs are recorded in the run log of `autoshovel-run-log`. The protocol is async-opcua's; nothing of it is written here.

pub mod control;
pub mod drive;
pub mod error;
pub mod model;
pub mod nodes;
pub mod pki;
pub mod plc;
pub mod relay;
pub mod server;

pub use autoshovel_run_log::RunLog;
pub use control::{Caller, Refusal};
pub use drive::{drive, drive_logged, DriveOptions, DriveRun, Link, LinkEvent, LinkParams, Policy};
pub use error::LinkError;
pub use plc::{Clock, FaultKind, Plc, PlcParams, PlcSimSummary, HEARTBEAT_TIMEOUT};
pub use server::{PlcServer, ServeParams};
